#pragma once
/// What a prior-map SLAM run consumes: a start pose, the vehicle's motion (bicycle controls or
/// measured SE(2) increments) and range-bearing observations of point landmarks, with the noise
/// models that describe them. Simulated (urban_scenario.hpp) or read from files (slam_io.hpp).

#include <limits>
#include <numbers>
#include <variant>
#include <vector>

#include <priormap/core/se2.hpp>

namespace priormap::slam {

/// Speed (m/s) and steering angle (rad) of a steered bicycle, held over a step.
struct BicycleControl {
  double speed = 0.0;
  double steer = 0.0;
};

/// The motion over one interval (time - dt, time]: bicycle controls held over it, or an
/// odometry increment measured over it (the pose at its end in the frame of the pose at its start).
struct MotionStep {
  double time = 0.0;  ///< end of the interval, s
  double dt = 0.0;    ///< its length, s (> 0)
  std::variant<BicycleControl, Se2> motion;
  /// For an increment: its 1-sigma errors (x, y, theta); NaN entries mean "use MotionNoise".
  Vec3 increment_std = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
  /// Where its motion was read (1-based): the cell of the row's speed (bicycle controls, held
  /// from that row on) or dx (an increment), for messages; 0 when not read from a file.
  int line = 0;
  int col = 0;
};

/// One range-bearing measurement of a point landmark in the vehicle frame.
struct RangeBearing {
  int id = -1;  ///< landmark identifier; -1 when unknown (associated by nearest neighbour)
  double range = 0.0;
  double bearing = 0.0;  ///< rad, counter-clockwise from the vehicle's x axis
};

/// All measurements taken at one instant.
struct ObservationFrame {
  double time = 0.0;
  std::vector<RangeBearing> observations;
  int line = 0;  ///< where its time was read (1-based), for messages; 0 when not read from a file
  int col = 0;
};

struct MotionNoise {
  double wheelbase = 4.0;                             ///< bicycle: m
  double speed_std = 0.5;                             ///< bicycle: 1-sigma, m/s
  double steer_std = 3.0 * std::numbers::pi / 180.0;  ///< bicycle: 1-sigma, rad
  Vec3 increment_std{0.05, 0.05, 0.005};  ///< increments without their own: 1-sigma x, y, theta
};

struct SensorNoise {
  double range_std = 0.01;                               ///< m
  double bearing_std = 1.15 * std::numbers::pi / 180.0;  ///< rad
};

struct SlamInput {
  Se2 initial_pose;
  double start_time = 0.0;
  std::vector<MotionStep> motion;        ///< in time order, contiguous
  std::vector<ObservationFrame> frames;  ///< in time order
  MotionNoise motion_noise;
  SensorNoise sensor_noise;
};

}  // namespace priormap::slam
