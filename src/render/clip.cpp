#include "clip.hpp"

#include <algorithm>
#include <utility>

#include <priormap/core/segment.hpp>

namespace priormap::render::detail {

ClippedPolyline ClipPolyline(std::span<const Vec2> points, bool closed, const Box2& box) {
  ClippedPolyline out;
  const std::size_t n = points.size();
  const bool inside = std::all_of(points.begin(), points.end(),
                                  [&](const Vec2& p) { return p.allFinite() && box.contains(p); });
  if (inside) {
    if (n > 0) out.pieces.emplace_back(points.begin(), points.end());
    out.closed = closed;
    return out;
  }
  if (n < 2) return out;
  // Whether the last piece ends at the uncut end of the segment before (where the next starts).
  bool joined = false;
  bool first_starts_uncut = false;  // the first segment's piece begins at points[0]
  const std::size_t segments = closed ? n : n - 1;
  for (std::size_t i = 0; i < segments; ++i) {
    const Vec2& a = points[i];
    const Vec2& b = points[(i + 1) % n];
    if (!a.allFinite() || !b.allFinite()) {
      joined = false;
      continue;
    }
    const auto [t0, t1] = ClipParametersToBox(a, b, box);
    if (!(t0 <= t1)) {
      joined = false;
      continue;
    }
    // The ends themselves where uncut, so that pieces join exactly.
    const Vec2 start = t0 == 0.0 ? a : Vec2(a + t0 * (b - a));
    const Vec2 end = t1 == 1.0 ? b : Vec2(a + t1 * (b - a));
    if (!start.allFinite() || !end.allFinite()) {  // a span wider than the largest double
      joined = false;
      continue;
    }
    if (!(joined && t0 == 0.0)) {
      out.pieces.push_back({start});
      if (i == 0) first_starts_uncut = t0 == 0.0;
    }
    out.pieces.back().push_back(end);
    joined = t1 == 1.0;
  }
  // A closed line whose last piece runs uncut into the first: one piece.
  if (closed && joined && first_starts_uncut && out.pieces.size() > 1) {
    std::vector<Vec2>& last = out.pieces.back();
    last.insert(last.end(), out.pieces.front().begin() + 1, out.pieces.front().end());
    out.pieces.erase(out.pieces.begin());
  }
  return out;
}

std::vector<Vec2> ClipPolygon(std::span<const Vec2> polygon, const Box2& box) {
  std::vector<Vec2> current(polygon.begin(), polygon.end());
  // Against each of the four half-planes in turn: x >= min.x, x <= max.x, y >= min.y, y <= max.y.
  for (int k = 0; k < 2; ++k) {
    for (const bool upper : {false, true}) {
      if (current.empty()) return current;
      const double bound = upper ? box.max()[k] : box.min()[k];
      const auto in = [&](const Vec2& p) { return upper ? p[k] <= bound : p[k] >= bound; };
      std::vector<Vec2> next;
      next.reserve(current.size() + 4);
      for (std::size_t i = 0; i < current.size(); ++i) {
        const Vec2& a = current[i];
        const Vec2& b = current[(i + 1) % current.size()];
        if (in(a)) next.push_back(a);
        if (in(a) != in(b)) {
          const double t = (bound - a[k]) / (b[k] - a[k]);
          Vec2 crossing = a + t * (b - a);
          crossing[k] = bound;  // exactly on the edge, whatever the rounding
          next.push_back(crossing);
        }
      }
      current = std::move(next);
    }
  }
  return current;
}

}  // namespace priormap::render::detail
