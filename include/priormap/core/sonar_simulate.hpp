#pragma once
/// Simulated sonar rings and localized sonar logs with per-reading ground truth: which feature
/// (surface, corner, or none) caused each reading (docs/sonar.md).

#include <cstdint>
#include <vector>

#include <priormap/core/log.hpp>
#include <priormap/core/rng.hpp>
#include <priormap/core/scene_corners.hpp>
#include <priormap/core/scene_ray_caster.hpp>
#include <priormap/core/simulate.hpp>
#include <priormap/core/sonar_sensor.hpp>

namespace priormap {

/// A scene prepared for sonar simulation: its ray caster and its corners.
struct SonarScene {
  explicit SonarScene(const Scene& scene) : caster(scene), corners(SceneCorners(scene)) {}
  SceneRayCaster caster;
  std::vector<SceneCorner> corners;
};

/// One ring fired from the robot pose `T_world_robot`: a Scan (channel "SONAR") whose pose is
/// the robot's, whose angles are the transducers' bearings and whose `sonar` fields give the
/// spread, the transducers' offsets and the truth; ScanTruth holds the causing feature's true
/// distance (the whole path for multipath), the surface normal, surface and region.
[[nodiscard]] Scan SimulateSonarRing(const SonarScene& scene, const SonarSensor& sensor,
                                     const Se2& T_world_robot, Rng& rng);

/// A localized sonar log: one ring per trajectory pose, with the ODOM and TRUEPOS records of
/// SimulateLog for the same trajectory, seed and options (so a laser and a sonar log of one
/// run share their odometry); pose_source is kGroundTruth. Rings are simulated in parallel,
/// each with its own random stream, so the result depends only on `seed`.
[[nodiscard]] Log SimulateSonarLog(const Scene& scene, const SonarSensor& sensor,
                                   const std::vector<TimedPose>& trajectory, std::uint64_t seed,
                                   const LogSimulationOptions& options = {});

}  // namespace priormap
