#include <priormap/core/circle.hpp>

namespace priormap {

Vec2 Circle::ClosestPoint(const Vec2& p) const {
  const Vec2 d = p - center;
  const double n = d.norm();
  return n > 0.0 ? Vec2(center + radius * d / n) : Vec2(center + Vec2(radius, 0.0));
}

double Circle::DistanceToBoundary(const Vec2& p) const {
  return std::abs((p - center).norm() - radius);
}

Box2 Circle::Bounds() const {
  return {center - Vec2::Constant(radius), center + Vec2::Constant(radius)};
}

}  // namespace priormap
