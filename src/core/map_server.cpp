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

namespace priormap {
namespace {

// The code point of the UTF-8 sequence at `text[at]` and its length, or nullopt when the bytes
// there are not one (overlong, surrogate, beyond U+10FFFF, cut short).
std::optional<std::pair<std::uint32_t, std::size_t>> DecodeUtf8(std::string_view text,
                                                                std::size_t at) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[at + k]); };
  const unsigned char lead = byte(0);
  if (lead < 0x80) return std::pair<std::uint32_t, std::size_t>{lead, 1};
  std::size_t length = 0;
  std::uint32_t code = 0;
  std::uint32_t smallest = 0;
  if ((lead & 0xE0) == 0xC0) {
    length = 2, code = lead & 0x1Fu, smallest = 0x80;
  } else if ((lead & 0xF0) == 0xE0) {
    length = 3, code = lead & 0x0Fu, smallest = 0x800;
  } else if ((lead & 0xF8) == 0xF0) {
    length = 4, code = lead & 0x07u, smallest = 0x10000;
  } else {
    return std::nullopt;
  }
  if (at + length > text.size()) return std::nullopt;
  for (std::size_t k = 1; k < length; ++k) {
    if ((byte(k) & 0xC0) != 0x80) return std::nullopt;
    code = code << 6 | (byte(k) & 0x3Fu);
  }
  if (code < smallest || code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF)) return std::nullopt;
  return std::pair<std::uint32_t, std::size_t>{code, length};
}

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
    const auto decoded = DecodeUtf8(text, at);
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
                             *image, raster.resolution, raster.origin.x(), raster.origin.y()));
}

}  // namespace priormap
