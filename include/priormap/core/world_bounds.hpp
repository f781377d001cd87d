#pragma once
/// How far from the origin the positions priormap reads may lie, and how long a return may be.

#include <algorithm>
#include <cmath>
#include <optional>
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

/// The largest radius of a circle about (x, y), a point within the world, that keeps x and y of
/// every point of the circle within kMaxWorldCoordinate: the one rule of the scene reader and
/// writer, so that whatever one accepts the other does.
[[nodiscard]] inline double LargestRadiusWithinWorld(double x, double y) {
  return kMaxWorldCoordinate - std::max(std::abs(x), std::abs(y));
}

/// Why a circle of `radius` about (x, y), a centre within the world, is not within it whole
/// (`radius` > LargestRadiusWithinWorld(x, y), or NaN), in the scene reader's words: "expected a
/// radius of at most 0.25 m, which keeps x and y of every point of the circle about (...) within
/// ±1e+09 m, got 0.35", or, for a centre on the bound, where no radius would do, that the centre
/// must move inwards; nullopt when the whole circle lies within the world. The reader refuses the
/// radius with this message and the writer quotes it, so that both say the same.
[[nodiscard]] std::optional<std::string> CircleBeyondWorld(double x, double y, double radius);

/// For writers: "`field` theta = nan, not a finite angle" when `theta`, a heading, is not finite
/// (Se2 wraps ±inf to NaN), which the readers refuse; nullopt otherwise.
[[nodiscard]] std::optional<std::string> HeadingNotFinite(std::string_view field, double theta);

/// The readers' message for a coordinate beyond kMaxWorldCoordinate: "expected `what` in metres
/// of a local frame, at most 1e+09 in magnitude, got `got`".
[[nodiscard]] std::string ExpectedWorldCoordinate(std::string_view what, std::string_view got);

/// Whether `range` (a return: a distance to a surface, m) is at most kMaxWorldCoordinate. Like a
/// coordinate, a return of 1e300 m is an error in the file; the bound keeps every point a return
/// gives within a few times kMaxWorldCoordinate of the origin, so that it can be gridded and
/// drawn. A no-return reading (at or above the max range) has no bound: it is kept as read.
[[nodiscard]] inline bool IsReturnWithinWorld(double range) {
  return std::abs(range) <= kMaxWorldCoordinate;
}

/// The readers' message for a return (a reading below the scan's `max_range`) longer than
/// kMaxWorldCoordinate: "expected `what` in metres, at most 1e+09 for a return or at or above
/// the max range (`max_range` m) for no return, got `got`".
[[nodiscard]] std::string ExpectedReturnWithinWorld(std::string_view what, std::string_view got,
                                                    double max_range);

/// For writers, which refuse what the readers would: "`field` x = 1e+300" when x (or else y) is
/// beyond kMaxWorldCoordinate or not finite; nullopt when both are within the world.
[[nodiscard]] std::optional<std::string> CoordinateBeyondWorld(std::string_view field, double x,
                                                               double y);

/// The writers' message for a value that the readers would refuse: "cannot write `what`:
/// `beyond`, beyond 1e+09 m in magnitude, ...".
[[nodiscard]] std::string CannotWriteBeyondWorld(std::string_view what, std::string_view beyond);

/// The writers' message for a value that the readers would refuse for another reason than the
/// world's bound, `refused` naming it: "cannot write `what`: `refused`; priormap's readers refuse
/// it (docs/formats.md)".
[[nodiscard]] std::string CannotWriteRefused(std::string_view what, std::string_view refused);

}  // namespace priormap
