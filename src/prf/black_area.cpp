#include <array>
#include <cmath>

#include <priormap/core/polygon.hpp>
#include <priormap/prf/black_area.hpp>
#include <priormap/prf/polygon_map.hpp>

namespace priormap::prf {
namespace {

// True when two edges of the closed ring that are not neighbours touch.
bool SelfTouching(std::span<const Vec2> ring) {
  const std::size_t n = ring.size();
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // neighbours across the closing edge
      if (SegmentsTouch(ring[i], ring[(i + 1) % n], ring[j], ring[(j + 1) % n])) return true;
    }
  return false;
}

bool IsRingVertex(std::span<const Vec2> ring, const Vec2& p) {
  for (const Vec2& v : ring)
    if (v == p) return true;
  return false;
}

// A point strictly inside a simple ring: the centroid of an ear (a convex corner whose
// triangle holds no other vertex), which every simple polygon has.
std::optional<Vec2> InteriorPoint(std::span<const Vec2> ring, double orientation) {
  const std::size_t n = ring.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2& a = ring[(i + n - 1) % n];
    const Vec2& b = ring[i];
    const Vec2& c = ring[(i + 1) % n];
    if (Cross(b - a, c - b) * orientation <= 0.0) continue;  // reflex or flat
    const std::array<Vec2, 3> ear = {a, b, c};
    bool empty = true;
    for (std::size_t j = 0; j < n && empty; ++j) {
      const Vec2& p = ring[j];
      if (p == a || p == b || p == c) continue;
      empty = !RingContains(ear, p);
    }
    if (empty) return (a + b + c) / 3.0;
  }
  return std::nullopt;
}

}  // namespace

double BlackArea(const Coloring& coloring) {
  double area = 0.0;
  for (const MapFace& face : ExtractFaces(coloring)) {
    if (face.colour != Colour::kBlack) continue;
    area += face.area;
    for (const auto& hole : face.holes) area -= std::abs(RingSignedArea(hole));
  }
  return area;
}

std::optional<double> BlackAreaChange(const Coloring& coloring, const Edit& edit) {
  const std::span<const Vec2> ring{edit.flipped_region.begin(), edit.flipped_region.size()};
  if (ring.size() < 3 || SelfTouching(ring)) return std::nullopt;
  const double signed_area = RingSignedArea(ring);
  if (signed_area == 0.0) return std::nullopt;
  // Nothing of the coloring inside: no edge left by the edit has an end or its midpoint
  // strictly inside (an edge inside the region cannot leave it without crossing its border).
  bool empty = true;
  ForEachCellUnder(coloring.grid(), ring, [&](int cell) {
    for (const EdgeId e : coloring.cell_edges(cell)) {
      if (!empty) return;
      if (edit.Removes(e)) continue;
      const Segment s = coloring.EdgeSegment(e);
      for (const Vec2& p : {s.a, s.b, Vec2(0.5 * (s.a + s.b))})
        if (!IsRingVertex(ring, p) && RingContains(ring, p)) empty = false;
    }
  });
  if (!empty) return std::nullopt;
  const std::optional<Vec2> inside = InteriorPoint(ring, signed_area);
  if (!inside) return std::nullopt;
  const double area = std::abs(signed_area);
  return coloring.ColourAt(*inside) == Colour::kWhite ? area : -area;
}

}  // namespace priormap::prf
