#pragma once
// Lines and polygons clipped, in doubles, to a box before Cairo sees them. Cairo's 24.8
// fixed-point coordinates wrap beyond about 8.4 million pixels, which turned lines to far points
// round and filled the whole figure for far polygons, and it draws NaN as some point.

#include <span>
#include <vector>

#include <priormap/core/types.hpp>

namespace priormap::render::detail {

struct ClippedPolyline {
  /// Runs of joined segments, each of at least two points, except that a polyline of one point
  /// that lies in the box gives that point alone.
  std::vector<std::vector<Vec2>> pieces;
  /// The polyline was closed and nothing of it was cut: the one piece is to be closed.
  bool closed = false;
};

/// The parts inside `box` of the polyline through `points` (closed: back to the first), each
/// segment clipped to the box (Liang & Barsky). A point with a non-finite coordinate breaks the
/// line. A polyline wholly inside comes back as it is.
[[nodiscard]] ClippedPolyline ClipPolyline(std::span<const Vec2> points, bool closed,
                                           const Box2& box);

/// The part of `polygon` inside `box` (Sutherland & Hodgman: edges along the box where the
/// polygon reaches beyond it); empty when nothing of it is inside. Precondition: finite vertices.
[[nodiscard]] std::vector<Vec2> ClipPolygon(std::span<const Vec2> polygon, const Box2& box);

}  // namespace priormap::render::detail
