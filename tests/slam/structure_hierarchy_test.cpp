// The structure class hierarchy and its part-of relation, and the hierarchy of a prior map.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <priormap/core/check.hpp>
#include <priormap/slam/prior_map.hpp>
#include <priormap/slam/structure_hierarchy.hpp>

namespace priormap::slam {
namespace {

using ::testing::ElementsAre;
using ::testing::IsEmpty;

// city > building > wall, as in the paper's Fig. 2 (a wall part of a building part of a city).
TEST(StructureHierarchy, PartOfIsTransitiveAndFollowsTheClasses) {
  StructureHierarchy h;
  const int city = h.AddClass("city");
  const int building = h.AddClass("building", city);
  const int wall = h.AddClass("wall", building);
  const int tree = h.AddClass("tree");
  EXPECT_EQ(h.ClassName(wall), "wall");

  const int c = h.AddInstance(city);
  const int b0 = h.AddInstance(building, c);
  const int b1 = h.AddInstance(building, c);
  const int w00 = h.AddInstance(wall, b0);
  const int w01 = h.AddInstance(wall, b0);
  const int w10 = h.AddInstance(wall, b1);
  const int t = h.AddInstance(tree);

  EXPECT_EQ(h.ClassOf(w01), wall);
  EXPECT_EQ(h.ParentOf(w01), b0);
  EXPECT_EQ(h.ParentOf(c), std::nullopt);
  EXPECT_TRUE(h.IsPartOf(w00, b0));
  EXPECT_TRUE(h.IsPartOf(w00, c));  // through its building
  EXPECT_FALSE(h.IsPartOf(w00, b1));
  EXPECT_FALSE(h.IsPartOf(b0, b0));  // not part of itself
  EXPECT_FALSE(h.IsPartOf(c, b0));   // the whole is not part of its part
  EXPECT_FALSE(h.IsPartOf(t, c));
  EXPECT_EQ(h.AncestorOfClass(w10, building), b1);
  EXPECT_EQ(h.AncestorOfClass(w10, city), c);
  EXPECT_EQ(h.AncestorOfClass(t, city), std::nullopt);
  EXPECT_THAT(h.PartsOf(b0, wall), ElementsAre(w00, w01));
  EXPECT_THAT(h.PartsOf(c, wall), ElementsAre(w00, w01, w10));
  EXPECT_THAT(h.PartsOf(c, building), ElementsAre(b0, b1));
  EXPECT_THAT(h.PartsOf(t, wall), IsEmpty());
}

TEST(StructureHierarchy, RejectsAnInstanceOutsideItsClassesParent) {
  StructureHierarchy h;
  const int building = h.AddClass("building");
  const int wall = h.AddClass("wall", building);
  const int tree = h.AddClass("tree");
  const int b = h.AddInstance(building);
  const int t = h.AddInstance(tree);
  EXPECT_THROW((void)h.AddInstance(wall, t), ContractError);      // a wall of a tree
  EXPECT_THROW((void)h.AddInstance(building, b), ContractError);  // a top-level class
  EXPECT_THROW((void)h.AddInstance(wall, 17), ContractError);     // no such instance
  EXPECT_THROW((void)h.AddClass("window", 9), ContractError);     // no such class
  EXPECT_NO_THROW((void)h.AddInstance(wall));                     // a wall of an unknown building
}

TEST(StructureHierarchy, PriorMapWallsArePartsOfTheirFeaturesBuilding) {
  PriorMap map;
  map.buildings = {"north", "south"};
  map.segments = {{Vec2(0, 0), Vec2(1, 0), 1.0, 1},
                  {Vec2(1, 0), Vec2(1, 1), 1.0, 0},
                  {Vec2(1, 1), Vec2(0, 1), 1.0, 1},
                  {Vec2(5, 5), Vec2(6, 5), 1.0, -1}};
  const PriorMapStructures s = StructuresOf(map);
  EXPECT_EQ(s.hierarchy.ClassName(s.building_class), "building");
  EXPECT_EQ(s.hierarchy.ClassName(s.wall_class), "wall");
  EXPECT_EQ(s.BuildingOf(0), 1);
  EXPECT_EQ(s.BuildingOf(1), 0);
  EXPECT_EQ(s.BuildingOf(3), std::nullopt);
  EXPECT_THAT(s.SegmentsOf(1), ElementsAre(0, 2));
  EXPECT_THAT(s.SegmentsOf(0), ElementsAre(1));
  EXPECT_TRUE(s.hierarchy.IsPartOf(s.wall_instance[2], s.building_instance[1]));
  EXPECT_FALSE(s.hierarchy.IsPartOf(s.wall_instance[2], s.building_instance[0]));
  EXPECT_THAT(s.BuildingsOf(0), ElementsAre(1));
  EXPECT_THAT(s.BuildingsOf(3), IsEmpty());
}

// A wall that buildings share (a merged wall: PriorSegment::shared_with) is a wall of each, one
// instance per building, whichever of them names it.
TEST(StructureHierarchy, ASharedWallIsPartOfEachOfItsBuildings) {
  PriorMap map;
  map.buildings = {"north", "south", "east"};
  map.segments = {{Vec2(0, 0), Vec2(1, 0), 1.0, 1, {0, 2}},
                  {Vec2(1, 0), Vec2(1, 1), 1.0, 0},
                  {Vec2(5, 5), Vec2(6, 5), 1.0, -1, {2}}};
  const PriorMapStructures s = StructuresOf(map);
  EXPECT_EQ(s.BuildingOf(0), 1);
  EXPECT_THAT(s.BuildingsOf(0), ElementsAre(0, 1, 2));
  EXPECT_THAT(s.BuildingsOf(1), ElementsAre(0));
  EXPECT_EQ(s.BuildingOf(2), 2);  // no building of its own: the one it is shared with
  EXPECT_THAT(s.BuildingsOf(2), ElementsAre(2));
  EXPECT_THAT(s.SegmentsOf(0), ElementsAre(0, 1));
  EXPECT_THAT(s.SegmentsOf(1), ElementsAre(0));
  EXPECT_THAT(s.SegmentsOf(2), ElementsAre(0, 2));
  ASSERT_EQ(s.shared_wall_instances[0].size(), 2u);
  EXPECT_TRUE(s.hierarchy.IsPartOf(s.shared_wall_instances[0][1], s.building_instance[2]));
  EXPECT_EQ(s.segment_of_wall[s.shared_wall_instances[0][1]], 0);

  map.segments[1].shared_with = {3};
  EXPECT_THROW((void)StructuresOf(map), ContractError);  // no building 3
}

}  // namespace
}  // namespace priormap::slam
