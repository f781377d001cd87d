#pragma once
/// The range-bearing sensor model and its inverse (landmark initialisation), with Jacobians
/// (checked against central differences in tests/slam/models_test.cpp).

#include <priormap/core/se2.hpp>

namespace priormap::slam {

/// (range, bearing) of world point `landmark` seen from `pose`; the bearing is wrapped to
/// (-pi, pi]. J_pose: 2x3, J_landmark: 2x2. Precondition: the landmark is not at the pose.
[[nodiscard]] Vec2 ObserveRangeBearing(const Se2& pose, const Vec2& landmark,
                                       Mat23* J_pose = nullptr, Mat2* J_landmark = nullptr);

/// The world point at (range, bearing) from `pose`. J_pose: 2x3, J_measurement: 2x2.
[[nodiscard]] Vec2 RangeBearingToPoint(const Se2& pose, const Vec2& range_bearing,
                                       Mat23* J_pose = nullptr, Mat2* J_measurement = nullptr);

/// The second-order terms of the range to a point whose position relative to the sensor is
/// Gaussian with mean `relative` and covariance `C`. Range is convex across the line of sight, so
/// its mean exceeds |relative| by var_t / (2 r) and its variance gains (var_t / r)^2 / 2, where
/// var_t is C's variance across the line of sight (the second-order EKF; Gelb, Applied Optimal
/// Estimation, 1974). With a 1 cm range sensor and a landmark spread 0.5 m across by its bearing at
/// 30 m, the variance term is as large as the sensor's: the first-order EKF ignores it and becomes
/// overconfident. Near the sensor, where the expansion diverges, each term is capped by the exact
/// bound it cannot exceed (sqrt(2 var_t / pi) and var_t); at the sensor itself (relative = 0)
/// var_t is C's largest variance.
struct RangeCurvature {
  double mean_offset = 0.0;  ///< E[range] - |relative|, m
  double variance = 0.0;     ///< added to the range's first-order variance, m^2
};
[[nodiscard]] RangeCurvature RangeSecondOrder(const Vec2& relative, const Mat2& C);

}  // namespace priormap::slam
