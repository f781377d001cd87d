#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Eigenvalues>

#include <priormap/core/angles.hpp>
#include <priormap/slam/range_bearing.hpp>

namespace priormap::slam {

Vec2 ObserveRangeBearing(const Se2& pose, const Vec2& landmark, Mat23* J_pose, Mat2* J_landmark) {
  const Vec2 d = landmark - pose.translation();
  const double r2 = d.squaredNorm();
  const double r = std::sqrt(r2);
  if (J_landmark) {
    *J_landmark << d.x() / r, d.y() / r,  //
        -d.y() / r2, d.x() / r2;
  }
  if (J_pose) {
    *J_pose << -d.x() / r, -d.y() / r, 0.0,  //
        d.y() / r2, -d.x() / r2, -1.0;
  }
  return {r, WrapAngle(std::atan2(d.y(), d.x()) - pose.theta())};
}

Vec2 RangeBearingToPoint(const Se2& pose, const Vec2& range_bearing, Mat23* J_pose,
                         Mat2* J_measurement) {
  const double r = range_bearing.x();
  const double angle = pose.theta() + range_bearing.y();
  const double c = std::cos(angle);
  const double s = std::sin(angle);
  if (J_pose) {
    *J_pose << 1.0, 0.0, -r * s,  //
        0.0, 1.0, r * c;
  }
  if (J_measurement) {
    *J_measurement << c, -r * s,  //
        s, r * c;
  }
  return pose.translation() + r * Vec2(c, s);
}

RangeCurvature RangeSecondOrder(const Vec2& relative, const Mat2& C) {
  // The squared norm of a point 1e-200 m away underflows to zero; stableNorm does not.
  double r = relative.norm();
  if (!(r > 0.0)) r = relative.stableNorm();
  double var_across = 0.0;
  if (r > 0.0) {
    const Vec2 across(-relative.y() / r, relative.x() / r);
    var_across = across.dot(C * across);
  } else {
    // At the sensor every direction is across the line of sight: the largest variance of any.
    var_across = Eigen::SelfAdjointEigenSolver<Mat2>(C, Eigen::EigenvaluesOnly).eigenvalues()[1];
  }
  if (!(var_across > 0.0)) return {};
  // The expansion grows without bound as r -> 0; the exact moments of sqrt(r^2 + t^2),
  // t ~ N(0, var_t), do not: the mean exceeds r by at most E|t| = sqrt(2 var_t / pi), and the
  // variance is at most var_t (the range is 1-Lipschitz in t). The bounds take over only within
  // about 0.7 sigma (sigma^2 = var_t) of the sensor, where the expansion no longer holds anyway.
  const double ratio = var_across / r;
  return {std::min(0.5 * ratio, std::sqrt(2.0 * var_across / std::numbers::pi)),
          std::min(0.5 * ratio * ratio, var_across)};
}

}  // namespace priormap::slam
