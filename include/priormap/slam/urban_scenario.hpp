#pragma once
/// The simulation study of Parsley & Julier (Sec. VI, Fig. 3): an urban scene of rectangular
/// buildings in blocks, point beacons on (60 %) or close to (40 %) their walls, a steered
/// bicycle that starts near the centre, drives one anticlockwise loop and ends at the top
/// (about 1.4 km at 14 m/s), a range-bearing sensor whose view the buildings occlude, and a
/// prior map of the true walls with 1 m endpoint noise plus 11 % spurious segments.
///
/// The world (scene, true trajectory, what is visible when) is made once per study; each Monte
/// Carlo run then only draws noise, so runs are cheap and independent of each other.

#include <cstdint>
#include <numbers>
#include <string>
#include <vector>

#include <priormap/core/polygon.hpp>
#include <priormap/core/se2.hpp>
#include <priormap/slam/prior_map.hpp>
#include <priormap/slam/slam_input.hpp>

namespace priormap::slam {

struct UrbanScenarioOptions {
  // City: a grid of square blocks between straight streets; the route is fixed in units of the
  // block pitch (block_size + street_width), so these two set the path length (1.44 km nominal).
  double block_size = 60.0;    ///< side of a block, kerb to kerb, m
  double street_width = 20.0;  ///< m
  double setback_min = 1.0;    ///< buildings stand this far back from the kerb, m
  double setback_max = 4.0;
  double building_gap_min = 2.0;  ///< gap between neighbouring buildings of a block, m
  double building_gap_max = 6.0;
  // Vehicle and its controller.
  double speed = 14.0;        ///< m/s
  double control_dt = 0.025;  ///< s between control steps
  int observe_every = 8;      ///< control steps between observation frames (0.2 s)
  double max_steer = 30.0 * std::numbers::pi / 180.0;
  double max_steer_rate = 90.0 * std::numbers::pi / 180.0;  ///< rad/s
  double waypoint_radius = 8.0;  ///< the controller turns to the next waypoint this close, m
  // Sensor.
  double max_range = 30.0;        ///< m
  double fov = std::numbers::pi;  ///< rad, centred on the heading
  // Beacons: on the street-facing walls, where the route sees them (from at least one frame).
  double beacon_spacing_min = 3.0;  ///< along a wall, m
  double beacon_spacing_max = 8.0;
  double off_wall_fraction = 0.4;  ///< beacons close to but not on a wall
  double off_wall_min = 0.5;       ///< their distance from the wall, m (outwards)
  double off_wall_max = 2.5;
  // Prior map.
  double prior_std = 1.0;           ///< endpoint noise, m
  double spurious_fraction = 0.11;  ///< of the prior map's segments
  double spurious_shift_min = 2.0;  ///< spurious walls: copies of walls moved out by, m
  double spurious_shift_max = 6.0;
  // Noise of what the filter is given.
  MotionNoise motion_noise{};  ///< wheelbase, speed and steering errors
  SensorNoise sensor_noise{};

  /// False (with the reason in `why`, if given) for inconsistent options.
  [[nodiscard]] bool IsValid(std::string* why = nullptr) const;
};

/// A beacon (point landmark); its index is its landmark id.
struct Beacon {
  Vec2 position = Vec2::Zero();
  int wall = -1;        ///< the wall it is on or next to (index into UrbanWorld::walls)
  bool on_wall = true;  ///< false: close to but not on the wall
};

/// A beacon seen from a true pose, with its true range and bearing.
struct VisibleBeacon {
  int beacon = -1;
  double range = 0.0;
  double bearing = 0.0;
};

struct UrbanWorld {
  std::vector<Polygon> buildings;  ///< counter-clockwise rectangles
  std::vector<Segment> walls;      ///< every building's edges, in order (wall 4 b + i: edge i of b)
  std::vector<int> wall_building;  ///< building of each wall
  std::vector<Beacon> beacons;
  std::vector<Vec2> waypoints;  ///< the route the controller follows
  double wheelbase = 4.0;

  // The true run, identical for every Monte Carlo run.
  std::vector<BicycleControl> controls;  ///< commanded (true) control of each step
  std::vector<Se2> poses;                ///< poses[0] the start, poses[k + 1] after step k
  double control_dt = 0.025;
  std::vector<int> frame_steps;  ///< frame f is taken at poses[frame_steps[f]]: steps
                                 ///< 0, observe_every, 2 observe_every, ... (time k dt)
  std::vector<std::vector<VisibleBeacon>> visible;  ///< per frame

  [[nodiscard]] double PathLength() const;
  [[nodiscard]] double Duration() const {
    return control_dt * static_cast<double>(controls.size());
  }
};

/// Deterministic for a given seed: the buildings, beacon placement and offsets are random, the
/// route is fixed. Draws from Rng::ForStream(seed, 2^62 + part), streams no run ever uses.
/// Precondition: options.IsValid().
[[nodiscard]] UrbanWorld MakeUrbanWorld(const UrbanScenarioOptions& options, std::uint64_t seed);

/// One Monte Carlo run's data: what the filter gets, and the truth to score it with.
struct UrbanRun {
  /// Noisy controls and observations (ids = beacon indices): motion[k] is control step k,
  /// {time (k + 1) dt, dt, commanded control + noise}; frames[f] is taken at time
  /// frame_steps[f] dt (frame 0 at the start, time 0); initial_pose = poses[0], known exactly.
  SlamInput input;
  /// Noisy true walls and spurious segments, shuffled. buildings: "building K" (world building
  /// K) for the true walls, then one "spurious J" per spurious segment.
  PriorMap prior_map;
  std::vector<int> segment_wall;  ///< per prior segment: its true wall, or -1 if spurious
  std::vector<Se2> frame_truth;   ///< true pose at each observation frame
};

/// Run `run` of the study seeded with `seed`: its noise comes from Rng::ForStream(seed, run),
/// so runs are reproducible and independent of the order or thread they run in.
[[nodiscard]] UrbanRun SimulateUrbanRun(const UrbanWorld& world,
                                        const UrbanScenarioOptions& options, std::uint64_t seed,
                                        int run);

}  // namespace priormap::slam
