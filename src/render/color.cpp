#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <string>

#include <priormap/render/color.hpp>

namespace priormap::render {
namespace {

// Samples of matplotlib's viridis at t = 0, 1/8, ..., 1; interpolated linearly in between.
constexpr std::array<Color, 9> kViridis = {{{0.267004, 0.004874, 0.329415},
                                            {0.282623, 0.140926, 0.457517},
                                            {0.253935, 0.265254, 0.529983},
                                            {0.206756, 0.371758, 0.553117},
                                            {0.163625, 0.471133, 0.558148},
                                            {0.127568, 0.566949, 0.550556},
                                            {0.134692, 0.658636, 0.517649},
                                            {0.266941, 0.748751, 0.440573},
                                            {0.993248, 0.906157, 0.143936}}};

Color Lerp(const Color& a, const Color& b, double t) {
  return {a.r + t * (b.r - a.r), a.g + t * (b.g - a.g), a.b + t * (b.b - a.b),
          a.a + t * (b.a - a.a)};
}

}  // namespace

Color Color::FromHex(std::string_view hex) {
  if (hex.size() != 7 && hex.size() != 9) return palette::kBlack;
  if (hex[0] != '#') return palette::kBlack;
  const auto is_hex_digit = [](char c) {
    return std::isxdigit(static_cast<unsigned char>(c)) != 0;
  };
  if (!std::all_of(hex.begin() + 1, hex.end(), is_hex_digit)) return palette::kBlack;
  const auto byte = [&](std::size_t i) {
    return static_cast<double>(std::strtol(std::string(hex.substr(i, 2)).c_str(), nullptr, 16)) /
           255.0;
  };
  return {byte(1), byte(3), byte(5), hex.size() == 9 ? byte(7) : 1.0};
}

Color palette::Categorical(int i) {
  static constexpr std::array<Color, 7> kColors = {kBlue,   kOrange,  kGreen, kVermillion,
                                                   kPurple, kSkyBlue, kYellow};
  const int n = static_cast<int>(kColors.size());
  return kColors[static_cast<std::size_t>(((i % n) + n) % n)];
}

Color MapColor(Colormap map, double t) {
  if (std::isnan(t)) return {0, 0, 0, 0};
  t = std::clamp(t, 0.0, 1.0);
  switch (map) {
    case Colormap::kViridis: {
      const double x = t * static_cast<double>(kViridis.size() - 1);
      const auto i = std::min(static_cast<std::size_t>(x), kViridis.size() - 2);
      return Lerp(kViridis[i], kViridis[i + 1], x - static_cast<double>(i));
    }
    case Colormap::kOccupancy:
      return {1.0 - t, 1.0 - t, 1.0 - t, 1.0};
  }
  return palette::kBlack;
}

}  // namespace priormap::render
