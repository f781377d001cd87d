#pragma once
/// Occupancy rasters as a ROS map_server pair: an 8-bit binary PGM (P5) and its YAML
/// (image, resolution, origin, negate, occupied_thresh, free_thresh, mode), as map_server's
/// map_saver writes them. With negate 0 a pixel x means occupancy probability (255 - x) / 255;
/// the first image row is the top of the map (largest y); origin is the pose of the lower-left
/// pixel's corner.

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include <Eigen/Core>

#include <priormap/core/types.hpp>

namespace priormap {

struct OccupancyRaster {
  /// P(occupied) per cell, row 0 at the bottom (smallest y); NaN where unknown.
  Eigen::MatrixXd probability;
  Vec2 origin = Vec2::Zero();  ///< lower-left corner of cell (0, 0), m
  double resolution = 0.05;    ///< m per cell
};

/// The PGM pixel of a probability: (1 - p) * 255 rounded; 205 (map_saver's unknown) for NaN.
[[nodiscard]] unsigned char MapServerPixel(double probability);

/// `text` as a YAML scalar that every YAML parser reads back as the string `text`: as it is when it
/// is a plain file name (letters, digits, '.', '_', '-', ending in ".pgm"), otherwise
/// double-quoted, with '"' and '\\' escaped and characters that YAML cannot hold raw (controls,
/// line separators) as \xXX or \uXXXX. nullopt when `text` is not UTF-8: YAML holds only Unicode.
[[nodiscard]] std::optional<std::string> YamlScalar(std::string_view text);

/// A finite `value` as the shortest text that reads back exactly and that YAML 1.1 parsers
/// (PyYAML) as well as 1.2 ones (yaml-cpp) resolve to a float: 1.0e-05 and 2.0, not the shortest
/// 1e-05 and 2, which YAML 1.1 reads as a string and an integer.
[[nodiscard]] std::string YamlFloat(double value);

/// Writes `yaml_path` and the PGM beside it (same stem, .pgm), each atomically; the YAML names the
/// PGM by its file name (YamlScalar). Throws IoError, before writing anything, for a resolution
/// that is not finite and > 0, a non-finite origin, or a file name that is not UTF-8.
void WriteMapServerMap(const std::filesystem::path& yaml_path, const OccupancyRaster& raster);

}  // namespace priormap
