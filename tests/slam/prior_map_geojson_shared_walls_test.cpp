// Prior maps whose buildings share walls, through GeoJSON: a merged map (MergeSameWalls) written
// and read back must keep every building's footprint, and merge back into the same walls.
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include <priormap/core/check.hpp>
#include <priormap/slam/same_walls.hpp>
#include <priormap/slam/slam_io.hpp>

namespace priormap::slam {
namespace {

PriorMap Parse(const std::string& text) {
  const Result<PriorMap> map = ParsePriorMapGeoJson(text, "map.geojson", 1.0);
  EXPECT_TRUE(map.ok()) << (map.ok() ? "" : map.error());
  return map.ok() ? map.value() : PriorMap{};
}

// Whether segments p and q are the same edge, either way round (merged walls are fits, so
// allow rounding: a few ulps of coordinates as large as UTM's).
bool SameEdge(const PriorSegment& p, const PriorSegment& q) {
  const auto near = [](const Vec2& u, const Vec2& v) {
    return (u - v).norm() <= 1e-9 * std::max(1.0, u.cwiseAbs().maxCoeff());
  };
  return (near(p.a, q.a) && near(p.b, q.b)) || (near(p.a, q.b) && near(p.b, q.a));
}

// The edges of building `b`'s footprint: its own segments and those it shares.
std::vector<PriorSegment> Footprint(const PriorMap& map, int b) {
  std::vector<PriorSegment> edges;
  for (const PriorSegment& s : map.segments) {
    const bool shared =
        std::find(s.shared_with.begin(), s.shared_with.end(), b) != s.shared_with.end();
    if (s.building == b || shared) edges.push_back(s);
  }
  return edges;
}

::testing::AssertionResult SameFootprints(const PriorMap& expected, const PriorMap& actual) {
  if (expected.buildings != actual.buildings) return ::testing::AssertionFailure() << "names";
  for (int b = 0; b < static_cast<int>(expected.buildings.size()); ++b) {
    const std::vector<PriorSegment> want = Footprint(expected, b), got = Footprint(actual, b);
    if (want.size() != got.size()) {
      return ::testing::AssertionFailure() << "building " << expected.buildings[b] << " has "
                                           << got.size() << " edges, expected " << want.size();
    }
    for (const PriorSegment& edge : want) {
      if (std::none_of(got.begin(), got.end(), [&](const auto& g) { return SameEdge(edge, g); })) {
        return ::testing::AssertionFailure()
               << "building " << expected.buildings[b] << " lost the edge (" << edge.a.x() << ", "
               << edge.a.y() << ")-(" << edge.b.x() << ", " << edge.b.y() << ")";
      }
    }
  }
  return ::testing::AssertionSuccess();
}

// Wall by wall: the same edge, building and shared_with.
::testing::AssertionResult SameWallsOf(const PriorMap& expected, const PriorMap& actual) {
  if (expected.segments.size() != actual.segments.size()) {
    return ::testing::AssertionFailure()
           << actual.segments.size() << " walls, expected " << expected.segments.size();
  }
  for (std::size_t i = 0; i < expected.segments.size(); ++i) {
    const PriorSegment &want = expected.segments[i], &got = actual.segments[i];
    if (!SameEdge(want, got) || want.building != got.building ||
        want.shared_with != got.shared_with || std::abs(want.std - got.std) > 1e-12) {
      return ::testing::AssertionFailure() << "wall " << i << " differs";
    }
  }
  return ::testing::AssertionSuccess();
}

// Two terraced houses: west's east wall is east's west wall, traced the other way round.
constexpr const char* kTerrace = R"({"type": "FeatureCollection", "features": [
  {"type": "Feature", "properties": {"name": "west"}, "geometry": {"type": "Polygon",
   "coordinates": [[[0, 0], [10, 0], [10, 10], [0, 10], [0, 0]]]}},
  {"type": "Feature", "properties": {"name": "east"}, "geometry": {"type": "Polygon",
   "coordinates": [[[10, 0], [20, 0], [20, 10], [10, 10], [10, 0]]]}}
]})";

// The terrace at UTM-like coordinates (zone 31 easting and northing, m).
std::string UtmTerrace() {
  std::string text = kTerrace;
  for (const auto& [from, to] : {std::pair<std::string, std::string>{"[0, ", "[500000.25, "},
                                 {"[10, ", "[500010.25, "},
                                 {"[20, ", "[500020.25, "},
                                 {", 0]", ", 5000000.75]"},
                                 {", 10]", ", 5000010.75]"}}) {
    for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at))
      text.replace(at, from.size(), to);
  }
  return text;
}

class PriorMapGeoJsonSharedWalls : public ::testing::TestWithParam<std::string> {};

TEST_P(PriorMapGeoJsonSharedWalls, AMergedMapRoundTripsWithEveryFootprintClosed) {
  const PriorMap read = Parse(GetParam());
  const SameWalls merged = MergeSameWalls(read);
  ASSERT_EQ(merged.map.segments.size(), 7U);  // one wall fewer: the one they share
  const PriorMap again = Parse(FormatPriorMapGeoJson(merged.map));
  // Each building reads back with its 4 walls, as the file it came from had them.
  EXPECT_TRUE(SameFootprints(read, again));
  EXPECT_EQ(Footprint(again, 1).size(), 4U);
  // Merged again, the same walls: the shared one still a wall of both.
  const SameWalls remerged = MergeSameWalls(again);
  EXPECT_TRUE(SameWallsOf(merged.map, remerged.map));
  EXPECT_TRUE(SameFootprints(merged.map, remerged.map));
  const auto shared = std::find_if(remerged.map.segments.begin(), remerged.map.segments.end(),
                                   [](const PriorSegment& s) { return !s.shared_with.empty(); });
  ASSERT_NE(shared, remerged.map.segments.end());
  EXPECT_EQ(shared->building, 0);
  EXPECT_EQ(shared->shared_with, std::vector<int>{1});
}

INSTANTIATE_TEST_SUITE_P(LocalAndUtm, PriorMapGeoJsonSharedWalls,
                         ::testing::Values(std::string(kTerrace), UtmTerrace()));

// East is shallower: its west wall covers 6 m of west's 10 m east wall, enough to be the same
// wall (MergeSameWalls: half the shorter one). The merged wall spans both, and the merged map's
// east holds it whole: that is what the map it was written from says.
TEST(PriorMapGeoJsonSharedWallsPartly, APartlySharedWallRoundTripsAsTheMergedMapHoldsIt) {
  const PriorMap read = Parse(R"({"type": "FeatureCollection", "features": [
    {"type": "Feature", "properties": {"name": "west"}, "geometry": {"type": "Polygon",
     "coordinates": [[[0, 0], [10, 0], [10, 10], [0, 10], [0, 0]]]}},
    {"type": "Feature", "properties": {"name": "east"}, "geometry": {"type": "Polygon",
     "coordinates": [[[10, 2], [20, 2], [20, 8], [10, 8], [10, 2]]]}}
  ]})");
  const SameWalls merged = MergeSameWalls(read);
  ASSERT_EQ(merged.map.segments.size(), 7U);
  const PriorMap again = Parse(FormatPriorMapGeoJson(merged.map));
  EXPECT_TRUE(SameFootprints(merged.map, again));
  const std::vector<PriorSegment> east = Footprint(again, 1);
  ASSERT_EQ(east.size(), 4U);
  const PriorSegment whole{Vec2(10, 0), Vec2(10, 10), 1.0, 1};
  EXPECT_TRUE(
      std::any_of(east.begin(), east.end(), [&](const auto& s) { return SameEdge(s, whole); }));
  const SameWalls remerged = MergeSameWalls(again);
  EXPECT_TRUE(SameWallsOf(merged.map, remerged.map));
}

// A wall shared with a building the map does not have cannot be written.
TEST(PriorMapGeoJsonSharedWallsWriter, WriterRejectsAWallSharedWithNoBuilding) {
  PriorMap map;
  map.buildings = {"a"};
  map.segments = {{Vec2(0, 0), Vec2(1, 0), 1.0, 0, {1}}};
  EXPECT_THROW((void)FormatPriorMapGeoJson(map), ContractError);
  map.segments[0].shared_with = {-1};
  EXPECT_THROW((void)FormatPriorMapGeoJson(map), ContractError);
}

}  // namespace
}  // namespace priormap::slam
