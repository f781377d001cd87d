#include <array>
#include <cmath>
#include <optional>
#include <vector>

#include <fmt/format.h>

#include <priormap/core/segment.hpp>
#include <priormap/prf/scene_coloring.hpp>

namespace priormap::prf {
namespace {

// The side of the window's boundary that p (on it) lies on, with p put exactly on it; -1 at a
// corner, where no boundary vertex may sit.
int SnapToSide(const Window& w, Vec2* p) {
  const double tolerance = 1e-9 * (w.Width() + w.Height());
  const bool left = std::abs(p->x() - w.min.x()) <= tolerance;
  const bool right = std::abs(p->x() - w.max.x()) <= tolerance;
  const bool bottom = std::abs(p->y() - w.min.y()) <= tolerance;
  const bool top = std::abs(p->y() - w.max.y()) <= tolerance;
  if ((left || right) && (bottom || top)) return -1;
  if (bottom) return p->y() = w.min.y(), 0;
  if (right) return p->x() = w.max.x(), 1;
  if (top) return p->y() = w.max.y(), 2;
  if (left) return p->x() = w.min.x(), 3;
  return -1;
}

}  // namespace

std::variant<Coloring, std::string> SceneColoring(const Scene& scene, const SceneTruth& truth,
                                                  const Window& window, double cell_size) {
  std::vector<NewVertex> vertices;
  std::vector<std::array<int, 2>> edges;
  for (std::size_t s = 0; s < scene.surfaces.size(); ++s) {
    const auto* polyline = std::get_if<Polyline>(&scene.surfaces[s].shape);
    if (polyline == nullptr || !polyline->closed)
      return fmt::format(
          "surface {} is not a closed polyline: only closed polylines bound regions of a coloring",
          s);
    const std::size_t n = polyline->points.size();
    // The index of each polyline point inside the window, -1 outside.
    std::vector<int> inside(n, -1);
    for (std::size_t i = 0; i < n; ++i) {
      const Vec2& p = polyline->points[i];
      if (window.ContainsInterior(p)) {
        inside[i] = static_cast<int>(vertices.size());
        vertices.push_back({p, kInterior});
      } else if (p.x() >= window.min.x() && p.x() <= window.max.x() && p.y() >= window.min.y() &&
                 p.y() <= window.max.y()) {
        return fmt::format("surface {}: point {} lies on the window's boundary", s, i);
      }
    }
    const auto boundary_vertex = [&](Vec2 p) -> int {
      const int side = SnapToSide(window, &p);
      if (side < 0) return -1;
      vertices.push_back({p, side});
      return static_cast<int>(vertices.size()) - 1;
    };
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t j = (i + 1) % n;
      const Vec2& a = polyline->points[i];
      const Vec2& b = polyline->points[j];
      const std::optional<Segment> clipped = ClipSegmentToBox({a, b}, Box2(window.min, window.max));
      if (!clipped || clipped->a == clipped->b) continue;  // outside, or only touching it
      const int from = inside[i] >= 0 ? inside[i] : boundary_vertex(clipped->a);
      const int to = inside[j] >= 0 ? inside[j] : boundary_vertex(clipped->b);
      if (from < 0 || to < 0)
        return fmt::format("surface {}: segment {} meets a corner of the window", s, i);
      edges.push_back({from, to});
    }
  }
  const Colour anchor =
      truth.Occupied(Coloring(window, cell_size).anchor()) ? Colour::kBlack : Colour::kWhite;
  return Coloring::FromGraph(window, cell_size, vertices, edges, anchor);
}

}  // namespace priormap::prf
