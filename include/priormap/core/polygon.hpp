#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include <priormap/core/segment.hpp>

namespace priormap {

/// Shoelace area of the closed ring `ring` (the last vertex joins the first): positive when
/// counter-clockwise.
[[nodiscard]] double RingSignedArea(std::span<const Vec2> ring);
/// Even-odd rule point-in-ring test; points exactly on the boundary may go either way.
[[nodiscard]] bool RingContains(std::span<const Vec2> ring, const Vec2& p);

/// A simple polygon given by its vertices (either orientation; the last joins the first).
struct Polygon {
  std::vector<Vec2> vertices;

  [[nodiscard]] std::size_t size() const { return vertices.size(); }
  /// Edge i joins vertices i and i + 1 (mod size).
  [[nodiscard]] Segment Edge(std::size_t i) const;
  /// Positive for counter-clockwise vertices (shoelace formula).
  [[nodiscard]] double SignedArea() const;
  [[nodiscard]] double Area() const;
  [[nodiscard]] double Perimeter() const;
  /// Area centroid. Precondition: non-zero area.
  [[nodiscard]] Vec2 Centroid() const;
  /// Even-odd rule; points exactly on the boundary may go either way.
  [[nodiscard]] bool Contains(const Vec2& p) const;
  /// No two non-adjacent edges meet, and no edge is degenerate. O(n^2).
  [[nodiscard]] bool IsSimple() const;
  [[nodiscard]] Box2 Bounds() const;
};

}  // namespace priormap
