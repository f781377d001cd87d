#include <cmath>

#include <priormap/core/angles.hpp>
#include <priormap/core/ray_cast.hpp>

namespace priormap {
namespace {

// Normal `n` turned to face the ray (negative dot product with its direction).
double FacingNormalAngle(Vec2 n, const Vec2& direction) {
  if (n.dot(direction) > 0.0) n = -n;
  return WrapAngle(std::atan2(n.y(), n.x()));
}

}  // namespace

std::optional<RayHit> CastRay(const Ray& ray, const Segment& segment) {
  const Vec2 d = UnitVector(ray.angle);
  const Vec2 e = segment.b - segment.a;
  const double denominator = Cross(d, e);
  if (denominator == 0.0) return std::nullopt;
  const Vec2 w = segment.a - ray.origin;
  const double range = Cross(w, e) / denominator;
  const double s = Cross(w, d) / denominator;
  if (range < kMinRayRange || s < 0.0 || s > 1.0) return std::nullopt;
  return RayHit{range, FacingNormalAngle(Perp(e), d)};
}

std::optional<RayHit> CastRay(const Ray& ray, const Circle& circle) {
  const Vec2 d = UnitVector(ray.angle);
  const Vec2 m = ray.origin - circle.center;
  // |m + t d|^2 = r^2  ->  t^2 + 2 b t + c = 0.
  const double b = m.dot(d);
  const double c = m.squaredNorm() - circle.radius * circle.radius;
  const double discriminant = b * b - c;
  if (discriminant < 0.0) return std::nullopt;
  const double root = std::sqrt(discriminant);
  double range = -b - root;
  if (range < kMinRayRange) range = -b + root;  // origin inside the circle (or on it)
  if (range < kMinRayRange) return std::nullopt;
  const Vec2 hit = ray.origin + range * d;
  return RayHit{range, FacingNormalAngle(hit - circle.center, d)};
}

}  // namespace priormap
