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

}  // namespace priormap::slam
