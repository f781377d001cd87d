#pragma once
// Brute-force versions of what the coloring's grid index answers quickly, for the tests.
#include <algorithm>
#include <set>
#include <vector>

#include <priormap/prf/cell_grid.hpp>
#include <priormap/prf/coloring.hpp>

namespace priormap::prf {

// The cells whose closed rectangle meets segment ab, by clipping (Liang–Barsky) the segment to
// every cell: independent of the DDA.
inline std::set<int> CellsByClipping(const CellGrid& grid, const Vec2& a, const Vec2& b) {
  std::set<int> cells;
  const Vec2 d = b - a;
  for (int iy = 0; iy < grid.ny; ++iy) {
    for (int ix = 0; ix < grid.nx; ++ix) {
      const Vec2 lo = grid.origin + Vec2(ix * grid.cell.x(), iy * grid.cell.y());
      const Vec2 hi = lo + grid.cell;
      double t0 = 0.0, t1 = 1.0;
      bool inside = true;
      for (int k = 0; k < 2 && inside; ++k) {
        if (d[k] == 0.0) {
          inside = a[k] >= lo[k] && a[k] <= hi[k];
          continue;
        }
        double ta = (lo[k] - a[k]) / d[k], tb = (hi[k] - a[k]) / d[k];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
        inside = t0 <= t1;
      }
      if (inside) cells.insert(iy * grid.nx + ix);
    }
  }
  return cells;
}

// The segments of all edges of a coloring.
inline std::vector<Segment> AllEdges(const Coloring& coloring) {
  std::vector<Segment> segments;
  for (EdgeId e : coloring.edge_ids()) segments.push_back(coloring.EdgeSegment(e));
  return segments;
}

// Number of edges properly crossing the open segment ab.
inline int CrossingsByBruteForce(const Coloring& coloring, const Vec2& a, const Vec2& b) {
  int count = 0;
  for (const Segment& s : AllEdges(coloring)) {
    const double o1 = Cross(b - a, s.a - a), o2 = Cross(b - a, s.b - a);
    const double o3 = Cross(s.b - s.a, a - s.a), o4 = Cross(s.b - s.a, b - s.a);
    count += (o1 * o2 < 0.0 && o3 * o4 < 0.0);
  }
  return count;
}

// Number of other edges sharing a grid cell with segment ab (cells by clipping), leaving out
// the edges whose segments are in `excluded`.
inline int CellNeighboursByBruteForce(const Coloring& coloring, const Vec2& a, const Vec2& b,
                                      const std::vector<Segment>& excluded) {
  const std::set<int> mine = CellsByClipping(coloring.grid(), a, b);
  int count = 0;
  for (const Segment& s : AllEdges(coloring)) {
    const auto same = [&](const Segment& t) {
      return (t.a == s.a && t.b == s.b) || (t.a == s.b && t.b == s.a);
    };
    if (same({a, b}) || std::any_of(excluded.begin(), excluded.end(), same)) continue;
    const std::set<int> theirs = CellsByClipping(coloring.grid(), s.a, s.b);
    count += std::any_of(theirs.begin(), theirs.end(), [&](int c) { return mine.count(c) > 0; });
  }
  return count;
}

}  // namespace priormap::prf
