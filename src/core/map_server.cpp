#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include <fmt/format.h>

#include <priormap/core/file_io.hpp>
#include <priormap/core/map_server.hpp>
#include <priormap/core/utf8.hpp>

namespace priormap {
namespace {

// Characters a YAML double-quoted scalar must not hold as they are: the non-printable ones (YAML
// 1.2, 5.1), and those YAML 1.1 parsers (map_server's yaml-cpp) take as line breaks (NEL, LS, PS),
// which a quoted scalar folds into a space. The byte order mark too, which some parsers strip.
bool NeedsEscape(std::uint32_t code) {
  return code < 0x20 || code == 0x7F || (code >= 0x80 && code <= 0x9F) || code == 0x2028 ||
         code == 0x2029 || code == 0xFEFF || code == 0xFFFE || code == 0xFFFF;
}

// A plain scalar only for names that no YAML parser can misread: an indicator character first
// (- ? : , [ ] { } # & * ! | > ' " % @ `), ": " or " #" inside, or a name that resolves to
// another type (true, null, 1.5, .inf) all need quotes; a name ending in ".pgm" of letters,
// digits, '.', '_' and '-', not starting with '-' or '.', has none of these.
bool IsPlainSafe(std::string_view name) {
  const auto word = [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
  };
  return name.size() > 4 && name.ends_with(".pgm") && word(name.front()) &&
         std::all_of(name.begin(), name.end(),
                     [&](char c) { return word(c) || c == '.' || c == '-'; });
}

}  // namespace

std::optional<std::string> YamlScalar(std::string_view text) {
  if (IsPlainSafe(text)) return std::string(text);
  std::string out = "\"";
  for (std::size_t at = 0; at < text.size();) {
    const std::optional<Utf8Char> decoded = DecodeUtf8(text, at);
    if (!decoded) return std::nullopt;
    const auto [code, length] = *decoded;
    if (code == '"' || code == '\\') {
      out += '\\';
      out += static_cast<char>(code);
    } else if (NeedsEscape(code)) {
      out += code <= 0xFF ? fmt::format("\\x{:02X}", code) : fmt::format("\\u{:04X}", code);
    } else {
      out.append(text.substr(at, length));
    }
    at += length;
  }
  return out + "\"";
}

std::string YamlFloat(double value) {
  const std::string shortest = fmt::format("{}", value);
  const std::size_t exponent = shortest.find('e');
  std::string mantissa = shortest.substr(0, exponent);
  if (mantissa.find('.') == std::string::npos) mantissa += ".0";
  return exponent == std::string::npos ? mantissa : mantissa + shortest.substr(exponent);
}

unsigned char MapServerPixel(double probability) {
  if (std::isnan(probability)) return 205;
  const double p = std::clamp(probability, 0.0, 1.0);
  return static_cast<unsigned char>(std::lround((1.0 - p) * 255.0));
}

void WriteMapServerMap(const std::filesystem::path& yaml_path, const OccupancyRaster& raster) {
  std::filesystem::path pgm_path = yaml_path;
  pgm_path.replace_extension(".pgm");
  // Checked before either file is written: a PGM without its YAML would be left behind.
  const auto refuse = [&](std::string_view why) {
    throw IoError(fmt::format("cannot write the map_server map {}: {}", yaml_path.string(), why));
  };
  if (!(std::isfinite(raster.resolution) && raster.resolution > 0.0)) {
    refuse(
        fmt::format("resolution = {}, not a finite number > 0 (m per cell), which ROS "
                    "map_server refuses",
                    raster.resolution));
  }
  for (const auto& [axis, value] : {std::pair{"x", raster.origin.x()}, {"y", raster.origin.y()}}) {
    if (!std::isfinite(value)) {
      refuse(fmt::format("origin {} = {}, not a finite number (m), which ROS map_server refuses",
                         axis, value));
    }
  }
  const std::string name = pgm_path.filename().string();
  const std::optional<std::string> image = YamlScalar(name);
  if (!image) refuse(fmt::format("the image name {:?} is not UTF-8, which YAML cannot hold", name));

  const Eigen::MatrixXd& p = raster.probability;
  std::string pgm = fmt::format("P5\n{} {}\n255\n", p.cols(), p.rows());
  const std::size_t header = pgm.size();
  pgm.resize(header + static_cast<std::size_t>(p.rows() * p.cols()));
  std::size_t at = header;
  for (Eigen::Index row = p.rows() - 1; row >= 0; --row)  // top of the map first
    for (Eigen::Index col = 0; col < p.cols(); ++col)
      pgm[at++] = static_cast<char>(MapServerPixel(p(row, col)));
  WriteTextFileAtomically(pgm_path, pgm);
  WriteTextFileAtomically(
      yaml_path, fmt::format("image: {}\nresolution: {}\norigin: [{}, {}, 0.0]\nnegate: 0\n"
                             "occupied_thresh: 0.65\nfree_thresh: 0.196\nmode: trinary\n",
                             *image, YamlFloat(raster.resolution), YamlFloat(raster.origin.x()),
                             YamlFloat(raster.origin.y())));
}

}  // namespace priormap
