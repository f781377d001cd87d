// The simulator of Parsley & Julier's urban study (Sec. VI, Fig. 3) against the paper's numbers:
// route, beacons, occlusion, noise levels, prior map and reproducibility.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <string>
#include <variant>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <priormap/core/angles.hpp>
#include <priormap/slam/urban_scenario.hpp>

namespace priormap::slam {
namespace {

constexpr std::uint64_t kSeed = 20240601;

const UrbanScenarioOptions& Options() {
  static const UrbanScenarioOptions options;
  return options;
}

const UrbanWorld& World() {
  static const UrbanWorld world = MakeUrbanWorld(Options(), kSeed);
  return world;
}

Box2 CityBounds(const UrbanWorld& world) {
  Box2 bounds;
  for (const Polygon& building : world.buildings) bounds.extend(building.Bounds());
  return bounds;
}

// Length of the part of segment from -> to inside `box` (Liang-Barsky clipping): an independent
// occlusion test, valid because the buildings are axis-aligned rectangles.
double LengthInside(const Box2& box, const Vec2& from, const Vec2& to) {
  const Vec2 d = to - from;
  double t0 = 0.0;
  double t1 = 1.0;
  for (int axis = 0; axis < 2; ++axis) {
    if (std::abs(d(axis)) < 1e-15) {
      if (from(axis) <= box.min()(axis) || from(axis) >= box.max()(axis)) return 0.0;
      continue;
    }
    double a = (box.min()(axis) - from(axis)) / d(axis);
    double b = (box.max()(axis) - from(axis)) / d(axis);
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
  }
  return t1 > t0 ? (t1 - t0) * d.norm() : 0.0;
}

// The longest stretch of the sight line inside any one building.
double Penetration(const UrbanWorld& world, const Vec2& from, const Vec2& to) {
  double longest = 0.0;
  for (const Polygon& building : world.buildings) {
    longest = std::max(longest, LengthInside(building.Bounds(), from, to));
  }
  return longest;
}

struct Moments {
  double n = 0.0, sum = 0.0, sum2 = 0.0;
  void Add(double x) {
    n += 1.0;
    sum += x;
    sum2 += x * x;
  }
  [[nodiscard]] double Mean() const { return sum / n; }
  [[nodiscard]] double Std() const { return std::sqrt(sum2 / n - Mean() * Mean()); }
};

// Mean within 4 standard errors of 0, std within `relative` of `expected`.
void ExpectZeroMeanWithStd(const Moments& m, double expected, double relative,
                           const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_GT(m.n, 1000.0);
  EXPECT_LT(std::abs(m.Mean()), 4.0 * expected / std::sqrt(m.n));
  EXPECT_NEAR(m.Std(), expected, relative * expected);
}

TEST(UrbanScenario, DefaultOptionsAreValidAndBadOnesAreNot) {
  std::string why;
  EXPECT_TRUE(Options().IsValid(&why)) << why;
  UrbanScenarioOptions bad;
  bad.off_wall_min = 3.0;  // > off_wall_max
  EXPECT_FALSE(bad.IsValid(&why));
  EXPECT_FALSE(why.empty());
  bad = {};
  bad.spurious_fraction = 1.0;
  EXPECT_FALSE(bad.IsValid());
  // Nearer 1 the spurious segments would be billions (0.9999999999: an int overflow).
  bad.spurious_fraction = 0.9000001;
  EXPECT_FALSE(bad.IsValid(&why));
  EXPECT_THAT(why, ::testing::HasSubstr("0 <= spurious_fraction <= 0.9"));
  bad.spurious_fraction = 0.9;
  EXPECT_TRUE(bad.IsValid(&why)) << why;
  bad = {};
  bad.block_size = 20.0;
  EXPECT_FALSE(bad.IsValid());
}

TEST(UrbanScenario, RouteIsAboutOnePointFourKilometresAtFourteenMetresPerSecond) {
  const UrbanWorld& world = World();
  EXPECT_NEAR(world.PathLength(), 1400.0, 0.05 * 1400.0);
  EXPECT_NEAR(world.Duration(), 100.0, 5.0);
  EXPECT_NEAR(world.PathLength() / world.Duration(), Options().speed, 1e-9);
  ASSERT_EQ(world.poses.size(), world.controls.size() + 1);
  for (const BicycleControl& control : world.controls) {
    EXPECT_EQ(control.speed, Options().speed);
    EXPECT_LE(std::abs(control.steer), Options().max_steer + 1e-12);
  }
  for (std::size_t k = 1; k < world.controls.size(); ++k) {
    EXPECT_LE(std::abs(world.controls[k].steer - world.controls[k - 1].steer),
              Options().max_steer_rate * Options().control_dt + 1e-12);
  }
}

TEST(UrbanScenario, StartsNearTheCentreLoopsAnticlockwiseAndEndsAtTheTop) {
  const UrbanWorld& world = World();
  const Box2 city = CityBounds(world);
  const Vec2 start = world.poses.front().translation();
  const Vec2 end = world.poses.back().translation();
  EXPECT_LT((start - city.center()).norm(), 0.15 * city.sizes().norm());

  // The route closed from its end back to its start: the loop's area counts positively, the
  // stretches driven both ways cancel. The loop is 4 x 3 blocks (115200 m^2 at the pitch of
  // 80 m), a little less as the corners are cut.
  Polygon route;
  for (const Se2& pose : world.poses) route.vertices.push_back(pose.translation());
  EXPECT_GT(route.SignedArea(), 0.9 * 4.0 * 3.0 * 80.0 * 80.0);
  EXPECT_LT(route.SignedArea(), 1.05 * 4.0 * 3.0 * 80.0 * 80.0);

  double top = -1e9;
  for (const Se2& pose : world.poses) top = std::max(top, pose.y());
  EXPECT_GT(end.y(), top - 12.0);
  EXPECT_GT(end.y(), city.center().y() + 0.25 * city.sizes().y());
  EXPECT_NEAR(end.x(), start.x(), 2.0);  // up the middle street
}

TEST(UrbanScenario, VehicleStaysOnTheStreets) {
  const UrbanWorld& world = World();
  double closest = 1e9;
  for (const Se2& pose : world.poses) {
    for (const Polygon& building : world.buildings) {
      ASSERT_FALSE(building.Contains(pose.translation()));
      closest = std::min(closest, building.Bounds().exteriorDistance(pose.translation()));
    }
  }
  EXPECT_GT(closest, 2.0);
  RecordProperty("closest_building_m", std::to_string(closest));
}

TEST(UrbanScenario, BuildingsAreCounterClockwiseRectanglesAndWallsTheirEdges) {
  const UrbanWorld& world = World();
  EXPECT_GE(world.buildings.size(), 30u);  // 30 blocks of 1-4 buildings
  EXPECT_LE(world.buildings.size(), 120u);
  ASSERT_EQ(world.walls.size(), 4 * world.buildings.size());
  ASSERT_EQ(world.wall_building.size(), world.walls.size());
  for (std::size_t b = 0; b < world.buildings.size(); ++b) {
    const Polygon& building = world.buildings[b];
    ASSERT_EQ(building.size(), 4u);
    EXPECT_NEAR(building.SignedArea(), building.Bounds().volume(), 1e-6);
    for (std::size_t i = 0; i < 4; ++i) {
      EXPECT_EQ(world.wall_building[4 * b + i], static_cast<int>(b));
      EXPECT_TRUE(world.walls[4 * b + i].a.isApprox(building.Edge(i).a));
      EXPECT_TRUE(world.walls[4 * b + i].b.isApprox(building.Edge(i).b));
    }
  }
}

TEST(UrbanScenario, FortyPercentOfBeaconsAreCloseToButNotOnTheirWall) {
  const UrbanWorld& world = World();
  const std::size_t n = world.beacons.size();
  EXPECT_GE(n, 400u);
  EXPECT_LE(n, 600u);
  std::size_t off = 0;
  for (const Beacon& beacon : world.beacons) {
    ASSERT_GE(beacon.wall, 0);
    const Segment& wall = world.walls[beacon.wall];
    const double outwards = -SignedLineDistance(beacon.position, wall.a, wall.b);
    double t = 0.0;
    (void)ClosestPointOnSegment(wall, beacon.position, &t);
    EXPECT_GT(t, 0.0);
    EXPECT_LT(t, 1.0);
    if (beacon.on_wall) {
      EXPECT_NEAR(outwards, 0.0, 1e-9);
    } else {
      ++off;
      EXPECT_GE(outwards, Options().off_wall_min - 1e-9);
      EXPECT_LE(outwards, Options().off_wall_max + 1e-9);
      for (const Polygon& building : world.buildings) {
        EXPECT_FALSE(building.Contains(beacon.position));
      }
    }
  }
  EXPECT_NEAR(static_cast<double>(off) / static_cast<double>(n), 0.4, 1.0 / static_cast<double>(n));
}

TEST(UrbanScenario, EveryFrameSeesSomeBeacons) {
  const UrbanWorld& world = World();
  const int every = Options().observe_every;
  ASSERT_EQ(world.frame_steps.size(), world.controls.size() / every + 1);
  ASSERT_EQ(world.visible.size(), world.frame_steps.size());
  std::size_t min_seen = 1000000;
  std::size_t total = 0;
  std::set<int> ever_seen;
  for (std::size_t f = 0; f < world.visible.size(); ++f) {
    EXPECT_EQ(world.frame_steps[f], static_cast<int>(f) * every);
    min_seen = std::min(min_seen, world.visible[f].size());
    total += world.visible[f].size();
    for (const VisibleBeacon& seen : world.visible[f]) ever_seen.insert(seen.beacon);
  }
  const double mean = static_cast<double>(total) / static_cast<double>(world.visible.size());
  EXPECT_GE(min_seen, 2u) << "min " << min_seen << ", mean " << mean << " beacons per frame";
  EXPECT_GE(mean, 8.0) << "min " << min_seen << ", mean " << mean << " beacons per frame";
  // Beacons are placed where the route comes: nearly all are seen at some time.
  EXPECT_GE(static_cast<double>(ever_seen.size()), 0.9 * static_cast<double>(world.beacons.size()));
  std::printf(
      "[ info ] %zu buildings, %zu walls, %zu beacons (%zu ever seen), %zu frames; "
      "per frame: min %zu, mean %.1f visible; path %.1f m in %.2f s\n",
      world.buildings.size(), world.walls.size(), world.beacons.size(), ever_seen.size(),
      world.visible.size(), min_seen, mean, world.PathLength(), world.Duration());
}

TEST(UrbanScenario, VisibleBeaconsAreInRangeInViewAndInSight) {
  const UrbanWorld& world = World();
  for (std::size_t f = 0; f < world.visible.size(); ++f) {
    const Se2& pose = world.poses[world.frame_steps[f]];
    for (const VisibleBeacon& seen : world.visible[f]) {
      const Vec2 b = world.beacons[seen.beacon].position;
      const Vec2 d = b - pose.translation();
      EXPECT_NEAR(seen.range, d.norm(), 1e-9);
      EXPECT_NEAR(AngleDifference(seen.bearing, std::atan2(d.y(), d.x()) - pose.theta()), 0.0,
                  1e-9);
      EXPECT_LE(seen.range, Options().max_range);
      EXPECT_LE(std::abs(seen.bearing), 0.5 * Options().fov);
      EXPECT_LT(Penetration(world, pose.translation(), b), 1e-6)
          << "frame " << f << " beacon " << seen.beacon;
    }
  }
}

TEST(UrbanScenario, BeaconsBehindBuildingsAreNeverVisibleAndTheRestAlways) {
  const UrbanWorld& world = World();
  int hidden = 0;
  int clear = 0;
  for (std::size_t f = 0; f < world.visible.size(); ++f) {
    const Se2& pose = world.poses[world.frame_steps[f]];
    std::set<int> seen;
    for (const VisibleBeacon& v : world.visible[f]) seen.insert(v.beacon);
    for (std::size_t i = 0; i < world.beacons.size(); ++i) {
      const Vec2 b = world.beacons[i].position;
      const Vec2 d = b - pose.translation();
      const double bearing = WrapAngle(std::atan2(d.y(), d.x()) - pose.theta());
      if (d.norm() > Options().max_range || std::abs(bearing) > 0.5 * Options().fov) continue;
      const double inside = Penetration(world, pose.translation(), b);
      if (inside > 0.01) {
        ++hidden;
        EXPECT_FALSE(seen.contains(static_cast<int>(i))) << "frame " << f << " beacon " << i;
      } else if (inside == 0.0) {
        ++clear;
        EXPECT_TRUE(seen.contains(static_cast<int>(i))) << "frame " << f << " beacon " << i;
      }
    }
  }
  // Buildings do hide some of what is in range and view (beacons face the streets the route
  // takes, so most are in sight when in range).
  EXPECT_GT(hidden, 200);
  EXPECT_GT(clear, 4000);
  RecordProperty("hidden_pairs", hidden);
  RecordProperty("clear_pairs", clear);
}

TEST(UrbanScenario, ControlNoiseMatchesTheOptions) {
  const UrbanWorld& world = World();
  Moments speed, steer;
  for (int run = 0; run < 3; ++run) {
    const UrbanRun data = SimulateUrbanRun(world, Options(), kSeed, run);
    ASSERT_EQ(data.input.motion.size(), world.controls.size());
    EXPECT_TRUE(IsApprox(data.input.initial_pose, world.poses.front(), 1e-12));
    EXPECT_EQ(data.input.start_time, 0.0);
    EXPECT_EQ(data.input.motion_noise.speed_std, Options().motion_noise.speed_std);
    for (std::size_t k = 0; k < world.controls.size(); ++k) {
      const MotionStep& step = data.input.motion[k];
      EXPECT_DOUBLE_EQ(step.time, static_cast<double>(k + 1) * Options().control_dt);
      EXPECT_EQ(step.dt, Options().control_dt);
      const auto& control = std::get<BicycleControl>(step.motion);
      speed.Add(control.speed - world.controls[k].speed);
      steer.Add(control.steer - world.controls[k].steer);
    }
  }
  ExpectZeroMeanWithStd(speed, Options().motion_noise.speed_std, 0.03, "speed");
  ExpectZeroMeanWithStd(steer, Options().motion_noise.steer_std, 0.03, "steer");
}

TEST(UrbanScenario, ObservationNoiseMatchesTheOptions) {
  const UrbanWorld& world = World();
  Moments range, bearing;
  for (int run = 0; run < 3; ++run) {
    const UrbanRun data = SimulateUrbanRun(world, Options(), kSeed, run);
    ASSERT_EQ(data.input.frames.size(), world.visible.size());
    ASSERT_EQ(data.frame_truth.size(), world.visible.size());
    for (std::size_t f = 0; f < world.visible.size(); ++f) {
      const ObservationFrame& frame = data.input.frames[f];
      EXPECT_DOUBLE_EQ(frame.time, world.frame_steps[f] * Options().control_dt);
      EXPECT_TRUE(IsApprox(data.frame_truth[f], world.poses[world.frame_steps[f]], 1e-12));
      ASSERT_EQ(frame.observations.size(), world.visible[f].size());
      for (std::size_t i = 0; i < frame.observations.size(); ++i) {
        const RangeBearing& z = frame.observations[i];
        EXPECT_EQ(z.id, world.visible[f][i].beacon);
        EXPECT_LE(std::abs(z.bearing), kPi);
        range.Add(z.range - world.visible[f][i].range);
        bearing.Add(AngleDifference(z.bearing, world.visible[f][i].bearing));
      }
    }
  }
  ExpectZeroMeanWithStd(range, Options().sensor_noise.range_std, 0.03, "range");
  ExpectZeroMeanWithStd(bearing, Options().sensor_noise.bearing_std, 0.03, "bearing");
}

TEST(UrbanScenario, PriorMapIsTheWallsWithOneMetreNoiseAndElevenPercentSpurious) {
  const UrbanWorld& world = World();
  const std::size_t n_buildings = world.buildings.size();
  Moments endpoint;
  for (int run = 0; run < 3; ++run) {
    const UrbanRun data = SimulateUrbanRun(world, Options(), kSeed, run);
    const PriorMap& map = data.prior_map;
    ASSERT_EQ(data.segment_wall.size(), map.segments.size());
    const auto spurious = std::count(data.segment_wall.begin(), data.segment_wall.end(), -1);
    EXPECT_EQ(map.segments.size(), world.walls.size() + static_cast<std::size_t>(spurious));
    EXPECT_NEAR(static_cast<double>(spurious) / static_cast<double>(map.segments.size()), 0.11,
                0.5 / static_cast<double>(map.segments.size()));
    ASSERT_EQ(map.buildings.size(), n_buildings + static_cast<std::size_t>(spurious));
    EXPECT_EQ(map.buildings[3], "building 3");
    EXPECT_EQ(map.buildings[n_buildings], "spurious 0");
    std::set<int> walls;
    std::set<int> spurious_buildings;
    bool shuffled = false;
    for (std::size_t s = 0; s < map.segments.size(); ++s) {
      const PriorSegment& segment = map.segments[s];
      EXPECT_EQ(segment.std, Options().prior_std);
      const int w = data.segment_wall[s];
      if (w >= 0) {
        shuffled = shuffled || w != static_cast<int>(s);
        walls.insert(w);
        EXPECT_EQ(segment.building, world.wall_building[w]);
        for (int c = 0; c < 2; ++c) {
          endpoint.Add(segment.a(c) - world.walls[w].a(c));
          endpoint.Add(segment.b(c) - world.walls[w].b(c));
        }
      } else {
        EXPECT_GE(segment.building, static_cast<int>(n_buildings));
        EXPECT_TRUE(spurious_buildings.insert(segment.building).second);  // one each
      }
    }
    EXPECT_EQ(walls.size(), world.walls.size());  // every true wall, once
    EXPECT_TRUE(shuffled);
  }
  ExpectZeroMeanWithStd(endpoint, Options().prior_std, 0.04, "prior endpoints");
}

TEST(UrbanScenario, SpuriousSegmentsLieInFrontOfWallsWithBeacons) {
  // Plausible confusers: near the beacons, not in some corner nobody drives past.
  const UrbanWorld& world = World();
  const UrbanRun data = SimulateUrbanRun(world, Options(), kSeed, 0);
  for (std::size_t s = 0; s < data.prior_map.segments.size(); ++s) {
    if (data.segment_wall[s] >= 0) continue;
    const PriorSegment& segment = data.prior_map.segments[s];
    const Vec2 middle = 0.5 * (segment.a + segment.b);
    double nearest = 1e9;
    for (const Beacon& beacon : world.beacons) {
      nearest = std::min(nearest, PointSegmentDistance(beacon.position, {segment.a, segment.b}));
    }
    EXPECT_LT(nearest, 15.0);
    for (const Polygon& building : world.buildings) EXPECT_FALSE(building.Contains(middle));
  }
}

TEST(UrbanScenario, RunsAreReproducibleAndDiffer) {
  const UrbanWorld& world = World();
  const UrbanRun a = SimulateUrbanRun(world, Options(), kSeed, 5);
  const UrbanRun b = SimulateUrbanRun(world, Options(), kSeed, 5);
  const UrbanRun c = SimulateUrbanRun(world, Options(), kSeed, 6);
  ASSERT_EQ(a.input.motion.size(), b.input.motion.size());
  for (std::size_t k = 0; k < a.input.motion.size(); ++k) {
    const auto& ua = std::get<BicycleControl>(a.input.motion[k].motion);
    const auto& ub = std::get<BicycleControl>(b.input.motion[k].motion);
    ASSERT_EQ(ua.speed, ub.speed);
    ASSERT_EQ(ua.steer, ub.steer);
  }
  for (std::size_t f = 0; f < a.input.frames.size(); ++f) {
    for (std::size_t i = 0; i < a.input.frames[f].observations.size(); ++i) {
      ASSERT_EQ(a.input.frames[f].observations[i].range, b.input.frames[f].observations[i].range);
      ASSERT_EQ(a.input.frames[f].observations[i].bearing,
                b.input.frames[f].observations[i].bearing);
    }
  }
  ASSERT_EQ(a.segment_wall, b.segment_wall);
  for (std::size_t s = 0; s < a.prior_map.segments.size(); ++s) {
    ASSERT_EQ(a.prior_map.segments[s].a, b.prior_map.segments[s].a);
    ASSERT_EQ(a.prior_map.segments[s].b, b.prior_map.segments[s].b);
  }
  // Another run: other noise on the same world.
  EXPECT_NE(std::get<BicycleControl>(a.input.motion[0].motion).speed,
            std::get<BicycleControl>(c.input.motion[0].motion).speed);
  EXPECT_NE(a.input.frames[0].observations[0].range, c.input.frames[0].observations[0].range);
  EXPECT_NE(a.segment_wall, c.segment_wall);
}

TEST(UrbanScenario, WorldsAreReproducibleAndDifferBySeed) {
  const UrbanWorld& world = World();
  const UrbanWorld again = MakeUrbanWorld(Options(), kSeed);
  const UrbanWorld other = MakeUrbanWorld(Options(), kSeed + 1);
  ASSERT_EQ(again.buildings.size(), world.buildings.size());
  for (std::size_t b = 0; b < world.buildings.size(); ++b) {
    ASSERT_EQ(again.buildings[b].vertices, world.buildings[b].vertices);
  }
  ASSERT_EQ(again.beacons.size(), world.beacons.size());
  for (std::size_t i = 0; i < world.beacons.size(); ++i) {
    ASSERT_EQ(again.beacons[i].position, world.beacons[i].position);
    ASSERT_EQ(again.beacons[i].on_wall, world.beacons[i].on_wall);
  }
  ASSERT_EQ(again.poses.size(), world.poses.size());
  for (std::size_t f = 0; f < world.visible.size(); ++f) {
    ASSERT_EQ(again.visible[f].size(), world.visible[f].size());
  }
  // Another seed: another city (the route, being fixed, is driven the same way).
  EXPECT_NE(other.buildings.front().vertices, world.buildings.front().vertices);
  EXPECT_TRUE(other.beacons.size() != world.beacons.size() ||
              other.beacons.front().position != world.beacons.front().position);
  EXPECT_EQ(other.poses.size(), world.poses.size());
  EXPECT_NEAR(other.PathLength(), 1400.0, 0.05 * 1400.0);
}

// Every run of a world has one observation frame per visible step. (Their cost is measured in
// bench/slam_bench.cpp, not asserted here: a wall-clock limit fails on a loaded machine.)
TEST(UrbanScenario, EveryRunHasAFrameForEachVisibleStep) {
  const UrbanWorld world = MakeUrbanWorld(Options(), kSeed + 2);
  constexpr int kRuns = 20;
  std::size_t sink = 0;
  for (int run = 0; run < kRuns; ++run) {
    sink += SimulateUrbanRun(world, Options(), kSeed, run).input.frames.size();
  }
  EXPECT_EQ(sink, kRuns * world.visible.size());
}

}  // namespace
}  // namespace priormap::slam
