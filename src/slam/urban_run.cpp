// One Monte Carlo run of the urban study (Parsley & Julier, Sec. VI): the world's true run seen
// through noisy controls, a noisy range-bearing sensor and a noisy prior map with spurious walls.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include <priormap/core/angles.hpp>
#include <priormap/core/check.hpp>

#include "urban_detail.hpp"

namespace priormap::slam {
namespace {

// Control step k, held over ((k) dt, (k + 1) dt], with speed and steering errors (Bailey &
// Nieto's simulator adds them to the commanded controls at every step).
std::vector<MotionStep> NoisyMotion(const UrbanWorld& world, const MotionNoise& noise, Rng& rng) {
  std::vector<MotionStep> motion;
  motion.reserve(world.controls.size());
  for (std::size_t k = 0; k < world.controls.size(); ++k) {
    const BicycleControl& truth = world.controls[k];
    MotionStep step;
    step.time = static_cast<double>(k + 1) * world.control_dt;
    step.dt = world.control_dt;
    step.motion = BicycleControl{truth.speed + noise.speed_std * rng.Normal(),
                                 truth.steer + noise.steer_std * rng.Normal()};
    motion.push_back(step);
  }
  return motion;
}

std::vector<ObservationFrame> NoisyObservations(const UrbanWorld& world, const SensorNoise& noise,
                                                Rng& rng) {
  std::vector<ObservationFrame> frames(world.frame_steps.size());
  for (std::size_t f = 0; f < frames.size(); ++f) {
    frames[f].time = static_cast<double>(world.frame_steps[f]) * world.control_dt;
    frames[f].observations.reserve(world.visible[f].size());
    for (const VisibleBeacon& seen : world.visible[f]) {
      frames[f].observations.push_back(
          {seen.beacon, seen.range + noise.range_std * rng.Normal(),
           WrapAngle(seen.bearing + noise.bearing_std * rng.Normal())});
    }
  }
  return frames;
}

Vec2 NormalVec2(Rng& rng) {
  const double x = rng.Normal();  // in this order, for reproducibility
  const double y = rng.Normal();
  return {x, y};
}

PriorSegment NoisySegment(const Segment& truth, int building, double std, Rng& rng) {
  const Vec2 a = truth.a + std * NormalVec2(rng);
  const Vec2 b = truth.b + std * NormalVec2(rng);
  return {a, b, std, building};
}

// Spurious segments made to confuse: part of a wall that carries beacons, moved out into the
// street by a few metres, as an outdated or misregistered outline would be. Off-wall beacons
// (0.5-2.5 m out) may well lie on them.
Segment SpuriousWall(const UrbanWorld& world, const std::vector<int>& walls_with_beacons,
                     const UrbanScenarioOptions& options, Rng& rng) {
  const Segment& wall =
      world.walls[walls_with_beacons[rng.UniformIndex(walls_with_beacons.size())]];
  const Vec2 shift = rng.Uniform(options.spurious_shift_min, options.spurious_shift_max) *
                     detail::OutwardNormal(wall);
  const double t0 = rng.Uniform(0.0, 0.3);
  const double t1 = rng.Uniform(0.7, 1.0);
  return {wall.PointAt(t0) + shift, wall.PointAt(t1) + shift};
}

// Every true wall with 1-sigma endpoint noise prior_std, plus round(f n / (1 - f)) spurious
// segments so that they are the fraction f of the map, shuffled.
void NoisyPriorMap(const UrbanWorld& world, const UrbanScenarioOptions& options, Rng& rng,
                   UrbanRun* run) {
  const int walls = static_cast<int>(world.walls.size());
  const int spurious = static_cast<int>(
      std::lround(options.spurious_fraction * walls / (1.0 - options.spurious_fraction)));
  std::vector<int> walls_with_beacons;
  for (const Beacon& beacon : world.beacons) walls_with_beacons.push_back(beacon.wall);
  std::sort(walls_with_beacons.begin(), walls_with_beacons.end());
  walls_with_beacons.erase(std::unique(walls_with_beacons.begin(), walls_with_beacons.end()),
                           walls_with_beacons.end());
  PRIORMAP_CHECK(spurious == 0 || !walls_with_beacons.empty(), "no beacons to confuse");

  std::vector<PriorSegment> segments;
  std::vector<int> segment_wall;
  PriorMap& map = run->prior_map;
  for (std::size_t b = 0; b < world.buildings.size(); ++b) {
    map.buildings.push_back("building " + std::to_string(b));
  }
  for (int w = 0; w < walls; ++w) {
    segments.push_back(
        NoisySegment(world.walls[w], world.wall_building[w], options.prior_std, rng));
    segment_wall.push_back(w);
  }
  for (int j = 0; j < spurious; ++j) {
    const Segment wall = SpuriousWall(world, walls_with_beacons, options, rng);
    segments.push_back(
        NoisySegment(wall, static_cast<int>(map.buildings.size()), options.prior_std, rng));
    segment_wall.push_back(-1);
    map.buildings.push_back("spurious " + std::to_string(j));
  }

  std::vector<std::size_t> order(segments.size());
  std::iota(order.begin(), order.end(), 0);
  for (std::size_t k = order.size(); k > 1; --k) {
    std::swap(order[k - 1], order[rng.UniformIndex(k)]);
  }
  map.segments.reserve(order.size());
  run->segment_wall.reserve(order.size());
  for (const std::size_t i : order) {
    map.segments.push_back(segments[i]);
    run->segment_wall.push_back(segment_wall[i]);
  }
}

}  // namespace

UrbanRun SimulateUrbanRun(const UrbanWorld& world, const UrbanScenarioOptions& options,
                          std::uint64_t seed, int run) {
  PRIORMAP_CHECK(run >= 0, "SimulateUrbanRun: run must be >= 0");
  PRIORMAP_CHECK(!world.poses.empty() && world.poses.size() == world.controls.size() + 1 &&
                     world.frame_steps.size() == world.visible.size(),
                 "SimulateUrbanRun: the world is not one made by MakeUrbanWorld");
  PRIORMAP_CHECK(options.motion_noise.wheelbase == world.wheelbase,
                 "SimulateUrbanRun: options of another wheelbase than the world's");
  // One stream per run, drawn in a fixed order: controls, observations, prior map.
  Rng rng = Rng::ForStream(seed, static_cast<std::uint64_t>(run));
  UrbanRun out;
  out.input.initial_pose = world.poses.front();
  out.input.start_time = 0.0;
  out.input.motion_noise = options.motion_noise;
  out.input.sensor_noise = options.sensor_noise;
  out.input.motion = NoisyMotion(world, options.motion_noise, rng);
  out.input.frames = NoisyObservations(world, options.sensor_noise, rng);
  for (const int k : world.frame_steps) out.frame_truth.push_back(world.poses[k]);
  NoisyPriorMap(world, options, rng, &out);
  return out;
}

}  // namespace priormap::slam
