// The world of the urban study (Parsley & Julier, Sec. VI, Fig. 3): the city, the fixed route and
// the true run along it, the beacons and what is visible from each observation frame.
#include <algorithm>
#include <cmath>
#include <string>

#include <priormap/core/angles.hpp>
#include <priormap/core/check.hpp>
#include <priormap/slam/prior_map.hpp>
#include <priormap/slam/vehicle_model.hpp>

#include "urban_detail.hpp"

namespace priormap::slam {
namespace detail {

std::vector<Vec2> RouteWaypoints(const UrbanScenarioOptions& options, Se2* start) {
  // Fig. 3's route: from the centre of the city south to the loop's bottom street, one
  // anticlockwise loop round a 4 x 3 block rectangle (every turn a left turn), back up the middle
  // street and on to the top street. 18 pitches: 1.44 km at the default pitch of 80 m, about
  // 1.41 km driven as the controller cuts the seven corners.
  const double p = options.block_size + options.street_width;
  *start = Se2(0.0, 0.0, -0.5 * kPi);
  return {{0.0, -p},      {2.0 * p, -p}, {2.0 * p, 2.0 * p}, {-2.0 * p, 2.0 * p},
          {-2.0 * p, -p}, {0.0, -p},     {0.0, 2.0 * p}};
}

void DriveRoute(const UrbanScenarioOptions& options, const Se2& start, UrbanWorld* world) {
  // Bailey & Nieto's compute_steering: the steering angle turns towards the bearing of the
  // current waypoint, at most max_steer_rate, up to max_steer; the next waypoint is taken within
  // waypoint_radius. The run ends when the last waypoint is abeam (no longer ahead).
  const std::vector<Vec2>& waypoints = world->waypoints;
  double nominal = (waypoints.front() - start.translation()).norm();
  for (std::size_t i = 1; i < waypoints.size(); ++i) {
    nominal += (waypoints[i] - waypoints[i - 1]).norm();
  }
  const auto max_steps =
      static_cast<std::size_t>(2.0 * nominal / (options.speed * options.control_dt));
  const double max_delta = options.max_steer_rate * options.control_dt;
  Se2 pose = start;
  double steer = 0.0;
  std::size_t target = 0;
  world->poses = {start};
  while (true) {
    const Vec2 to = waypoints[target] - pose.translation();
    if (target + 1 < waypoints.size() && to.norm() < options.waypoint_radius) {
      ++target;
      continue;
    }
    if (target + 1 == waypoints.size() && to.dot(UnitVector(pose.theta())) <= 0.0) break;
    const double delta = WrapAngle(std::atan2(to.y(), to.x()) - pose.theta() - steer);
    steer = std::clamp(steer + std::clamp(delta, -max_delta, max_delta), -options.max_steer,
                       options.max_steer);
    const BicycleControl control{options.speed, steer};
    pose = BicycleMotion(pose, control, options.control_dt, world->wheelbase);
    world->controls.push_back(control);
    world->poses.push_back(pose);
    PRIORMAP_CHECK(world->controls.size() < max_steps,
                   "the vehicle of the urban scenario does not reach its waypoints");
  }
}

}  // namespace detail

bool UrbanScenarioOptions::IsValid(std::string* why) const {
  const auto fail = [why](const char* message) {
    if (why) *why = message;
    return false;
  };
  if (!(block_size > 0.0 && street_width > 0.0))
    return fail("block_size, street_width must be > 0");
  if (!(0.0 <= setback_min && setback_min <= setback_max))
    return fail("need 0 <= setback_min <= setback_max");
  if (!(0.0 <= building_gap_min && building_gap_min <= building_gap_max)) {
    return fail("need 0 <= building_gap_min <= building_gap_max");
  }
  // The narrowest building (urban_city.cpp): a cell of 0.35 block_size, a setback or half a gap
  // plus a yard of up to a quarter of the cell off each side.
  const double cell = 0.35 * block_size;
  const double half_gap = 0.5 * building_gap_max + 0.25 * cell;
  if (cell - std::max(setback_max + half_gap, 2.0 * half_gap) < 2.0) {
    return fail("block_size is too small for its setbacks and gaps");
  }
  if (!(speed > 0.0 && control_dt > 0.0 && observe_every >= 1)) {
    return fail("need speed > 0, control_dt > 0 and observe_every >= 1");
  }
  if (!(max_steer > 0.0 && max_steer < 0.5 * kPi && max_steer_rate > 0.0 &&
        waypoint_radius > 0.0)) {
    return fail("need 0 < max_steer < pi/2, max_steer_rate > 0 and waypoint_radius > 0");
  }
  if (!(max_range > 0.0 && fov > 0.0 && fov <= kTwoPi))
    return fail("need max_range > 0, 0 < fov <= 2 pi");
  if (!(beacon_spacing_min > 0.0 && beacon_spacing_min <= beacon_spacing_max)) {
    return fail("need 0 < beacon_spacing_min <= beacon_spacing_max");
  }
  if (!(off_wall_fraction >= 0.0 && off_wall_fraction <= 1.0 && off_wall_min > 0.0 &&
        off_wall_min <= off_wall_max)) {
    return fail("need 0 <= off_wall_fraction <= 1 and 0 < off_wall_min <= off_wall_max");
  }
  // Up to 9 spurious segments per wall: nearer 1, their count (f / (1 - f) per wall) grows without
  // bound.
  if (!(IsValidPriorStd(prior_std) && spurious_fraction >= 0.0 && spurious_fraction <= 0.9 &&
        spurious_shift_min >= 0.0 && spurious_shift_min <= spurious_shift_max)) {
    return fail(
        "need 0 < prior_std <= 1e9, 0 <= spurious_fraction <= 0.9, 0 <= spurious_shift_min <= "
        "max");
  }
  if (!(motion_noise.wheelbase > 0.0 && motion_noise.speed_std >= 0.0 &&
        motion_noise.steer_std >= 0.0 && sensor_noise.range_std >= 0.0 &&
        sensor_noise.bearing_std >= 0.0)) {
    return fail("need wheelbase > 0 and non-negative noise levels");
  }
  return true;
}

double UrbanWorld::PathLength() const {
  double length = 0.0;
  for (std::size_t k = 1; k < poses.size(); ++k) {
    length += (poses[k].translation() - poses[k - 1].translation()).norm();
  }
  return length;
}

UrbanWorld MakeUrbanWorld(const UrbanScenarioOptions& options, std::uint64_t seed) {
  std::string why;
  PRIORMAP_CHECK(options.IsValid(&why), "invalid UrbanScenarioOptions: " + why);
  // Separate streams, so that e.g. other beacon options leave the buildings as they are.
  Rng city_rng = Rng::ForStream(seed, detail::kWorldStream);
  Rng beacon_rng = Rng::ForStream(seed, detail::kWorldStream + 1);

  UrbanWorld world;
  detail::City city = detail::BuildCity(options, city_rng);

  Se2 start;
  world.waypoints = detail::RouteWaypoints(options, &start);
  world.wheelbase = options.motion_noise.wheelbase;
  world.control_dt = options.control_dt;
  detail::DriveRoute(options, start, &world);

  world.frame_steps = detail::FrameSteps(world.controls.size(), options.observe_every);
  world.beacons = detail::PlaceBeacons(city, world.poses, world.frame_steps, options, beacon_rng);
  world.visible = detail::Visibility(city, world.poses, world.frame_steps, world.beacons, options);

  world.buildings = std::move(city.buildings);
  world.walls = std::move(city.walls);
  world.wall_building = std::move(city.wall_building);
  return world;
}

}  // namespace priormap::slam
