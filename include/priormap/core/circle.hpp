#pragma once

#include <priormap/core/types.hpp>

namespace priormap {

struct Circle {
  Vec2 center = Vec2::Zero();
  double radius = 1.0;

  /// True for points inside or on the circle.
  [[nodiscard]] bool Contains(const Vec2& p) const { return (p - center).norm() <= radius; }
  /// The point of the circle (the curve) closest to p; for p at the centre, the point at angle 0.
  [[nodiscard]] Vec2 ClosestPoint(const Vec2& p) const;
  /// Distance from p to the curve (zero on it, positive inside and outside).
  [[nodiscard]] double DistanceToBoundary(const Vec2& p) const;
  [[nodiscard]] Box2 Bounds() const;
};

}  // namespace priormap
