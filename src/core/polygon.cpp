#include <cmath>

#include <priormap/core/check.hpp>
#include <priormap/core/polygon.hpp>

namespace priormap {

Segment Polygon::Edge(std::size_t i) const {
  PRIORMAP_CHECK(i < vertices.size(), "edge index out of range");
  return {vertices[i], vertices[(i + 1) % vertices.size()]};
}

double RingSignedArea(std::span<const Vec2> ring) {
  double twice_area = 0.0;
  for (std::size_t i = 0; i < ring.size(); ++i)
    twice_area += Cross(ring[i], ring[(i + 1) % ring.size()]);
  return 0.5 * twice_area;
}

bool RingContains(std::span<const Vec2> ring, const Vec2& p) {
  bool inside = false;
  for (std::size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++) {
    const Vec2& a = ring[i];
    const Vec2& b = ring[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) &&
        p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x()) {
      inside = !inside;
    }
  }
  return inside;
}

double Polygon::SignedArea() const {
  return RingSignedArea(vertices);
}

double Polygon::Area() const {
  return std::abs(SignedArea());
}

double Polygon::Perimeter() const {
  double perimeter = 0.0;
  for (std::size_t i = 0; i < vertices.size(); ++i) perimeter += Edge(i).Length();
  return perimeter;
}

Vec2 Polygon::Centroid() const {
  const double area = SignedArea();
  PRIORMAP_CHECK(area != 0.0, "centroid of a polygon with zero area");
  Vec2 sum = Vec2::Zero();
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    const Vec2& p = vertices[i];
    const Vec2& q = vertices[(i + 1) % vertices.size()];
    sum += (p + q) * Cross(p, q);
  }
  return sum / (6.0 * area);
}

bool Polygon::Contains(const Vec2& p) const {
  return RingContains(vertices, p);
}

bool Polygon::IsSimple() const {
  const std::size_t n = vertices.size();
  if (n < 3) return false;
  for (std::size_t i = 0; i < n; ++i) {
    if (Edge(i).Length() == 0.0) return false;
  }
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      const bool adjacent = j == i + 1 || (i == 0 && j == n - 1);
      if (adjacent) continue;
      if (IntersectSegments(Edge(i), Edge(j))) return false;
    }
  }
  return true;
}

Box2 Polygon::Bounds() const {
  Box2 box;
  for (const Vec2& p : vertices) box.extend(p);
  return box;
}

}  // namespace priormap
