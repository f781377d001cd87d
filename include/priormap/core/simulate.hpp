#pragma once
/// Simulated scans and localized logs with per-beam ground truth.

#include <cstdint>
#include <vector>

#include <priormap/core/log.hpp>
#include <priormap/core/range_sensor.hpp>
#include <priormap/core/rng.hpp>
#include <priormap/core/scene_ray_caster.hpp>

namespace priormap {

/// One scan from `pose` (T_world_sensor). Truth: range and normal of the first surface along
/// each beam, its surface and region ids, and which readings are synthetic outliers.
[[nodiscard]] Scan SimulateScan(const SceneRayCaster& caster, const RangeSensor& sensor,
                                const Se2& pose, Rng& rng);

struct TimedPose {
  double time = 0.0;  ///< s
  Se2 pose;
};

/// Length of the polyline through `waypoints`, m.
[[nodiscard]] double WaypointPathLength(const std::vector<Vec2>& waypoints);

/// How many poses TrajectoryFromWaypoints gives, computed without making them, so that a caller
/// can refuse a typo of speed or rate before it exhausts memory. speed > 0, rate > 0; may be
/// +inf, not a count to allocate.
[[nodiscard]] double TrajectoryPoseCount(const std::vector<Vec2>& waypoints, double speed,
                                         double rate);

/// Poses along the polyline through `waypoints` at constant `speed` (m/s), one every
/// 1 / `rate` seconds, heading along the path. Preconditions: >= 2 distinct waypoints,
/// speed > 0, rate > 0.
[[nodiscard]] std::vector<TimedPose> TrajectoryFromWaypoints(const std::vector<Vec2>& waypoints,
                                                             double speed, double rate);

struct LogSimulationOptions {
  /// Odometry noise: standard deviation of the error of each increment, per metre travelled
  /// (translation, m/m, drawn for x and for y apart, in the increment's start frame) and per
  /// radian turned plus per metre travelled (rotation).
  double odom_sigma_per_meter = 0.02;
  double odom_sigma_rad_per_rad = 0.02;
  double odom_sigma_rad_per_meter = 0.01;
};

/// A localized log: one scan per trajectory pose (pose = truth, odom_pose = noisy odometry) and
/// the matching ODOM and TRUEPOS records; pose_source is kGroundTruth. Scans are simulated in
/// parallel, each with its own random stream, so the result depends only on `seed`.
[[nodiscard]] Log SimulateLog(const Scene& scene, const RangeSensor& sensor,
                              const std::vector<TimedPose>& trajectory, std::uint64_t seed,
                              const LogSimulationOptions& options = {});

}  // namespace priormap
