#pragma once
/// Ray casting of one beam against segments and circles, returning the range and the surface
/// normal at the hit. Normals point back towards the ray's origin (the convention of Censi's CSM
/// `true_alpha`: the normal and the beam direction have a negative dot product).

#include <optional>

#include <priormap/core/circle.hpp>
#include <priormap/core/segment.hpp>

namespace priormap {

struct Ray {
  Vec2 origin = Vec2::Zero();
  double angle = 0.0;  ///< direction, rad, in the frame of `origin`
};

struct RayHit {
  double range = 0.0;         ///< distance from the origin along the ray, m (> 0)
  double normal_angle = 0.0;  ///< angle of the surface normal, in (-pi, pi], same frame as the ray
};

/// Hits closer than this to the origin are ignored, so that a ray starting on a surface leaves it.
inline constexpr double kMinRayRange = 1e-9;

/// The hit of `ray` on `segment` (endpoints included). A ray parallel to the segment misses it.
[[nodiscard]] std::optional<RayHit> CastRay(const Ray& ray, const Segment& segment);

/// The first hit of `ray` on the circle, from outside or from inside.
[[nodiscard]] std::optional<RayHit> CastRay(const Ray& ray, const Circle& circle);

}  // namespace priormap
