#include <cmath>

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
  const double r = relative.norm();
  const Vec2 across(-relative.y() / r, relative.x() / r);
  const double var_across = across.dot(C * across);
  return {var_across / (2.0 * r), 0.5 * (var_across / r) * (var_across / r)};
}

}  // namespace priormap::slam
