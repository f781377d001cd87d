// Prior segments that are the same wall (same_walls.hpp): a wall that two footprints share is
// one wall to the filter, parallel walls beyond their uncertainty are not, and on simulated data
// with a shared copy of every wall the landmarks on those walls are related to them again.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <set>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <priormap/core/rng.hpp>
#include <priormap/slam/prior_map_slam.hpp>
#include <priormap/slam/same_walls.hpp>
#include <priormap/slam/study.hpp>
#include <priormap/slam/urban_scenario.hpp>

#include "standing_beacons.hpp"

namespace priormap::slam {
namespace {

using ::testing::ElementsAre;

PriorSegment Wall(double ax, double ay, double bx, double by, double std = 1.0, int building = 0) {
  return {Vec2(ax, ay), Vec2(bx, by), std, building};
}

TEST(SameWalls, ASharedWallIsOneWallWhicheverWayItIsDrawn) {
  const PriorSegment wall = Wall(0, 0, 20, 0);
  EXPECT_TRUE(IsSameWall(wall, Wall(20, 0, 0, 0, 1.0, 1)));   // the neighbour's ring, reversed
  EXPECT_TRUE(IsSameWall(wall, Wall(0.3, -0.4, 19.6, 0.5)));  // digitised again, 1 m std
  // Digitised independently, 1.2 m apart: two walls by default, one for an overlaid map's gate.
  EXPECT_FALSE(IsSameWall(wall, Wall(0.8, -0.9, 19.1, 1.2)));
  EXPECT_TRUE(IsSameWall(wall, Wall(0.8, -0.9, 19.1, 1.2), 2.0));
  EXPECT_TRUE(IsSameWall(wall, Wall(5, 0, 12, 0)));   // a smaller neighbour's part of it
  EXPECT_TRUE(IsSameWall(wall, Wall(10, 0, 30, 0)));  // staggered: half of each shared
}

TEST(SameWalls, ParallelWallsBeyondTheirUncertaintyAreDistinct) {
  // 1 m std: walls 1 m or more apart are two (the statistic is d^2 / std^2 = 1 for 1 m, above
  // the gate 0.5), 0.5 m apart they are one; the study's neighbours stand 2-6 m apart.
  EXPECT_FALSE(IsSameWall(Wall(0, 0, 20, 0), Wall(0, 1, 20, 1)));
  EXPECT_FALSE(IsSameWall(Wall(0, 0, 20, 0), Wall(0, 2, 20, 2)));
  EXPECT_FALSE(IsSameWall(Wall(0, 0, 20, 0), Wall(0, 4, 20, 4)));
  EXPECT_FALSE(IsSameWall(Wall(0, 0, 20, 0), Wall(0, 4, 20, 4), 9.21));  // even at 99 %
  EXPECT_TRUE(IsSameWall(Wall(0, 0, 20, 0), Wall(0, 0.5, 20, 0.5)));
  // 0.1 m std, as precise footprints: 0.5 m apart are two walls (a wall and a fence, say).
  EXPECT_FALSE(IsSameWall(Wall(0, 0, 20, 0, 0.1), Wall(0, 0.5, 20, 0.5, 0.1)));
  EXPECT_TRUE(IsSameWall(Wall(0, 0, 20, 0, 0.1), Wall(0, 0.05, 20, -0.05, 0.1)));
  // Not parallel: 20 m walls at 30 degrees.
  EXPECT_FALSE(IsSameWall(Wall(0, 0, 20, 0), Wall(0, 0, 17.3, 10)));
}

TEST(SameWalls, WallsThatContinueEachOtherAreNotOne) {
  EXPECT_FALSE(IsSameWall(Wall(0, 0, 20, 0), Wall(20, 0, 35, 0)));  // split at a vertex
  EXPECT_FALSE(IsSameWall(Wall(0, 0, 20, 0), Wall(24, 0, 40, 0)));  // the next building
  EXPECT_FALSE(IsSameWall(Wall(0, 0, 20, 0), Wall(18, 0, 38, 0)));  // overlapping by 2 m of 20
  EXPECT_FALSE(IsSameWall(Wall(0, 0, 20, 0), Wall(0, 0, 0, 0)));    // no length
}

// A footprint that draws one straight wall with an extra vertex: one wall. A neighbour's wall
// that continues it, a gap, or a bend beyond the walls' error: not.
TEST(SameWalls, AWallAFootprintSplitsAtAVertexIsOneWall) {
  EXPECT_TRUE(ContinuesWall(Wall(0, 0, 20, 0), Wall(20, 0, 35, 0)));
  EXPECT_TRUE(ContinuesWall(Wall(20, 0, 35, 0), Wall(0, 0, 20, 0)));    // either order
  EXPECT_TRUE(ContinuesWall(Wall(0, 0, 20, 0), Wall(35, 0.2, 20, 0)));  // drawn the other way
  EXPECT_FALSE(ContinuesWall(Wall(0, 0, 20, 0), Wall(20, 0, 35, 0, 1.0, 1)));  // the next house
  EXPECT_FALSE(ContinuesWall(Wall(0, 0, 20, 0), Wall(20.5, 0, 35, 0)));        // no shared vertex
  EXPECT_FALSE(ContinuesWall(Wall(0, 0, 20, 0), Wall(20, 0, 30, 5)));          // a 27 degree bend
  EXPECT_FALSE(ContinuesWall(Wall(0, 0, 20, 0), Wall(20, 0, 20, 10)));         // a corner
  const SameWalls walls =
      MergeSameWalls(PriorMap{{Wall(0, 0, 20, 0), Wall(20, 0, 35, 0), Wall(35, 0, 35, 10)}, {"b"}});
  ASSERT_EQ(walls.map.segments.size(), 2u);
  EXPECT_THAT(walls.members[0], ElementsAre(0, 1));
  EXPECT_TRUE(walls.map.segments[0].a.isApprox(Vec2(0, 0), 1e-12));
  EXPECT_TRUE(walls.map.segments[0].b.isApprox(Vec2(35, 0), 1e-12));
  EXPECT_DOUBLE_EQ(walls.map.segments[0].std, 1.0);
}

// The polyline through `points`, each segment a wall of building 0 with `std`; consecutive
// segments share their vertex bit for bit, as a GeoJSON ring's do.
PriorMap Footprint(const std::vector<Vec2>& points, bool closed, double std) {
  PriorMap map;
  map.buildings = {"b"};
  const std::size_t n = points.size();
  for (std::size_t i = 0; i + 1 < n + (closed ? 1 : 0); ++i)
    map.segments.push_back({points[i], points[(i + 1) % n], std, 0});
  return map;
}

// A regular polygon of `sides` sides `length` long: a round building's footprint.
std::vector<Vec2> RegularPolygon(int sides, double length) {
  const double radius = length / (2.0 * std::sin(std::numbers::pi / sides));
  std::vector<Vec2> points;
  for (int i = 0; i < sides; ++i) {
    const double angle = 2.0 * std::numbers::pi * i / sides;
    points.emplace_back(radius * std::cos(angle), radius * std::sin(angle));
  }
  return points;
}

// `count` segments `length` long, each turning by `turn_deg` from the last: a curved facade.
std::vector<Vec2> Arc(int count, double length, double turn_deg) {
  std::vector<Vec2> points{Vec2(0, 0)};
  for (int i = 0; i < count; ++i) {
    const double heading = i * turn_deg * std::numbers::pi / 180.0;
    points.push_back(points.back() + length * Vec2(std::cos(heading), std::sin(heading)));
  }
  return points;
}

// Short sides against a 1 m std pass the endpoints' test at 60 degrees (chi2 0.32 for 1 m sides),
// and the parts chained into one chord as long as the building, with a std of its radius. A turn
// beyond the digitiser's precision is a corner, whatever the std.
TEST(SameWalls, ARoundFootprintKeepsItsSides) {
  for (const auto& [sides, length] : {std::pair{6, 1.0}, {16, 2.0}, {32, 3.0}}) {
    const SameWalls walls = MergeSameWalls(Footprint(RegularPolygon(sides, length), true, 1.0));
    EXPECT_EQ(walls.map.segments.size(), static_cast<std::size_t>(sides)) << sides << "-gon";
  }
}

// Slight turns each within the digitiser's precision still add up to a curve: 30 sides of 3 m
// turning 1 degree each (29 degrees in all) are not one wall, nor are any two of them, since
// which two would be a matter of order. Sides turning 3 degrees are not joined pairwise.
TEST(SameWalls, ACurvedFacadeIsNotOneWall) {
  for (const double turn : {1.0, 3.0}) {
    const SameWalls walls = MergeSameWalls(Footprint(Arc(30, 3.0, turn), false, 1.0));
    EXPECT_EQ(walls.map.segments.size(), 30u) << turn << " degrees a side";
  }
}

// A wall drawn in three parts, a 3 degree kink, and two more parts: two walls, each part of one of
// them; the kink cuts the chain, so the straight runs still merge.
TEST(SameWalls, AKinkBetweenStraightRunsCutsTheWall) {
  std::vector<Vec2> points{{0, 0}, {10, 0}, {20, 0}, {30, 0}};
  const double kink = 3.0 * std::numbers::pi / 180.0;
  for (int i = 1; i <= 2; ++i)
    points.push_back(Vec2(30, 0) + 10.0 * i * Vec2(std::cos(kink), std::sin(kink)));
  const SameWalls walls = MergeSameWalls(Footprint(points, false, 1.0));
  ASSERT_EQ(walls.map.segments.size(), 2u);
  EXPECT_THAT(walls.members[0], ElementsAre(0, 1, 2));
  EXPECT_THAT(walls.members[1], ElementsAre(3, 4));
}

// Beacons on the wall x = 10, and the prior map's segment for it 0.4 m off, drawn whole or with a
// vertex at y = 0. Which beacons are related to it.
std::set<int> RelatedToAWall(bool split) {
  const std::vector<Vec2> beacons{
      {10.0, -6.0}, {10.0, -3.0}, {10.0, 0.3}, {10.0, 3.0}, {10.0, 6.0}};
  PriorMap map;
  map.buildings = {"b"};
  if (split) {
    map.segments = {Wall(10.4, -10, 10.4, 0, 0.5), Wall(10.4, 0, 10.4, 10, 0.5)};
  } else {
    map.segments = {Wall(10.4, -10, 10.4, 10, 0.5)};
  }
  const SensorNoise sensor;
  PriorMapSlam slam(Se2(), 0.0, testing::StandingStillMotion(), sensor, &map, SlamOptions{});
  Rng rng(6);
  std::set<int> related;
  for (const RelationRecord& r :
       testing::WatchBeacons(slam, Se2(), beacons, 30, sensor, &rng).relations)
    related.insert(r.landmark);
  return related;
}

// Drawn with a vertex at y = 0, the beacon next to it was gated with both parts, and its cluster
// (every beacon on the wall) never reached p_accept: no beacon was related to the wall at all.
TEST(SameWalls, BeaconsOnAWallSplitAtAVertexAreRelatedAsOnTheWholeWall) {
  const std::set<int> whole = RelatedToAWall(false);
  EXPECT_EQ(whole, (std::set<int>{0, 1, 2, 3, 4}));
  EXPECT_EQ(RelatedToAWall(true), whole);
}

// Two adjacent footprints (squares) that share the wall x = 10, as GeoJSON gives them: 8
// segments, 7 walls.
PriorMap TwoAdjacentBuildings() {
  PriorMap map;
  map.buildings = {"west", "east"};
  const auto ring = [&](double x0, double x1, int building) {
    const Vec2 c[4] = {{x0, 0}, {x1, 0}, {x1, 10}, {x0, 10}};
    for (int i = 0; i < 4; ++i) map.segments.push_back({c[i], c[(i + 1) % 4], 0.5, building});
  };
  ring(0, 10, 0);   // segment 1: (10, 0) -> (10, 10)
  ring(10, 20, 1);  // segment 7: (10, 10) -> (10, 0)
  return map;
}

TEST(SameWalls, MergesTheSharedWallOfTwoFootprintsAndKeepsTheRest) {
  const SameWalls walls = MergeSameWalls(TwoAdjacentBuildings());
  ASSERT_EQ(walls.map.segments.size(), 7u);
  ASSERT_EQ(walls.members.size(), 7u);
  EXPECT_THAT(walls.members[1], ElementsAre(1, 7));
  for (std::size_t w = 0; w < 7; ++w) {
    if (w != 1) {
      EXPECT_EQ(walls.members[w].size(), 1u) << w;
    }
  }
  // Identical copies give the segment back: same endpoints, same std (not fused to 0.35 m).
  const PriorSegment& shared = walls.map.segments[1];
  EXPECT_TRUE(shared.a.isApprox(Vec2(10, 0), 1e-12));
  EXPECT_TRUE(shared.b.isApprox(Vec2(10, 10), 1e-12));
  EXPECT_DOUBLE_EQ(shared.std, 0.5);
  EXPECT_EQ(shared.building, 0);
  EXPECT_THAT(shared.shared_with, ElementsAre(1));  // and still east's wall
  for (std::size_t w = 0; w < 7; ++w) {
    if (w != 1) {
      EXPECT_TRUE(walls.map.segments[w].shared_with.empty()) << w;
    }
  }
  EXPECT_EQ(walls.map.buildings, TwoAdjacentBuildings().buildings);
}

TEST(SameWalls, APartOfAWallMergesIntoTheWholeWithTheirSpreadInItsStd) {
  PriorMap map;
  map.buildings = {"long", "short"};
  map.segments = {Wall(0, 0, 20, 0, 0.5, 0), Wall(14, 0.15, 4, 0.15, 0.2, 1)};
  const SameWalls walls = MergeSameWalls(map);
  ASSERT_EQ(walls.map.segments.size(), 1u);
  const PriorSegment& merged = walls.map.segments[0];
  // Through all four endpoints, spanning them, in the first segment's direction.
  EXPECT_NEAR(merged.a.x(), 0.0, 0.01);
  EXPECT_NEAR(merged.b.x(), 20.0, 0.01);
  EXPECT_GT(merged.a.y(), 0.0);
  EXPECT_LT(merged.a.y(), 0.15);
  // The larger std grown by the largest distance of an endpoint from the fitted line.
  EXPECT_GT(merged.std, 0.5);
  EXPECT_LT(merged.std, std::hypot(0.5, 0.15));
}

// A vehicle standing still at the origin facing +x; five beacons on the wall x = 10, which the
// prior map holds twice (two buildings sharing it), 0.8 m off.
struct SharedWallWorld {
  std::vector<Vec2> beacons{{10.0, -6.0}, {10.0, -3.0}, {10.0, 0.0}, {10.0, 3.0}, {10.0, 6.0}};
  PriorMap map;
  SharedWallWorld() {
    map.buildings = {"west", "east"};
    map.segments.push_back({Vec2(10.8, -10.0), Vec2(10.8, 10.0), 1.0, 0});
    map.segments.push_back({Vec2(10.8, 10.0), Vec2(10.8, -10.0), 1.0, 1});
  }
};

SlamResult FilterSharedWall(bool merge) {
  const SharedWallWorld world;
  const SensorNoise sensor;
  SlamOptions options;
  options.merge_same_walls = merge;
  PriorMapSlam slam(Se2(), 0.0, testing::StandingStillMotion(), sensor, &world.map, options);
  Rng rng(4);
  return testing::WatchBeacons(slam, Se2(), world.beacons, 20, sensor, &rng);
}

TEST(SameWalls, PointsOnAWallTheMapHoldsTwiceAreRelatedToIt) {
  // Without the merge the probability of each point splits between the copies: no relation.
  EXPECT_TRUE(FilterSharedWall(false).relations.empty());
  const SlamResult merged = FilterSharedWall(true);
  ASSERT_EQ(merged.relations.size(), 5u);
  for (const RelationRecord& r : merged.relations) EXPECT_EQ(r.segment, 0);  // named by its first
  EXPECT_THAT(merged.same_walls, ElementsAre(ElementsAre(0, 1)));
  ASSERT_EQ(merged.segments.size(), 1u);
  EXPECT_EQ(merged.segments[0].segment, 0);
  EXPECT_NEAR(merged.segments[0].a.x(), 10.0, 0.05);
  EXPECT_NEAR(merged.segments[0].b.x(), 10.0, 0.05);
}

// Two buildings share a wall: south (x 10..20, y -10..0) and north (x 10..30, y 0..10), the wall
// y = 0. The prior map holds it in both footprints, 0.3 m off, and south's east wall (x = 20)
// 0.4 m off, std 0.5 m. A vehicle stands at (26, -12) facing north, by south's east face.
// Beacons: three on south's east wall, three on the shared wall where only north runs on (x > 20)
// and one at south's corner (20, 0), which lies on both the shared wall and south's east wall, so
// no single wall can be chosen for it: with relations to buildings it lies on "some wall of
// south". The merged wall is named by whichever footprint the map lists first; the relation must
// not depend on that.
struct TwoBuildingsSharingAWall {
  static constexpr int kCorner = 6;
  const Se2 pose{26.0, -12.0, std::numbers::pi / 2};
  std::vector<Vec2> beacons{{20, -8}, {20, -5}, {20, -2}, {23, 0}, {25, 0}, {27, 0}, {20, 0}};
  PriorMap map;
  std::vector<std::string> label;  // per prior segment: which wall it is, the copies alike
  RelationTruth truth;

  explicit TwoBuildingsSharingAWall(bool north_first) {
    // Walls: 0 shared, 1 south's east, then the others (no beacon is on them).
    const auto south = [&] {
      Add("south", {10, -10}, {20.4, -10}, "south south", 2);
      Add("south", {20.4, -10}, {20.4, 0.3}, "south east", 1);
      Add("south", {20.4, 0.3}, {10, 0.3}, "shared", 0);
      Add("south", {10, 0.3}, {10, -10}, "south west", 3);
    };
    const auto north = [&] {
      Add("north", {10, 0.3}, {30, 0.3}, "shared", 0);
      Add("north", {30, 0.3}, {30, 10}, "north east", 4);
      Add("north", {30, 10}, {10, 10}, "north north", 5);
      Add("north", {10, 10}, {10, 0.3}, "north west", 6);
    };
    if (north_first) {
      north();
      south();
    } else {
      south();
      north();
    }
    truth.landmark_wall = {1, 1, 1, 0, 0, 0, 0};
    truth.landmark_on_wall.assign(beacons.size(), true);
  }

  void Add(const std::string& building, Vec2 a, Vec2 b, const std::string& wall, int true_wall) {
    auto it = std::find(map.buildings.begin(), map.buildings.end(), building);
    if (it == map.buildings.end()) it = map.buildings.insert(it, building);
    map.segments.push_back({a, b, 0.5, static_cast<int>(it - map.buildings.begin())});
    label.push_back(wall);
    truth.segment_wall.push_back(true_wall);
  }
};

// What the filter related, in the map's own terms (building names, wall labels), so that runs on
// the same world listed in another order compare.
struct Related {
  std::set<std::pair<int, std::string>> to_walls;  // (landmark, wall)
  std::set<std::tuple<int, std::string, std::set<std::string>>> to_buildings;
  std::size_t incorrect = 0;
};

Related FilterTwoBuildingsSharingAWall(bool north_first) {
  const TwoBuildingsSharingAWall world(north_first);
  const SensorNoise sensor;
  SlamOptions options;
  options.building_relations = true;
  PriorMapSlam slam(world.pose, 0.0, testing::StandingStillMotion(), sensor, &world.map, options,
                    &world.truth);
  Rng rng(6);
  const SlamResult result =
      testing::WatchBeacons(slam, world.pose, world.beacons, 30, sensor, &rng);
  EXPECT_EQ(result.same_walls.size(), 1u);  // the shared wall, and nothing else
  Related related;
  for (const RelationRecord& r : result.relations) {
    if (!r.correct.value()) ++related.incorrect;
    if (r.building < 0) {
      related.to_walls.emplace(r.landmark, world.label[static_cast<std::size_t>(r.segment)]);
      continue;
    }
    std::set<std::string> walls;
    for (int wall : r.walls) walls.insert(world.label[static_cast<std::size_t>(wall)]);
    related.to_buildings.emplace(r.landmark,
                                 world.map.buildings[static_cast<std::size_t>(r.building)], walls);
  }
  return related;
}

// A merged wall used to keep only its first segment's building: listed first, south had its
// corner beacon related to it; listed second, the shared wall was north's alone, south had one
// wall gated at its corner and the beacon was never related. Now the shared wall is a wall of
// both, and the result is the same whichever building the map lists first.
TEST(SameWalls, AWallTwoBuildingsShareCountsForBothWhicheverIsListedFirst) {
  const Related south_first = FilterTwoBuildingsSharingAWall(false);
  const Related north_first = FilterTwoBuildingsSharingAWall(true);
  using Building = std::tuple<int, std::string, std::set<std::string>>;
  const Building corner{TwoBuildingsSharingAWall::kCorner, "south", {"shared", "south east"}};
  EXPECT_THAT(south_first.to_buildings, ElementsAre(corner));
  EXPECT_THAT(north_first.to_buildings, ElementsAre(corner));
  // The beacons on the walls are related to their own walls, alike in both orders.
  EXPECT_GE(south_first.to_walls.size(), 3u);
  EXPECT_EQ(north_first.to_walls, south_first.to_walls);
  for (const auto& [landmark, wall] : south_first.to_walls)
    EXPECT_EQ(wall, landmark < 3 ? "south east" : "shared") << landmark;
  EXPECT_EQ(south_first.incorrect, 0u);
  EXPECT_EQ(north_first.incorrect, 0u);
}

// The urban study (seed 1) with every true wall also held by a neighbouring footprint: an exact
// copy (shared vertices) or one digitised again (independent 1 m noise). Scored against the
// truth: relations applied, and the error of the mapped on-wall beacons.
struct Score {
  std::size_t correct = 0, incorrect = 0;
  double landmark_rms = 0.0;
};

Score DuplicatedWallsStudy(int copies, bool merge, int runs, double gate = kSameWallChi2) {
  const UrbanScenarioOptions scenario;
  const UrbanWorld world = MakeUrbanWorld(scenario, 1);
  Score score;
  double sum2 = 0.0;
  std::size_t n = 0;
  for (int r = 0; r < runs; ++r) {
    UrbanRun run = SimulateUrbanRun(world, scenario, 1, r);
    Rng rng = Rng::ForStream(7, static_cast<std::uint64_t>(r));
    const std::size_t segments = run.prior_map.segments.size();
    for (std::size_t i = 0; copies > 0 && i < segments; ++i) {
      if (run.segment_wall[i] < 0) continue;
      PriorSegment copy = run.prior_map.segments[i];
      if (copies == 2) {
        const Segment& truth = world.walls[static_cast<std::size_t>(run.segment_wall[i])];
        copy.a = truth.a + copy.std * Vec2(rng.Normal(), rng.Normal());
        copy.b = truth.b + copy.std * Vec2(rng.Normal(), rng.Normal());
      }
      std::swap(copy.a, copy.b);  // the neighbour's ring runs the other way
      copy.building = static_cast<int>(run.prior_map.buildings.size());
      run.prior_map.buildings.push_back("neighbour " + std::to_string(i));
      run.prior_map.segments.push_back(copy);
      run.segment_wall.push_back(run.segment_wall[i]);
    }
    const RelationTruth truth = TruthOf(world, run);
    SlamOptions options;
    options.merge_same_walls = merge;
    options.same_wall_chi2 = gate;
    const SlamResult result = RunSlam(run.input, &run.prior_map, options, &truth);
    for (const RelationRecord& relation : result.relations)
      ++(relation.correct.value() ? score.correct : score.incorrect);
    for (const MappedLandmark& mapped : result.all_landmarks) {
      const Beacon& beacon = world.beacons[static_cast<std::size_t>(mapped.estimate.id)];
      if (!beacon.on_wall) continue;
      sum2 += (mapped.estimate.position - beacon.position).squaredNorm();
      ++n;
    }
  }
  score.landmark_rms = std::sqrt(sum2 / static_cast<double>(n));
  return score;
}

TEST(SameWalls, LandmarksOnWallsThatNeighboursShareAreRelatedAndMappedAsWithoutTheCopies) {
  const int runs = 5;
  const Score plain = DuplicatedWallsStudy(0, true, runs);  // the study's own map
  // There the merge finds few pairs (distinct walls stand 2 m or more apart, 2 std) and changes
  // little.
  const Score unmerged = DuplicatedWallsStudy(0, false, runs);
  EXPECT_LT(plain.landmark_rms, 1.02 * unmerged.landmark_rms);
  EXPECT_LE(plain.incorrect, unmerged.incorrect + 2);
  // Every wall twice, shared vertices: without the merge no landmark is ever related (the
  // probability splits between the copies) and the map is as bad as with no prior map at all.
  const Score split = DuplicatedWallsStudy(1, false, runs);
  EXPECT_EQ(split.correct, 0u);
  EXPECT_GT(split.landmark_rms, 3.0 * plain.landmark_rms);
  // Merged, the relations and the map's error are those of the map without the copies.
  const Score shared = DuplicatedWallsStudy(1, true, runs);
  EXPECT_GE(static_cast<double>(shared.correct), 0.95 * static_cast<double>(plain.correct));
  EXPECT_LE(shared.incorrect, plain.incorrect + 2);
  EXPECT_LT(shared.landmark_rms, 1.05 * plain.landmark_rms);
  // Digitised twice, independently (1 m noise each): with the gate for overlaid maps (2) two
  // copies of three merge, and the error falls.
  const Score twice = DuplicatedWallsStudy(2, false, runs);
  const Score twice_merged = DuplicatedWallsStudy(2, true, runs, 2.0);
  EXPECT_LT(twice.correct, 5u);
  EXPECT_GT(static_cast<double>(twice_merged.correct), 0.4 * static_cast<double>(plain.correct));
  EXPECT_LT(twice_merged.landmark_rms, 0.6 * twice.landmark_rms);
  std::printf(
      "on-wall landmark RMS, m (relations correct/incorrect), %d runs:\n"
      "  study's map %.3f (%zu/%zu); every wall twice: %.3f (%zu/%zu) -> merged %.3f "
      "(%zu/%zu); digitised twice: %.3f (%zu/%zu) -> merged %.3f (%zu/%zu)\n",
      runs, plain.landmark_rms, plain.correct, plain.incorrect, split.landmark_rms, split.correct,
      split.incorrect, shared.landmark_rms, shared.correct, shared.incorrect, twice.landmark_rms,
      twice.correct, twice.incorrect, twice_merged.landmark_rms, twice_merged.correct,
      twice_merged.incorrect);
}

}  // namespace
}  // namespace priormap::slam
