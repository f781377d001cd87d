#pragma once
/// Casts beams against a whole Scene and reports which surface and region each hit.

#include <optional>
#include <vector>

#include <priormap/core/ray_cast.hpp>
#include <priormap/core/scene.hpp>

namespace priormap {

struct SceneHit {
  double range = 0.0;
  double normal_angle = 0.0;  ///< world frame, pointing back towards the sensor
  int surface = -1;
  int region = -1;
  bool clutter = false;
};

class SceneRayCaster {
 public:
  explicit SceneRayCaster(const Scene& scene);

  /// The closest hit of `ray` (world frame) within `max_range`, if any.
  [[nodiscard]] std::optional<SceneHit> Cast(const Ray& ray, double max_range) const;

  [[nodiscard]] const std::vector<ScenePrimitive>& primitives() const { return primitives_; }

 private:
  std::vector<ScenePrimitive> primitives_;
  std::vector<Box2> bounds_;  ///< one per primitive, for a cheap reject before the exact test
};

}  // namespace priormap
