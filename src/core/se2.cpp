#include <cmath>

#include <fmt/format.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/se2.hpp>

namespace priormap {
namespace {

// d R(theta) / d theta.
Mat2 RotationDerivative(double theta) {
  const double c = std::cos(theta), s = std::sin(theta);
  Mat2 d;
  d << -s, -c, c, -s;
  return d;
}

}  // namespace

Se2::Se2(double x, double y, double theta) : x_(x), y_(y), theta_(WrapAngle(theta)) {}

Se2::Se2(const Vec2& translation, double theta) : Se2(translation.x(), translation.y(), theta) {}

Mat2 Se2::rotation() const {
  const double c = std::cos(theta_), s = std::sin(theta_);
  Mat2 r;
  r << c, -s, s, c;
  return r;
}

bool Se2::IsFinite() const {
  return std::isfinite(x_) && std::isfinite(y_) && std::isfinite(theta_);
}

Se2 Se2::Compose(const Se2& other, Mat3* J_out_this, Mat3* J_out_other) const {
  const Mat2 r = rotation();
  const Vec2 t = translation() + r * other.translation();
  if (J_out_this) {
    J_out_this->setIdentity();
    J_out_this->block<2, 1>(0, 2) = RotationDerivative(theta_) * other.translation();
  }
  if (J_out_other) {
    J_out_other->setIdentity();
    J_out_other->block<2, 2>(0, 0) = r;
  }
  return {t, theta_ + other.theta_};
}

Se2 Se2::Inverse(Mat3* J_out_this) const {
  const Mat2 rt = rotation().transpose();
  const Vec2 t = translation();
  if (J_out_this) {
    J_out_this->setZero();
    J_out_this->block<2, 2>(0, 0) = -rt;
    J_out_this->block<2, 1>(0, 2) = -RotationDerivative(theta_).transpose() * t;
    (*J_out_this)(2, 2) = -1.0;
  }
  return {-rt * t, -theta_};
}

Se2 Se2::Between(const Se2& other, Mat3* J_out_this, Mat3* J_out_other) const {
  Mat3 J_inv_this, J_out_inv;
  const Se2 inv = Inverse(J_out_this ? &J_inv_this : nullptr);
  const Se2 out = inv.Compose(other, J_out_this ? &J_out_inv : nullptr, J_out_other);
  if (J_out_this) *J_out_this = J_out_inv * J_inv_this;
  return out;
}

Vec2 Se2::Transform(const Vec2& point, Mat23* J_out_pose, Mat2* J_out_point) const {
  const Mat2 r = rotation();
  if (J_out_pose) {
    J_out_pose->block<2, 2>(0, 0).setIdentity();
    J_out_pose->col(2) = RotationDerivative(theta_) * point;
  }
  if (J_out_point) *J_out_point = r;
  return r * point + translation();
}

Vec2 Se2::InverseTransform(const Vec2& point, Mat23* J_out_pose, Mat2* J_out_point) const {
  const Mat2 rt = rotation().transpose();
  const Vec2 delta = point - translation();
  if (J_out_pose) {
    J_out_pose->block<2, 2>(0, 0) = -rt;
    J_out_pose->col(2) = RotationDerivative(theta_).transpose() * delta;
  }
  if (J_out_point) *J_out_point = rt;
  return rt * delta;
}

std::string Se2::ToString() const {
  return fmt::format("{} {} {}", x_, y_, theta_);
}

bool IsApprox(const Se2& a, const Se2& b, double tolerance) {
  return std::abs(a.x() - b.x()) <= tolerance && std::abs(a.y() - b.y()) <= tolerance &&
         std::abs(AngleDifference(a.theta(), b.theta())) <= tolerance;
}

}  // namespace priormap
