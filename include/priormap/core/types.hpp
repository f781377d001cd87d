#pragma once
/// Short names for the fixed-size Eigen types used across priormap.

#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace priormap {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Mat2 = Eigen::Matrix2d;
using Mat3 = Eigen::Matrix3d;
using Mat23 = Eigen::Matrix<double, 2, 3>;
using Row2 = Eigen::RowVector2d;
using Row3 = Eigen::RowVector3d;
using Box2 = Eigen::AlignedBox2d;

/// The 2D cross product (z component of the 3D one): positive when b is counter-clockwise of a.
inline double Cross(const Vec2& a, const Vec2& b) {
  return a.x() * b.y() - a.y() * b.x();
}

/// `v` rotated by +90 degrees.
inline Vec2 Perp(const Vec2& v) {
  return {-v.y(), v.x()};
}

/// Unit vector at angle `theta` (rad) from the x axis.
inline Vec2 UnitVector(double theta) {
  return {std::cos(theta), std::sin(theta)};
}

}  // namespace priormap
