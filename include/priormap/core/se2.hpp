#pragma once
/// Rigid motions of the plane. A pose T_world_sensor maps sensor coordinates to world ones.
/// Jacobians are taken with respect to the parameters (x, y, theta), the convention of
/// EKF-SLAM; the angle of an output is wrapped, so numeric checks must compare angles modulo 2 pi.

#include <string>

#include <priormap/core/types.hpp>

namespace priormap {

class Se2 {
 public:
  /// The identity.
  Se2() = default;
  /// `theta` is wrapped to (-pi, pi].
  Se2(double x, double y, double theta);
  Se2(const Vec2& translation, double theta);
  /// From (x, y, theta).
  static Se2 FromVector(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

  [[nodiscard]] double x() const { return x_; }
  [[nodiscard]] double y() const { return y_; }
  [[nodiscard]] double theta() const { return theta_; }
  [[nodiscard]] Vec2 translation() const { return {x_, y_}; }
  [[nodiscard]] Mat2 rotation() const;
  [[nodiscard]] Vec3 vector() const { return {x_, y_, theta_}; }
  [[nodiscard]] bool IsFinite() const;

  /// this * other. J_out_this, J_out_other: 3x3.
  [[nodiscard]] Se2 Compose(const Se2& other, Mat3* J_out_this = nullptr,
                            Mat3* J_out_other = nullptr) const;
  /// this^-1.
  [[nodiscard]] Se2 Inverse(Mat3* J_out_this = nullptr) const;
  /// this^-1 * other: `other` expressed in the frame of `this` (odometry increments).
  [[nodiscard]] Se2 Between(const Se2& other, Mat3* J_out_this = nullptr,
                            Mat3* J_out_other = nullptr) const;
  /// R p + t: a point of this frame in the parent frame. J_out_pose: 2x3, J_out_point: 2x2.
  [[nodiscard]] Vec2 Transform(const Vec2& point, Mat23* J_out_pose = nullptr,
                               Mat2* J_out_point = nullptr) const;
  /// R^T (p - t): a parent-frame point in this frame.
  [[nodiscard]] Vec2 InverseTransform(const Vec2& point, Mat23* J_out_pose = nullptr,
                                      Mat2* J_out_point = nullptr) const;

  [[nodiscard]] Se2 operator*(const Se2& other) const { return Compose(other); }
  [[nodiscard]] Vec2 operator*(const Vec2& point) const { return Transform(point); }

  /// "x y theta" with full precision.
  [[nodiscard]] std::string ToString() const;

 private:
  double x_ = 0.0;
  double y_ = 0.0;
  double theta_ = 0.0;
};

/// Componentwise equality within `tolerance` (the angle compared modulo 2 pi).
[[nodiscard]] bool IsApprox(const Se2& a, const Se2& b, double tolerance = 1e-9);

}  // namespace priormap
