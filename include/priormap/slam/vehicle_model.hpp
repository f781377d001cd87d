#pragma once
/// Motion models of the vehicle with their Jacobians (checked against central differences in
/// tests/slam/models_test.cpp).

#include <priormap/core/se2.hpp>
#include <priormap/slam/slam_input.hpp>

namespace priormap::slam {

using Mat32 = Eigen::Matrix<double, 3, 2>;

/// The steered bicycle of Bailey & Nieto's EKF-SLAM simulator: the pose moves along heading +
/// steer and turns at the rate speed * sin(steer) / wheelbase:
///   x' = x + v dt cos(theta + g),  y' = y + v dt sin(theta + g),
///   theta' = theta + v dt sin(g) / L.
/// J_pose: 3x3 derivative by (x, y, theta); J_control: 3x2 by (speed, steer).
[[nodiscard]] Se2 BicycleMotion(const Se2& pose, const BicycleControl& control, double dt,
                                double wheelbase, Mat3* J_pose = nullptr,
                                Mat32* J_control = nullptr);

/// pose * increment, the odometry model. J_increment: 3x3 by the increment's (x, y, theta).
[[nodiscard]] Se2 IncrementMotion(const Se2& pose, const Se2& increment, Mat3* J_pose = nullptr,
                                  Mat3* J_increment = nullptr);

}  // namespace priormap::slam
