#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/check.hpp>
#include <priormap/core/observed_area.hpp>
#include <priormap/core/scene_truth.hpp>

namespace priormap {
namespace {

// A w × h room centred on the origin, optionally with a clutter box.
Scene Room(double w, double h) {
  Scene scene;
  scene.name = "room";
  scene.surfaces.push_back(
      {Polyline{{{-w / 2, -h / 2}, {w / 2, -h / 2}, {w / 2, h / 2}, {-w / 2, h / 2}}, true}, false,
       "walls"});
  scene.waypoints = {{-0.5, -0.5}, {0.5, -0.5}};
  return scene;
}

void AddBox(Scene* scene, const Vec2& min, const Vec2& max) {
  scene->surfaces.push_back(
      {Polyline{{min, {max.x(), min.y()}, max, {min.x(), max.y()}}, true}, true, "box"});
}

ScenePrimitive SegmentWall(const Vec2& a, const Vec2& b) {
  return {Segment{a, b}, 0, 0, false};
}

TEST(SegmentTouchesWall, SegmentsCrossingTouchingOverlappingOrApart) {
  const ScenePrimitive wall = SegmentWall({0, 0}, {1, 0});
  EXPECT_TRUE(SegmentTouchesWall({0.5, -1}, {0.5, 1}, wall));     // crossing
  EXPECT_TRUE(SegmentTouchesWall({0.5, 0}, {0.5, 1}, wall));      // ending on it
  EXPECT_TRUE(SegmentTouchesWall({1, 0}, {2, 1}, wall));          // at its end point
  EXPECT_TRUE(SegmentTouchesWall({0.5, 0}, {3, 0}, wall));        // collinear, overlapping
  EXPECT_FALSE(SegmentTouchesWall({1.5, 0}, {3, 0}, wall));       // collinear, apart
  EXPECT_FALSE(SegmentTouchesWall({0, 0.1}, {1, 0.1}, wall));     // parallel
  EXPECT_FALSE(SegmentTouchesWall({0.5, 0.01}, {0.5, 1}, wall));  // stopping short
}

TEST(SegmentTouchesWall, CirclesOnlyWhereTheCurveIs) {
  const ScenePrimitive circle{Circle{{0, 0}, 1.0}, 0, 0, false};
  EXPECT_TRUE(SegmentTouchesWall({0, 0}, {2, 0}, circle));        // from inside out
  EXPECT_TRUE(SegmentTouchesWall({-2, 0.5}, {2, 0.5}, circle));   // a chord's line
  EXPECT_TRUE(SegmentTouchesWall({-1, 1}, {1, 1}, circle));       // tangent
  EXPECT_FALSE(SegmentTouchesWall({-0.5, 0}, {0.5, 0}, circle));  // inside
  EXPECT_FALSE(SegmentTouchesWall({2, 2}, {3, 2}, circle));       // outside
  EXPECT_NEAR(DistanceToWall(Vec2(0.25, 0), circle), 0.75, 1e-12);
  EXPECT_NEAR(DistanceToWall(Vec2(0, 3), circle), 2.0, 1e-12);
}

TEST(SceneTruth, RoomIsFreeInsideAndOccupiedBeyondItsWalls) {
  const Scene scene = Room(4, 4);
  const SceneTruth truth = SceneTruth::OfScene(scene);
  EXPECT_FALSE(truth.Occupied({0, 0}));
  EXPECT_FALSE(truth.Occupied({1.9, -1.9}));
  // A few millimetres either side of a wall, between the raster's centres.
  EXPECT_FALSE(truth.Occupied({1.997, 0.3333}));
  EXPECT_TRUE(truth.Occupied({2.003, 0.3333}));
  EXPECT_FALSE(truth.Occupied({-0.4444, -1.9985}));
  EXPECT_TRUE(truth.Occupied({-0.4444, -2.0015}));
  EXPECT_TRUE(truth.Occupied({2.05, 0}));
  EXPECT_TRUE(truth.Occupied({50, -7}));  // beyond the raster: the unbounded face
  EXPECT_NEAR(truth.DistanceToWall({0, 0}), 2.0, 1e-12);
  EXPECT_NEAR(truth.DistanceToWall({1.5, 0.2}), 0.5, 1e-12);
  EXPECT_NEAR(truth.DistanceToWall({3, 0}), 1.0, 1e-12);
  EXPECT_EQ(truth.walls().size(), 4u);
}

TEST(SceneTruth, ClutterIsOccupiedAndTheFloorAroundItFree) {
  Scene scene = Room(4, 4);
  AddBox(&scene, {0.5, 0.5}, {1.0, 0.8});
  const SceneTruth truth = SceneTruth::OfScene(scene);
  EXPECT_TRUE(truth.Occupied({0.75, 0.65}));
  EXPECT_TRUE(truth.Occupied({0.999, 0.799}));
  EXPECT_FALSE(truth.Occupied({1.001, 0.65}));
  EXPECT_FALSE(truth.Occupied({1.5, 1.5}));  // between the box and the walls
}

TEST(SceneTruth, EveryBuiltinSceneHasItsFreeSpaceWhite) {
  struct Probe {
    const char* scene;
    Vec2 point;
    bool occupied;
  };
  const std::vector<Probe> probes = {
      {"square", {0, 0}, false},
      {"square", {2.1, 0}, true},
      {"rectangle", {2.9, 1.9}, false},
      {"rectangle", {3.05, 0}, true},
      {"circle", {1.99, 0}, false},
      {"circle", {0, -2.01}, true},
      {"circle", {1.5, 1.5}, true},          // beyond the curve, inside its box
      {"two-circles", {-0.95, 0.25}, true},  // in a pillar
      {"two-circles", {1.2, -0.5}, true},    // in the other
      {"two-circles", {2.0, 2.0}, false},    // the open floor around them
      {"two-circles", {40, 40}, false},      // and far beyond
      {"l-room", {-2, 2}, false},
      {"l-room", {2, -2}, false},
      {"l-room", {1.5, 1.5}, true},     // the L's missing quarter
      {"l-room", {-0.8, -2.3}, true},   // in the box
      {"l-room", {-2.3, -0.6}, true},   // in the bin
      {"l-room", {-2.3, -0.4}, false},  // beside it
      {"corridor", {0, 0}, false},
      {"corridor", {2, 1.5}, false},  // through the door
      // Zero-thickness walls: the outside is reached through the doorway, so it is free too.
      {"corridor", {0, -1.05}, false},
  };
  for (const Probe& probe : probes) {
    const Scene scene = *BuiltinScene(probe.scene);
    const SceneTruth truth = SceneTruth::OfScene(scene);
    EXPECT_EQ(truth.Occupied(probe.point), probe.occupied)
        << probe.scene << " at " << probe.point.transpose();
  }
}

TEST(SceneTruth, RefusesASeedOnAWall) {
  const Scene scene = Room(4, 4);
  const std::vector<Vec2> seeds = {{2.0, 0.0}};
  EXPECT_THROW(SceneTruth(scene, seeds), ContractError);
  EXPECT_THROW(SceneTruth(scene, std::vector<Vec2>{}), ContractError);
}

// What SceneTruth and the simulator would refuse with an internal error, said up front.
TEST(SceneChecks, PointsOnSurfacesAndWaypointPathsThroughWalls) {
  Scene scene = Room(4, 4);
  EXPECT_EQ(PointOnASurface(scene, std::vector<Vec2>{{0, 0}, {1.9, 1.9}}), "");
  EXPECT_THAT(PointOnASurface(scene, std::vector<Vec2>{{0, 0}, {2.0, 0.5}}),
              ::testing::HasSubstr("(2, 0.5) lies on surface 1"));
  EXPECT_EQ(WaypointPathProblem(scene), "");
  scene.waypoints = {{0, 0}, {0, 0}};
  EXPECT_THAT(WaypointPathProblem(scene), ::testing::HasSubstr("no waypoint path"));
  scene.waypoints = {{0, 0}, {1, 0}, {1, 3}};
  EXPECT_THAT(WaypointPathProblem(scene),
              ::testing::HasSubstr("the leg from waypoint 1 (1, 0) to waypoint 2 (1, 3) meets "
                                   "surface 2"));
}

TEST(ObservedArea, VisibleBehindASurfaceOrUnseen) {
  const Scene scene = Room(4, 4);
  const ObservedArea area(scene, {{.pose = Se2(0, 0, 0), .fov = kTwoPi, .max_range = 8}}, 0.1);
  EXPECT_EQ(area.Classify({1, 1}), Observation::kVisible);
  EXPECT_EQ(area.Classify({0, 0}), Observation::kVisible);
  EXPECT_EQ(area.Classify({2, 0.3}), Observation::kVisible);  // on the wall seen
  EXPECT_EQ(area.Classify({2.05, 0}), Observation::kBehindSurface);
  EXPECT_EQ(area.Classify({0, -2.09}), Observation::kBehindSurface);
  EXPECT_EQ(area.Classify({2.2, 0}), Observation::kUnseen);
  EXPECT_EQ(area.Classify({5, 0}), Observation::kUnseen);
}

TEST(ObservedArea, FieldOfViewAndRangeLimitIt) {
  const Scene scene = Room(4, 4);
  // A 180° sensor looking along +x with a 1 m reach.
  const ObservedArea area(scene, {{.pose = Se2(0, 0, 0), .fov = kPi, .max_range = 1.0}}, 0.1);
  EXPECT_EQ(area.Classify({0.9, 0}), Observation::kVisible);
  EXPECT_EQ(area.Classify({0, 0.5}), Observation::kVisible);    // at the edge of the view
  EXPECT_EQ(area.Classify({-0.1, 0.5}), Observation::kUnseen);  // behind the sensor
  EXPECT_EQ(area.Classify({1.05, 0}), Observation::kUnseen);    // beyond its reach, no wall
  const ObservedArea near_wall(scene, {{.pose = Se2(1.5, 0, 0), .fov = kPi, .max_range = 1.0}},
                               0.1);
  EXPECT_EQ(near_wall.Classify({2.05, 0}), Observation::kBehindSurface);  // wall at 0.5 m
}

TEST(ObservedArea, ClutterHidesWhatIsBehindIt) {
  Scene scene = Room(4, 4);
  AddBox(&scene, {0.8, -0.2}, {1.2, 0.2});
  const SensorView left{.pose = Se2(0, 0, 0), .fov = kTwoPi, .max_range = 8};
  const ObservedArea area(scene, {left}, 0.1);
  EXPECT_EQ(area.Classify({0.85, 0}), Observation::kBehindSurface);  // in the box
  EXPECT_EQ(area.Classify({1.5, 0}), Observation::kUnseen);          // in its shadow
  const SensorView right{.pose = Se2(1.8, 0, kPi), .fov = kTwoPi, .max_range = 8};
  const ObservedArea both(scene, {left, right}, 0.1);
  EXPECT_EQ(both.Classify({1.5, 0}), Observation::kVisible);
  EXPECT_EQ(both.Classify({1.0, 0}), Observation::kUnseen);  // the box's middle
}

TEST(ObservedArea, VisibleWallPointsAreThoseInView) {
  const Scene scene = Room(4, 4);
  const ObservedArea all(scene, {{.pose = Se2(0, 0, 0), .fov = kTwoPi, .max_range = 8}}, 0.1);
  EXPECT_EQ(VisibleWallPoints(scene, all, 0.1).size(), 160u);
  // Looking along +x with 180°: the right wall and the right halves of the top and bottom.
  const ObservedArea half(scene, {{.pose = Se2(0, 0, 0), .fov = kPi, .max_range = 8}}, 0.1);
  const std::vector<Vec2> points = VisibleWallPoints(scene, half, 0.1);
  EXPECT_EQ(points.size(), 80u);
  for (const Vec2& p : points) EXPECT_GT(p.x(), 0.0);
}

}  // namespace
}  // namespace priormap
