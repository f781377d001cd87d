#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <variant>

#include <fmt/format.h>

#include <priormap/core/check.hpp>
#include <priormap/core/scene_truth.hpp>

namespace priormap {
namespace {

int Orientation(const Vec2& a, const Vec2& b, const Vec2& c) {
  const double v = Cross(b - a, c - a);
  return (v > 0.0) - (v < 0.0);
}

// c, collinear with ab, lies within the segment's box.
bool WithinBox(const Vec2& a, const Vec2& b, const Vec2& c) {
  return std::min(a.x(), b.x()) <= c.x() && c.x() <= std::max(a.x(), b.x()) &&
         std::min(a.y(), b.y()) <= c.y() && c.y() <= std::max(a.y(), b.y());
}

bool ClosedSegmentsTouch(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  const int o1 = Orientation(a, b, c);
  const int o2 = Orientation(a, b, d);
  const int o3 = Orientation(c, d, a);
  const int o4 = Orientation(c, d, b);
  if (o1 != o2 && o3 != o4) return true;
  return (o1 == 0 && WithinBox(a, b, c)) || (o2 == 0 && WithinBox(a, b, d)) ||
         (o3 == 0 && WithinBox(c, d, a)) || (o4 == 0 && WithinBox(c, d, b));
}

Box2 WallBounds(const ScenePrimitive& wall) {
  return std::visit([](const auto& shape) { return shape.Bounds(); }, wall.shape);
}

}  // namespace

bool SegmentTouchesWall(const Vec2& a, const Vec2& b, const ScenePrimitive& wall) {
  if (const auto* segment = std::get_if<Segment>(&wall.shape))
    return ClosedSegmentsTouch(a, b, segment->a, segment->b);
  // The curve meets the segment when the segment has points both within and beyond the radius.
  const Circle& circle = std::get<Circle>(wall.shape);
  const double nearest = PointSegmentDistance(circle.center, Segment{a, b});
  const double farthest = std::max((a - circle.center).norm(), (b - circle.center).norm());
  return nearest <= circle.radius && circle.radius <= farthest;
}

double DistanceToWall(const Vec2& p, const ScenePrimitive& wall) {
  if (const auto* segment = std::get_if<Segment>(&wall.shape))
    return PointSegmentDistance(p, *segment);
  return std::get<Circle>(wall.shape).DistanceToBoundary(p);
}

SceneTruth::SceneTruth(const Scene& scene, std::span<const Vec2> seeds,
                       const SceneTruthOptions& options)
    : walls_(scene.Primitives()), resolution_(options.resolution) {
  PRIORMAP_CHECK(options.resolution > 0.0 && options.margin >= 2.0 * options.resolution,
                 "the truth raster needs a positive cell and a margin of two cells");
  PRIORMAP_CHECK(!seeds.empty(), "the truth needs at least one point of the free space");
  Box2 box;
  for (const ScenePrimitive& wall : walls_) {
    bounds_.push_back(WallBounds(wall));
    box.extend(bounds_.back());
  }
  for (const Vec2& seed : seeds) {
    PRIORMAP_CHECK(seed.allFinite(), "a seed of the free space is not finite");
    box.extend(seed);
  }
  origin_ = box.min() - Vec2::Constant(options.margin);
  const Vec2 size = (box.sizes() + Vec2::Constant(2.0 * options.margin)) / resolution_;
  PRIORMAP_CHECK(size.x() * size.y() < 2e8, "the truth raster would exceed 2e8 cells");
  nx_ = static_cast<int>(std::ceil(size.x()));
  ny_ = static_cast<int>(std::ceil(size.y()));
  const auto cells = static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_);
  blocked_right_.assign(cells, 0);
  blocked_up_.assign(cells, 0);
  near_wall_.assign(cells, 0);
  free_.assign(cells, 0);
  MarkBarriers();
  FloodFill(seeds);
  // The margin holds no wall, so the raster's border lies in the unbounded face.
  outside_free_ = free_[0] != 0;
}

SceneTruth SceneTruth::OfScene(const Scene& scene, const SceneTruthOptions& options) {
  std::vector<Vec2> seeds = scene.waypoints;
  if (scene.default_pose) seeds.push_back(scene.default_pose->translation());
  return SceneTruth(scene, seeds, options);
}

void SceneTruth::MarkBarriers() {
  for (std::size_t w = 0; w < walls_.size(); ++w) {
    const Box2& box = bounds_[w];
    // Centres whose edges to a neighbour can reach the wall's box.
    const auto first = [&](double v, double o) {
      return static_cast<int>(std::floor((v - o) / resolution_ - 1.5));
    };
    const auto last = [&](double v, double o) {
      return static_cast<int>(std::ceil((v - o) / resolution_ + 0.5));
    };
    const int x0 = std::max(0, first(box.min().x(), origin_.x()));
    const int y0 = std::max(0, first(box.min().y(), origin_.y()));
    const int x1 = std::min(nx_ - 1, last(box.max().x(), origin_.x()));
    const int y1 = std::min(ny_ - 1, last(box.max().y(), origin_.y()));
    for (int iy = y0; iy <= y1; ++iy) {
      for (int ix = x0; ix <= x1; ++ix) {
        const std::size_t i = Index(ix, iy);
        const Vec2 c = Centre(ix, iy);
        if (ix + 1 < nx_ && SegmentTouchesWall(c, Centre(ix + 1, iy), walls_[w])) {
          blocked_right_[i] = 1;
          near_wall_[i] = near_wall_[i + 1] = 1;
        }
        if (iy + 1 < ny_ && SegmentTouchesWall(c, Centre(ix, iy + 1), walls_[w])) {
          blocked_up_[i] = 1;
          near_wall_[i] = near_wall_[Index(ix, iy + 1)] = 1;
        }
      }
    }
  }
}

void SceneTruth::FloodFill(std::span<const Vec2> seeds) {
  std::deque<std::size_t> queue;
  const auto nx = static_cast<std::size_t>(nx_);
  for (const Vec2& seed : seeds) {
    PRIORMAP_CHECK(
        DistanceToWall(seed) > 0.0,
        fmt::format("the free-space point ({}, {}) lies on a surface", seed.x(), seed.y()));
    // The nearest centre the seed sees without crossing a wall.
    const int cx = std::clamp(static_cast<int>((seed.x() - origin_.x()) / resolution_), 0, nx_ - 1);
    const int cy = std::clamp(static_cast<int>((seed.y() - origin_.y()) / resolution_), 0, ny_ - 1);
    std::optional<std::size_t> start;
    double best = std::numeric_limits<double>::infinity();
    for (int iy = std::max(0, cy - 1); iy <= std::min(ny_ - 1, cy + 1); ++iy)
      for (int ix = std::max(0, cx - 1); ix <= std::min(nx_ - 1, cx + 1); ++ix) {
        const double d = (Centre(ix, iy) - seed).norm();
        if (d < best && !Blocked(seed, Centre(ix, iy))) {
          best = d;
          start = Index(ix, iy);
        }
      }
    PRIORMAP_CHECK(start.has_value(),
                   fmt::format("the free-space point ({}, {}) is closed in by surfaces thinner "
                               "than the truth raster",
                               seed.x(), seed.y()));
    if (!free_[*start]) {
      free_[*start] = 1;
      queue.push_back(*start);
    }
  }
  while (!queue.empty()) {
    const std::size_t i = queue.front();
    queue.pop_front();
    const std::size_t ix = i % nx;
    const auto visit = [&](std::size_t j, bool open) {
      if (open && !free_[j]) {
        free_[j] = 1;
        queue.push_back(j);
      }
    };
    if (ix + 1 < nx) visit(i + 1, !blocked_right_[i]);
    if (ix > 0) visit(i - 1, !blocked_right_[i - 1]);
    if (i + nx < free_.size()) visit(i + nx, !blocked_up_[i]);
    if (i >= nx) visit(i - nx, !blocked_up_[i - nx]);
  }
}

bool SceneTruth::Blocked(const Vec2& a, const Vec2& b) const {
  Box2 box(a);
  box.extend(b);
  for (std::size_t w = 0; w < walls_.size(); ++w)
    if (bounds_[w].intersects(box) && SegmentTouchesWall(a, b, walls_[w])) return true;
  return false;
}

bool SceneTruth::Occupied(const Vec2& p) const {
  // The four centres around p.
  const double gx = (p.x() - origin_.x()) / resolution_ - 0.5;
  const double gy = (p.y() - origin_.y()) / resolution_ - 0.5;
  if (!(gx >= 0.0 && gy >= 0.0 && gx < nx_ - 1 && gy < ny_ - 1)) return !outside_free_;
  const int ix = static_cast<int>(gx);
  const int iy = static_cast<int>(gy);
  std::array<std::pair<int, int>, 4> corners{
      {{ix, iy}, {ix + 1, iy}, {ix, iy + 1}, {ix + 1, iy + 1}}};
  std::sort(corners.begin(), corners.end(), [&](const auto& u, const auto& v) {
    return (Centre(u.first, u.second) - p).squaredNorm() <
           (Centre(v.first, v.second) - p).squaredNorm();
  });
  const auto near = [&](const auto& c) { return near_wall_[Index(c.first, c.second)] != 0; };
  // No wall crosses the square of the four centres (its sides would be blocked): any of them.
  if (std::none_of(corners.begin(), corners.end(), near))
    return !free_[Index(corners[0].first, corners[0].second)];
  for (const auto& [cx, cy] : corners)
    if (!Blocked(p, Centre(cx, cy))) return !free_[Index(cx, cy)];
  return !free_[Index(corners[0].first, corners[0].second)];  // on a wall: either way
}

double SceneTruth::DistanceToWall(const Vec2& p) const {
  double best = std::numeric_limits<double>::infinity();
  for (const ScenePrimitive& wall : walls_)
    best = std::min(best, priormap::DistanceToWall(p, wall));
  return best;
}

std::string PointOnASurface(const Scene& scene, std::span<const Vec2> points) {
  const std::vector<ScenePrimitive> walls = scene.Primitives();
  for (const Vec2& p : points) {
    for (std::size_t w = 0; w < walls.size(); ++w) {
      if (DistanceToWall(p, walls[w]) == 0.0)
        return fmt::format("the point ({}, {}) lies on surface {} of scene '{}'", p.x(), p.y(), w,
                           scene.name);
    }
  }
  return {};
}

std::string WaypointPathProblem(const Scene& scene) {
  const std::vector<Vec2>& path = scene.waypoints;
  if (std::adjacent_find(path.begin(), path.end(), std::not_equal_to<>()) == path.end())
    return fmt::format("scene '{}' has no waypoint path (two distinct waypoints at least)",
                       scene.name);
  const std::vector<ScenePrimitive> walls = scene.Primitives();
  for (std::size_t i = 0; i + 1 < path.size(); ++i) {
    for (std::size_t w = 0; w < walls.size(); ++w) {
      if (SegmentTouchesWall(path[i], path[i + 1], walls[w]))
        return fmt::format(
            "scene '{}': the leg from waypoint {} ({}, {}) to waypoint {} ({}, {}) meets surface "
            "{}: a robot cannot drive it",
            scene.name, i, path[i].x(), path[i].y(), i + 1, path[i + 1].x(), path[i + 1].y(), w);
    }
  }
  return {};
}

}  // namespace priormap
