#include <array>
#include <cmath>
#include <optional>
#include <vector>

#include <priormap/core/polygon.hpp>
#include <priormap/prf/black_area.hpp>
#include <priormap/prf/polygon_map.hpp>

namespace priormap::prf {
namespace {

// The pairs of edges (i, i+1) and (j, j+1), i < j, of the closed ring that are not neighbours
// and touch; stops counting at `limit`.
struct Touch {
  std::size_t i, j;
};
std::vector<Touch> TouchingEdges(std::span<const Vec2> ring, std::size_t limit) {
  std::vector<Touch> touches;
  const std::size_t n = ring.size();
  for (std::size_t i = 0; i < n && touches.size() < limit; ++i)
    for (std::size_t j = i + 2; j < n && touches.size() < limit; ++j) {
      if (i == 0 && j == n - 1) continue;  // neighbours across the closing edge
      if (SegmentsTouch(ring[i], ring[(i + 1) % n], ring[j], ring[(j + 1) % n]))
        touches.push_back({i, j});
    }
  return touches;
}

// Where segments ab and cd cross, when they cross properly: at one point inside both, no end
// of either on the other, not parallel.
std::optional<Vec2> ProperCrossing(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  const double denominator = Cross(b - a, d - c);
  if (denominator == 0.0) return std::nullopt;
  const double t = Cross(c - a, d - c) / denominator;
  const double u = Cross(c - a, b - a) / denominator;
  if (!(t > 0.0 && t < 1.0 && u > 0.0 && u < 1.0)) return std::nullopt;
  const Vec2 x = a + t * (b - a);
  if (x == a || x == b || x == c || x == d) return std::nullopt;
  return x;
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

// True when no edge the edit keeps has an end or its midpoint strictly inside one of the loops
// (an edge inside a loop cannot leave it without crossing its border, which the edit's edges
// form).
bool NothingInside(const Coloring& coloring, const Edit& edit,
                   std::span<const std::vector<Vec2>> loops, std::span<const Vec2> ring) {
  bool empty = true;
  ForEachCellUnder(coloring.grid(), ring, [&](int cell) {
    for (const EdgeId e : coloring.cell_edges(cell)) {
      if (!empty) return;
      if (edit.Removes(e)) continue;
      const Segment s = coloring.EdgeSegment(e);
      for (const Vec2& p : {s.a, s.b, Vec2(0.5 * (s.a + s.b))})
        for (const std::vector<Vec2>& loop : loops)
          if (!IsRingVertex(loop, p) && RingContains(loop, p)) empty = false;
    }
  });
  return empty;
}

// The change of black area when a simple loop holding nothing of the coloring flips: plus its
// area when it is white now, minus when black.
std::optional<double> LoopChange(const Coloring& coloring, std::span<const Vec2> loop) {
  const double signed_area = RingSignedArea(loop);
  if (signed_area == 0.0) return std::nullopt;
  const std::optional<Vec2> inside = InteriorPoint(loop, signed_area);
  if (!inside) return std::nullopt;
  const double area = std::abs(signed_area);
  return coloring.ColourAt(*inside) == Colour::kWhite ? area : -area;
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
  if (ring.size() < 3) return std::nullopt;
  // A simple ring is one loop. A ring that crosses itself once (a bow tie: a vertex moved
  // past the line of its neighbours) is two, each simple, one on either side of the old
  // boundary: the one flips from black to white, the other from white to black.
  std::vector<std::vector<Vec2>> loops;
  const std::vector<Touch> touches = TouchingEdges(ring, 2);
  if (touches.empty()) {
    loops.emplace_back(ring.begin(), ring.end());
  } else if (touches.size() == 1) {
    const std::size_t n = ring.size();
    const auto [i, j] = touches[0];
    const auto x = ProperCrossing(ring[i], ring[(i + 1) % n], ring[j], ring[(j + 1) % n]);
    if (!x) return std::nullopt;
    std::vector<Vec2> first = {*x}, second = {*x};
    for (std::size_t k = i + 1; k <= j; ++k) first.push_back(ring[k]);
    for (std::size_t k = j + 1; k < n + i + 1; ++k) second.push_back(ring[k % n]);
    if (first.size() < 3 || second.size() < 3) return std::nullopt;
    loops = {std::move(first), std::move(second)};
  } else {
    return std::nullopt;
  }
  if (!NothingInside(coloring, edit, loops, ring)) return std::nullopt;
  double change = 0.0;
  for (const std::vector<Vec2>& loop : loops) {
    const std::optional<double> part = LoopChange(coloring, loop);
    if (!part) return std::nullopt;
    change += *part;
  }
  return change;
}

}  // namespace priormap::prf
