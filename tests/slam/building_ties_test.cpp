// Relations to buildings (eq. 3) must not depend on the order in which the map lists its
// buildings: a point that two buildings claim exactly equally is not given to the first of them.
#include <algorithm>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include <priormap/core/rng.hpp>
#include <priormap/slam/prior_map_slam.hpp>

#include "standing_beacons.hpp"

namespace priormap::slam {
namespace {

// What the filter related, by building names and wall endpoints, so that maps listing the same
// buildings in another order compare.
struct Related {
  std::set<std::pair<int, std::pair<double, double>>> to_walls;  // (landmark, wall's first end)
  std::set<std::pair<int, std::set<std::string>>> to_buildings;  // (landmark, buildings)
};

// One corner, x = 10.4 and y = 5.3, as two features of one map (an outline surveyed twice, or a
// building and its part): every wall near the corner is a wall of both. Three beacons on each
// wall and one at the corner, which no single wall can take; `order` lists the features.
Related FilterCornerOfTwoBuildings(const std::vector<std::string>& order) {
  const std::vector<Vec2> beacons{{10.0, -6.0}, {10.0, -3.0}, {10.0, 0.0}, {13.0, 5.0},
                                  {16.0, 5.0},  {19.0, 5.0},  {10.0, 5.0}};
  PriorMap map;
  map.buildings = order;
  for (int b = 0; b < static_cast<int>(order.size()); ++b) {
    map.segments.push_back({Vec2(10.4, -10.0), Vec2(10.4, 5.3), 0.5, b});
    map.segments.push_back({Vec2(10.4, 5.3), Vec2(20.0, 5.3), 0.5, b});
  }
  const SensorNoise sensor;
  SlamOptions options;
  options.building_relations = true;
  PriorMapSlam slam(Se2(), 0.0, testing::StandingStillMotion(), sensor, &map, options);
  Rng rng(6);
  const SlamResult result = testing::WatchBeacons(slam, Se2(), beacons, 30, sensor, &rng);
  Related related;
  for (const RelationRecord& r : result.relations) {
    const PriorSegment& s = map.segments[static_cast<std::size_t>(r.segment)];
    if (r.building < 0) {
      related.to_walls.emplace(r.landmark, std::make_pair(s.a.x(), s.a.y()));
      continue;
    }
    EXPECT_TRUE(std::is_sorted(r.buildings.begin(), r.buildings.end()));
    EXPECT_TRUE(!r.buildings.empty() && r.buildings.front() == r.building);
    std::set<std::string> names{map.buildings[static_cast<std::size_t>(r.building)]};
    for (int b : r.buildings) names.insert(map.buildings[static_cast<std::size_t>(b)]);
    related.to_buildings.emplace(r.landmark, names);
  }
  return related;
}

// The corner beacon's evidence for "some wall of the old outline" and "some wall of the new" is
// the same number, from the same two walls. It used to go to whichever the map listed first; now
// the relation names both, so listing them the other way round relates the same.
TEST(BuildingTies, ACornerTwoBuildingsShareIsRelatedToBothWhicheverIsListedFirst) {
  const Related old_first = FilterCornerOfTwoBuildings({"old survey", "new survey"});
  const Related new_first = FilterCornerOfTwoBuildings({"new survey", "old survey"});
  const std::set<std::pair<int, std::set<std::string>>> corner{{6, {"old survey", "new survey"}}};
  EXPECT_EQ(old_first.to_buildings, corner);
  EXPECT_EQ(new_first.to_buildings, corner);
  EXPECT_GE(old_first.to_walls.size(), 3u);
  EXPECT_EQ(old_first.to_walls, new_first.to_walls);
}

// Two buildings whose corners face the vehicle on either side of its heading, mirror images:
// three beacons on each of their walls and one at each corner. Observed without noise, both corner
// beacons are related to their buildings in the same frame. Returns every landmark's final
// estimate, by id.
std::vector<LandmarkEstimate> FilterTwoCorners(bool left_first) {
  std::vector<Vec2> beacons;
  PriorMap map;
  for (const double side : left_first ? std::vector{1.0, -1.0} : std::vector{-1.0, 1.0}) {
    const int b = static_cast<int>(map.buildings.size());
    map.buildings.push_back(side > 0 ? "left" : "right");
    map.segments.push_back({Vec2(10.4, side * 3.3), Vec2(10.4, side * 15.0), 0.5, b});
    map.segments.push_back({Vec2(10.4, side * 3.3), Vec2(20.0, side * 3.3), 0.5, b});
  }
  for (const double side : {1.0, -1.0}) {
    for (const Vec2& p : {Vec2(10.0, 6.0), Vec2(10.0, 9.0), Vec2(10.0, 12.0), Vec2(13.0, 3.0),
                          Vec2(16.0, 3.0), Vec2(19.0, 3.0), Vec2(10.0, 3.0)}) {
      beacons.emplace_back(p.x(), side * p.y());
    }
  }
  SlamOptions options;
  options.building_relations = true;
  PriorMapSlam slam(Se2(), 0.0, testing::StandingStillMotion(), SensorNoise{}, &map, options);
  const SlamResult result = testing::WatchBeacons(slam, Se2(), beacons, 30, SensorNoise{}, nullptr);
  std::size_t building_relations = 0;
  for (const RelationRecord& r : result.relations) building_relations += r.building >= 0;
  EXPECT_EQ(building_relations, 2u);  // each corner beacon to its building
  std::vector<LandmarkEstimate> landmarks = result.landmarks;
  std::sort(landmarks.begin(), landmarks.end(),
            [](const auto& a, const auto& b) { return a.id < b.id; });
  return landmarks;
}

// The relations to buildings of one frame are mixtures applied one after another, and the
// collapse after each makes the order matter. They used to be applied in building order, so
// listing the buildings the other way round moved the map; now they go by landmark.
TEST(BuildingTies, RelationsToBuildingsOfOneFrameDoNotDependOnTheBuildingsOrder) {
  const std::vector<LandmarkEstimate> left_first = FilterTwoCorners(true);
  const std::vector<LandmarkEstimate> right_first = FilterTwoCorners(false);
  ASSERT_EQ(left_first.size(), right_first.size());
  for (std::size_t i = 0; i < left_first.size(); ++i) {
    EXPECT_EQ(left_first[i].id, right_first[i].id);
    EXPECT_LT((left_first[i].position - right_first[i].position).norm(), 1e-12)
        << "landmark " << left_first[i].id;
  }
}

}  // namespace
}  // namespace priormap::slam
