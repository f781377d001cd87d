#include <cmath>

#include <priormap/core/scene_ray_caster.hpp>

namespace priormap {
namespace {

// Slab test: does the ray reach `box` within `max_range`?
bool RayMayHitBox(const Vec2& origin, const Vec2& direction, double max_range, const Box2& box) {
  double t_min = 0.0, t_max = max_range;
  for (int k = 0; k < 2; ++k) {
    if (direction[k] == 0.0) {
      if (origin[k] < box.min()[k] || origin[k] > box.max()[k]) return false;
      continue;
    }
    double t0 = (box.min()[k] - origin[k]) / direction[k];
    double t1 = (box.max()[k] - origin[k]) / direction[k];
    if (t0 > t1) std::swap(t0, t1);
    t_min = std::max(t_min, t0);
    t_max = std::min(t_max, t1);
    if (t_min > t_max) return false;
  }
  return true;
}

}  // namespace

SceneRayCaster::SceneRayCaster(const Scene& scene) : primitives_(scene.Primitives()) {
  bounds_.reserve(primitives_.size());
  for (const ScenePrimitive& p : primitives_) {
    Box2 box = std::visit([](const auto& shape) { return shape.Bounds(); }, p.shape);
    // Pad so that round-off never rejects a ray that grazes an axis-aligned segment.
    bounds_.push_back(Box2(box.min() - Vec2::Constant(1e-9), box.max() + Vec2::Constant(1e-9)));
  }
}

std::optional<SceneHit> SceneRayCaster::Cast(const Ray& ray, double max_range) const {
  const Vec2 direction = UnitVector(ray.angle);
  std::optional<SceneHit> best;
  double best_range = max_range;
  for (std::size_t i = 0; i < primitives_.size(); ++i) {
    if (!RayMayHitBox(ray.origin, direction, best_range, bounds_[i])) continue;
    const ScenePrimitive& p = primitives_[i];
    const std::optional<RayHit> hit =
        std::visit([&](const auto& shape) { return CastRay(ray, shape); }, p.shape);
    if (hit && hit->range <= best_range) {
      best_range = hit->range;
      best = SceneHit{hit->range, hit->normal_angle, p.surface, p.region, p.clutter};
    }
  }
  return best;
}

}  // namespace priormap
