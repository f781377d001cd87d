#pragma once
// A vehicle standing still that sees fixed beacons: the smallest scene in which the structure
// inference's decisions (which wall, which building, merged or not) can be watched.

#include <cstddef>
#include <span>

#include <priormap/core/angles.hpp>
#include <priormap/core/rng.hpp>
#include <priormap/slam/prior_map_slam.hpp>
#include <priormap/slam/range_bearing.hpp>

namespace priormap::slam::testing {

// Odometry that all but knows the vehicle stands still, so that what is related depends on the
// prior map and the beacons, not on drift.
inline MotionNoise StandingStillMotion() {
  MotionNoise motion;
  motion.speed_std = 1e-3;
  motion.steer_std = 1e-3;
  return motion;
}

// `frames` frames 0.2 s apart in which the vehicle, at `pose`, sees every beacon (id = its index);
// each reading with `sensor`'s noise drawn from `rng` (range, then bearing, beacon by beacon), or
// exact without one. Returns the run's result.
inline SlamResult WatchBeacons(PriorMapSlam& slam, const Se2& pose, std::span<const Vec2> beacons,
                               int frames, const SensorNoise& sensor, Rng* rng) {
  for (int f = 1; f <= frames; ++f) {
    slam.Predict({0.2 * f, 0.2, BicycleControl{0.0, 0.0}});
    ObservationFrame frame;
    frame.time = 0.2 * f;
    for (std::size_t i = 0; i < beacons.size(); ++i) {
      const Vec2 z = ObserveRangeBearing(pose, beacons[i]);
      if (rng == nullptr) {
        frame.observations.push_back({static_cast<int>(i), z.x(), z.y()});
        continue;
      }
      frame.observations.push_back({static_cast<int>(i), z.x() + rng->Normal(0.0, sensor.range_std),
                                    WrapAngle(z.y() + rng->Normal(0.0, sensor.bearing_std))});
    }
    (void)slam.Observe(frame);
  }
  return slam.Finish();
}

}  // namespace priormap::slam::testing
