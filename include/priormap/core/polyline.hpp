#pragma once

#include <cstddef>
#include <vector>

#include <priormap/core/segment.hpp>

namespace priormap {

/// A chain of segments through `points`; when `closed`, the last point joins the first.
struct Polyline {
  std::vector<Vec2> points;
  bool closed = false;

  [[nodiscard]] std::size_t NumSegments() const;
  /// Segment i joins points[i] and points[(i + 1) % size]. Precondition: i < NumSegments().
  [[nodiscard]] Segment segment(std::size_t i) const;
  [[nodiscard]] double Length() const;
  /// Distance from p to the closest segment; `segment_index` receives that segment.
  [[nodiscard]] double Distance(const Vec2& p, std::size_t* segment_index = nullptr) const;
  [[nodiscard]] Box2 Bounds() const;
};

}  // namespace priormap
