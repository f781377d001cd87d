#pragma once
/// Colours and colour maps for figures.

#include <string_view>

namespace priormap::render {

struct Color {
  /// Each in [0, 1]; finite values beyond count as the end they pass, and the figures refuse
  /// NaN and infinity (ContractError) where the colour is given.
  double r = 0.0, g = 0.0, b = 0.0, a = 1.0;

  /// "#rrggbb" or "#rrggbbaa"; black for anything else.
  static Color FromHex(std::string_view hex);
  [[nodiscard]] Color WithAlpha(double alpha) const { return {r, g, b, alpha}; }
};

/// A qualitative palette (Okabe-Ito, readable by colour-blind people) and a few fixed colours.
namespace palette {
inline constexpr Color kBlack{0.0, 0.0, 0.0};
inline constexpr Color kWhite{1.0, 1.0, 1.0};
inline constexpr Color kGray{0.55, 0.55, 0.55};
inline constexpr Color kLightGray{0.85, 0.85, 0.85};
inline constexpr Color kOrange{0.902, 0.624, 0.0};
inline constexpr Color kSkyBlue{0.337, 0.706, 0.914};
inline constexpr Color kGreen{0.0, 0.620, 0.451};
inline constexpr Color kYellow{0.941, 0.894, 0.259};
inline constexpr Color kBlue{0.0, 0.447, 0.698};
inline constexpr Color kVermillion{0.835, 0.369, 0.0};
inline constexpr Color kPurple{0.800, 0.475, 0.655};
/// The i-th colour of the qualitative palette (cycles).
Color Categorical(int i);
}  // namespace palette

enum class Colormap {
  kViridis,    ///< perceptually uniform, dark blue (low) to yellow (high)
  kOccupancy,  ///< white (0, free) to black (1, occupied), the usual occupancy-grid look
};

/// The colour of `t` in [0, 1] (clamped; NaN gives transparent).
[[nodiscard]] Color MapColor(Colormap map, double t);

}  // namespace priormap::render
