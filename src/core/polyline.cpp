#include <limits>

#include <priormap/core/check.hpp>
#include <priormap/core/polyline.hpp>

namespace priormap {

std::size_t Polyline::NumSegments() const {
  if (points.size() < 2) return 0;
  return closed ? points.size() : points.size() - 1;
}

Segment Polyline::segment(std::size_t i) const {
  PRIORMAP_CHECK(i < NumSegments(), "segment index out of range");
  return {points[i], points[(i + 1) % points.size()]};
}

double Polyline::Length() const {
  double length = 0.0;
  for (std::size_t i = 0; i < NumSegments(); ++i) length += segment(i).Length();
  return length;
}

double Polyline::Distance(const Vec2& p, std::size_t* segment_index) const {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < NumSegments(); ++i) {
    const double d = PointSegmentDistance(p, segment(i));
    if (d < best) {
      best = d;
      if (segment_index) *segment_index = i;
    }
  }
  return best;
}

Box2 Polyline::Bounds() const {
  Box2 box;
  for (const Vec2& p : points) box.extend(p);
  return box;
}

}  // namespace priormap
