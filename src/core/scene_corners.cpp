#include <cmath>

#include <priormap/core/scene_corners.hpp>

namespace priormap {
namespace {

// Two walls leaving a vertex in opposite directions, to rounding.
bool IsStraight(const Vec2& a, const Vec2& b) {
  constexpr double kTolerance = 1e-9;
  return std::abs(Cross(a, b)) < kTolerance && a.dot(b) < 0.0;
}

}  // namespace

bool SceneCorner::IsConcaveFrom(const Vec2& viewpoint) const {
  if (IsFreeEnd()) return false;
  // The viewpoint sees the corner from inside the angle between the walls when it lies
  // strictly left of one wall and right of the other, turning the short way round.
  const Vec2 to_viewpoint = viewpoint - point;
  const double turn = Cross(walls[0], walls[1]);
  if (turn == 0.0) return false;  // straight or folded back: no reflector
  const double sign = turn > 0.0 ? 1.0 : -1.0;
  return sign * Cross(walls[0], to_viewpoint) > 0.0 && sign * Cross(to_viewpoint, walls[1]) > 0.0;
}

std::vector<SceneCorner> SceneCorners(const Scene& scene) {
  std::vector<SceneCorner> corners;
  int first_region = 0;
  for (std::size_t s = 0; s < scene.surfaces.size(); ++s) {
    const auto* polyline = std::get_if<Polyline>(&scene.surfaces[s].shape);
    if (polyline == nullptr) {
      ++first_region;  // a circle is one region
      continue;
    }
    const std::vector<Vec2>& p = polyline->points;
    const std::size_t n = p.size();
    const auto direction = [&](std::size_t from, std::size_t to) {
      return Vec2((p[to] - p[from]).normalized());
    };
    const auto add = [&](std::size_t at, int region0, std::size_t towards0, int region1,
                         std::size_t towards1) {
      SceneCorner c;
      c.point = p[at];
      c.surface = static_cast<int>(s);
      c.regions = {region0, region1};
      c.walls[0] = direction(at, towards0);
      if (region1 >= 0) {
        c.walls[1] = direction(at, towards1);
        // A vertex in the middle of a straight wall is no reflector: no corner echo from it.
        if (IsStraight(c.walls[0], c.walls[1])) return;
      }
      corners.push_back(c);
    };
    const int segments = static_cast<int>(polyline->NumSegments());
    if (polyline->closed) {
      // Point i joins segment i - 1 (from p[i - 1]) and segment i (to p[i + 1]).
      for (std::size_t i = 0; i < n; ++i) {
        const int before = first_region + static_cast<int>((i + n - 1) % n);
        add(i, before, (i + n - 1) % n, first_region + static_cast<int>(i), (i + 1) % n);
      }
    } else if (n >= 2) {
      add(0, first_region, 1, -1, 0);
      for (std::size_t i = 1; i + 1 < n; ++i)
        add(i, first_region + static_cast<int>(i) - 1, i - 1, first_region + static_cast<int>(i),
            i + 1);
      add(n - 1, first_region + segments - 1, n - 2, -1, 0);
    }
    first_region += segments;
  }
  return corners;
}

}  // namespace priormap
