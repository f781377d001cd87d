#pragma once
/// The corners of a scene's walls: the point features a sonar hears besides surfaces
/// (docs/sonar.md). They are where two segments of a polyline meet at an angle (not where a
/// straight wall is split in two) and the free ends of open polylines (door frames, wall ends).

#include <array>
#include <vector>

#include <priormap/core/scene.hpp>

namespace priormap {

struct SceneCorner {
  Vec2 point = Vec2::Zero();
  int surface = -1;
  /// The regions (Scene::Primitives ids) meeting here; the second is -1 at a free end.
  std::array<int, 2> regions{-1, -1};
  /// Unit directions of the walls leaving the corner; the second is zero at a free end.
  std::array<Vec2, 2> walls{Vec2::Zero(), Vec2::Zero()};

  [[nodiscard]] bool IsFreeEnd() const { return regions[1] < 0; }
  /// True when, seen from `viewpoint`, the two walls form a reflector: the angle between them
  /// on the viewpoint's side is below 180 deg. False at a free end.
  [[nodiscard]] bool IsConcaveFrom(const Vec2& viewpoint) const;
};

/// Every corner of the scene's polylines (circles have none), in surface order.
[[nodiscard]] std::vector<SceneCorner> SceneCorners(const Scene& scene);

}  // namespace priormap
