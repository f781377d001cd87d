#pragma once
/// How far from the origin the positions priormap reads may lie.

#include <cmath>
#include <string>
#include <string_view>

namespace priormap {

/// The largest magnitude of a world coordinate (x or y, metres in a local frame) that readers
/// accept: 1e9 m is 25 times round the Earth, far beyond any map, yet small enough that extents
/// (max - min) stay finite and grids, rasters and figures can be sized over them. A finite but
/// absurd coordinate (1e300) is refused where it is written, at file:line:col, instead of
/// failing later as a grid too large, far from its cause.
inline constexpr double kMaxWorldCoordinate = 1e9;

/// Whether |coordinate| <= kMaxWorldCoordinate (false for NaN).
[[nodiscard]] inline bool IsWithinWorld(double coordinate) {
  return std::abs(coordinate) <= kMaxWorldCoordinate;
}

/// The readers' message for a coordinate beyond kMaxWorldCoordinate: "expected `what` in metres
/// of a local frame, at most 1e+09 in magnitude, got `got`".
[[nodiscard]] std::string ExpectedWorldCoordinate(std::string_view what, std::string_view got);

}  // namespace priormap
