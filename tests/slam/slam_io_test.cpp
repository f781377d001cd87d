// The files of `priormap slam run`: hand-written examples parse as documented, writers produce
// what the readers accept, and write -> read gives back the same values bit for bit.
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <priormap/core/check.hpp>
#include <priormap/core/file_io.hpp>
#include <priormap/slam/slam_io.hpp>

#include "testing/temp_dir.hpp"

namespace priormap::slam {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

constexpr double kPi = std::numbers::pi;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// ---- equality, bit for bit (NaN equals NaN) ----

bool Same(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b) ||
         (std::isnan(a) && std::isnan(b));
}

bool Same(const Vec2& a, const Vec2& b) {
  return Same(a.x(), b.x()) && Same(a.y(), b.y());
}

::testing::AssertionResult SameFrames(const std::vector<ObservationFrame>& a,
                                      const std::vector<ObservationFrame>& b) {
  if (a.size() != b.size())
    return ::testing::AssertionFailure() << a.size() << " frames vs " << b.size();
  for (std::size_t f = 0; f < a.size(); ++f) {
    const auto& oa = a[f].observations;
    const auto& ob = b[f].observations;
    if (!Same(a[f].time, b[f].time) || oa.size() != ob.size())
      return ::testing::AssertionFailure() << "frame " << f << " differs in time or size";
    for (std::size_t i = 0; i < oa.size(); ++i) {
      if (oa[i].id != ob[i].id || !Same(oa[i].range, ob[i].range) ||
          !Same(oa[i].bearing, ob[i].bearing)) {
        return ::testing::AssertionFailure() << "frame " << f << " observation " << i << " differs";
      }
    }
  }
  return ::testing::AssertionSuccess();
}

::testing::AssertionResult SameOdometry(const Odometry& a, const Odometry& b) {
  if (!Same(a.start_time, b.start_time)) return ::testing::AssertionFailure() << "start time";
  if (a.steps.size() != b.steps.size())
    return ::testing::AssertionFailure() << a.steps.size() << " steps vs " << b.steps.size();
  for (std::size_t k = 0; k < a.steps.size(); ++k) {
    const MotionStep& sa = a.steps[k];
    const MotionStep& sb = b.steps[k];
    bool same = Same(sa.time, sb.time) && Same(sa.dt, sb.dt) &&
                sa.motion.index() == sb.motion.index() &&
                Same(sa.increment_std.x(), sb.increment_std.x()) &&
                Same(sa.increment_std.y(), sb.increment_std.y()) &&
                Same(sa.increment_std.z(), sb.increment_std.z());
    if (same && sa.motion.index() == 0) {
      const auto& ca = std::get<BicycleControl>(sa.motion);
      const auto& cb = std::get<BicycleControl>(sb.motion);
      same = Same(ca.speed, cb.speed) && Same(ca.steer, cb.steer);
    } else if (same) {
      const Se2& ia = std::get<Se2>(sa.motion);
      const Se2& ib = std::get<Se2>(sb.motion);
      same = Same(ia.x(), ib.x()) && Same(ia.y(), ib.y()) && Same(ia.theta(), ib.theta());
    }
    if (!same) return ::testing::AssertionFailure() << "step " << k << " differs";
  }
  return ::testing::AssertionSuccess();
}

::testing::AssertionResult SameMap(const PriorMap& a, const PriorMap& b) {
  if (a.buildings != b.buildings) return ::testing::AssertionFailure() << "building names differ";
  if (a.segments.size() != b.segments.size())
    return ::testing::AssertionFailure()
           << a.segments.size() << " segments vs " << b.segments.size();
  for (std::size_t i = 0; i < a.segments.size(); ++i) {
    const PriorSegment& sa = a.segments[i];
    const PriorSegment& sb = b.segments[i];
    if (!Same(sa.a, sb.a) || !Same(sa.b, sb.b) || !Same(sa.std, sb.std) ||
        sa.building != sb.building) {
      return ::testing::AssertionFailure() << "segment " << i << " differs";
    }
  }
  return ::testing::AssertionSuccess();
}

template <typename T>
T Ok(Result<T> result) {
  EXPECT_TRUE(result.ok()) << result.error();
  if (!result.ok()) throw std::runtime_error(result.error());
  return std::move(result).value();
}

std::vector<ObservationFrame> ParseObservations(const std::string& text) {
  return Ok(ParseObservationsCsv(text, "obs.csv"));
}
Odometry ParseOdometry(const std::string& text) {
  return Ok(ParseOdometryCsv(text, "odom.csv"));
}
PriorMap ParseMap(const std::string& text, double default_std = 1.0) {
  return Ok(ParsePriorMapGeoJson(text, "map.geojson", default_std));
}

// ---- observations ----

TEST(ObservationsCsv, ConsecutiveRowsWithOneTimeFormAFrame) {
  const auto frames = ParseObservations(
      "# beacons seen by the vehicle\n"
      "time,id,range,bearing\n"
      "\n"
      "0.0, 3, 12.5, 0.25\n"
      "0.0, 7, 4,   -1.5\n"
      "  # a comment inside\n"
      "0.2, 3, 12.25, +0.5\n"
      "0.4, 3, 1e1, -3.141592653589793\n"
      "0.4, 4, 9, 3.141592653589793\n");
  ASSERT_EQ(frames.size(), 3U);
  EXPECT_EQ(frames[0].time, 0.0);
  ASSERT_EQ(frames[0].observations.size(), 2U);
  EXPECT_EQ(frames[0].observations[1].id, 7);
  EXPECT_EQ(frames[0].observations[1].range, 4.0);
  EXPECT_EQ(frames[0].observations[1].bearing, -1.5);
  EXPECT_EQ(frames[1].time, 0.2);
  EXPECT_EQ(frames[1].observations[0].bearing, 0.5);
  EXPECT_EQ(frames[2].observations[0].range, 10.0);
  EXPECT_EQ(frames[2].observations[0].bearing, -kPi);
  EXPECT_EQ(frames[2].observations[1].bearing, kPi);
}

TEST(ObservationsCsv, UnknownIdsAreEmptyOrMinusOneAndMayRepeat) {
  const auto frames = ParseObservations("time,id,range,bearing\n1,,5,0\n1,-1,6,0\n2,,7,0\n");
  ASSERT_EQ(frames.size(), 2U);
  ASSERT_EQ(frames[0].observations.size(), 2U);
  EXPECT_EQ(frames[0].observations[0].id, -1);
  EXPECT_EQ(frames[0].observations[1].id, -1);
  EXPECT_EQ(frames[1].observations[0].id, -1);
}

TEST(ObservationsCsv, ColumnsMayComeInAnyOrderAndIdMayBeLeftOut) {
  const auto frames = ParseObservations("bearing,range,time\n0.5,3,1\n");
  ASSERT_EQ(frames.size(), 1U);
  EXPECT_EQ(frames[0].time, 1.0);
  EXPECT_EQ(frames[0].observations[0].id, -1);
  EXPECT_EQ(frames[0].observations[0].range, 3.0);
  EXPECT_EQ(frames[0].observations[0].bearing, 0.5);
}

TEST(ObservationsCsv, AcceptsCrLfQuotesAndAByteOrderMark) {
  const auto frames =
      ParseObservations("\xef\xbb\xbf\"time\",\"id\",\"range\",\"bearing\"\r\n1,\"2\",3,0\r\n");
  ASSERT_EQ(frames.size(), 1U);
  EXPECT_EQ(frames[0].observations[0].id, 2);
}

TEST(ObservationsCsv, HeaderOnlyMeansNoFrames) {
  EXPECT_TRUE(ParseObservations("time,id,range,bearing\n").empty());
}

TEST(ObservationsCsv, TheLargestIdIsTwoToTheThirtyOneMinusOne) {
  const auto frames = ParseObservations("time,id,range,bearing\n0,2147483647,1,0\n0,0,1,0\n");
  EXPECT_EQ(frames[0].observations[0].id, 2147483647);
  EXPECT_EQ(frames[0].observations[1].id, 0);
}

TEST(ObservationsCsv, WriterWritesOneRowPerObservationAtFullPrecision) {
  const std::vector<ObservationFrame> frames = {{0.1, {{3, 12.5, 0.1}, {7, 1.0 / 3.0, -kPi}}},
                                                {0.30000000000000004, {{3, 1e-300, kPi}}}};
  EXPECT_EQ(FormatObservationsCsv(frames),
            "time,id,range,bearing\n"
            "0.1,3,12.5,0.1\n"
            "0.1,7,0.3333333333333333,-3.141592653589793\n"
            "0.30000000000000004,3,1e-300,3.141592653589793\n");
}

TEST(ObservationsCsv, RowsWithoutRangeAndBearingAreFramesWithoutObservations) {
  const auto frames = ParseObservations(
      "time,id,range,bearing\n"
      "0.0,,,\n"
      "0.2,3,5,0\n"
      "0.4,-1, ,\n"
      "0.4,,,\n"
      "0.6,,,\n"
      "0.6,4,6,0.5\n");
  ASSERT_EQ(frames.size(), 4U);
  EXPECT_TRUE(frames[0].observations.empty());
  EXPECT_EQ(frames[1].observations.size(), 1U);
  EXPECT_EQ(frames[2].time, 0.4);
  EXPECT_TRUE(frames[2].observations.empty());
  ASSERT_EQ(frames[3].observations.size(), 1U);  // the marker adds nothing to a frame
  EXPECT_EQ(frames[3].observations[0].id, 4);
}

TEST(ObservationsCsv, FramesWithoutObservationsAreWrittenAsEmptyRows) {
  const std::vector<ObservationFrame> frames = {{0.0, {}}, {1.0, {{-1, 2.0, 0.0}}}, {2.0, {}}};
  const std::string text = FormatObservationsCsv(frames);
  EXPECT_EQ(text, "time,id,range,bearing\n0,,,\n1,-1,2,0\n2,,,\n");
  EXPECT_TRUE(SameFrames(ParseObservations(text), frames));
}

TEST(ObservationsCsv, WriterRejectsWhatCannotBeReadBack) {
  const auto format = [](std::vector<ObservationFrame> frames) {
    return FormatObservationsCsv(frames);
  };
  EXPECT_THROW(format({{1.0, {{1, 2.0, 0.0}}}, {1.0, {{2, 2.0, 0.0}}}}), ContractError);
  EXPECT_THROW(format({{1.0, {{1, 2.0, 0.0}, {1, 3.0, 0.0}}}}), ContractError);
  EXPECT_THROW(format({{1.0, {{1, 2.0, 0.0}, {-1, 3.0, 0.0}}}}), ContractError);
  EXPECT_THROW(format({{1.0, {{1, 0.0, 0.0}}}}), ContractError);
  EXPECT_THROW(format({{1.0, {{1, 2.0, 4.0}}}}), ContractError);
  EXPECT_THROW(format({{kNaN, {{1, 2.0, 0.0}}}}), ContractError);
  EXPECT_THROW(format({{1.0, {}}, {1.0, {}}}), ContractError);
}

TEST(ObservationsCsv, FilesRoundTripPlainAndGzipped) {
  const testing::TempDir dir;
  const std::vector<ObservationFrame> frames = {{0.5, {{0, 1.5, 0.25}, {9, 2.5, -0.25}}},
                                                {0.75, {{9, 2.25, -0.5}}}};
  for (const std::string name : {"obs.csv", "obs.csv.gz"}) {
    WriteObservationsCsv(frames, dir / name);
    const auto read = ReadObservationsCsv(dir / name);
    ASSERT_TRUE(read.ok()) << read.error();
    EXPECT_TRUE(SameFrames(read.value(), frames)) << name;
  }
  EXPECT_FALSE(testing::HasTemporaryFile(dir.path()));
  const auto missing = ReadObservationsCsv(dir / "missing.csv");
  ASSERT_FALSE(missing.ok());
  EXPECT_THAT(missing.error(), HasSubstr("missing.csv"));
}

// ---- odometry ----

TEST(OdometryCsv, BicycleControlsAreHeldUntilTheNextRow) {
  const Odometry odometry = ParseOdometry(
      "# speed m/s, steer rad\n"
      "time,speed,steer\n"
      "10.0,14,0.0\n"
      "10.25,14,0.125\n"
      "10.5,13.5,-0.125\n");
  EXPECT_EQ(odometry.start_time, 10.0);
  ASSERT_EQ(odometry.steps.size(), 2U);
  EXPECT_EQ(odometry.steps[0].time, 10.25);
  EXPECT_EQ(odometry.steps[0].dt, 0.25);
  const auto& c0 = std::get<BicycleControl>(odometry.steps[0].motion);
  EXPECT_EQ(c0.speed, 14.0);
  EXPECT_EQ(c0.steer, 0.0);
  EXPECT_EQ(odometry.steps[1].time, 10.5);
  EXPECT_EQ(odometry.steps[1].dt, 0.25);
  EXPECT_EQ(std::get<BicycleControl>(odometry.steps[1].motion).steer, 0.125);
  // The last row's controls end nothing.
  EXPECT_TRUE(std::isnan(odometry.steps[1].increment_std.x()));
}

TEST(OdometryCsv, IncrementsEndAtTheirRowsTime) {
  const Odometry odometry = ParseOdometry(
      "time, dtheta, dx, dy, sx, stheta\n"
      "0, 0, 0, 0, , \n"
      "0.5, 0.01, 1.0, 0.05, 0.1, \n"
      "1.5, -0.02, 2.0, -0.05, , 0.001\n");
  EXPECT_EQ(odometry.start_time, 0.0);
  ASSERT_EQ(odometry.steps.size(), 2U);
  const MotionStep& s0 = odometry.steps[0];
  EXPECT_EQ(s0.time, 0.5);
  EXPECT_EQ(s0.dt, 0.5);
  const Se2& i0 = std::get<Se2>(s0.motion);
  EXPECT_EQ(i0.x(), 1.0);
  EXPECT_EQ(i0.y(), 0.05);
  EXPECT_EQ(i0.theta(), 0.01);
  EXPECT_EQ(s0.increment_std.x(), 0.1);
  EXPECT_TRUE(std::isnan(s0.increment_std.y()));  // no sy column
  EXPECT_TRUE(std::isnan(s0.increment_std.z()));  // empty cell
  const MotionStep& s1 = odometry.steps[1];
  EXPECT_EQ(s1.dt, 1.0);
  EXPECT_EQ(std::get<Se2>(s1.motion).theta(), -0.02);
  EXPECT_TRUE(std::isnan(s1.increment_std.x()));
  EXPECT_EQ(s1.increment_std.z(), 0.001);
}

TEST(OdometryCsv, BicycleWriterRepeatsTheLastControlsOnTheClosingRow) {
  Odometry odometry;
  odometry.start_time = 0.0;
  odometry.steps.push_back({0.25, 0.25, BicycleControl{14.0, 0.1}});
  odometry.steps.push_back({0.5, 0.25, BicycleControl{13.5, -0.1}});
  const std::string text = FormatOdometryCsv(odometry);
  EXPECT_EQ(text, "time,speed,steer\n0,14,0.1\n0.25,13.5,-0.1\n0.5,13.5,-0.1\n");
  EXPECT_TRUE(SameOdometry(ParseOdometry(text), odometry));
}

TEST(OdometryCsv, IncrementWriterWritesStdColumnsOnlyWhenSomeStepHasOne) {
  Odometry odometry;
  odometry.start_time = 1.0;
  odometry.steps.push_back({2.0, 1.0, Se2(1.0, 0.0, 0.5)});
  EXPECT_EQ(FormatOdometryCsv(odometry), "time,dx,dy,dtheta\n1,0,0,0\n2,1,0,0.5\n");
  odometry.steps.push_back({3.0, 1.0, Se2(0.5, -0.25, -0.5), Vec3(0.1, kNaN, 0.01)});
  const std::string text = FormatOdometryCsv(odometry);
  EXPECT_EQ(
      text,
      "time,dx,dy,dtheta,sx,sy,stheta\n1,0,0,0,,,\n2,1,0,0.5,,,\n3,0.5,-0.25,-0.5,0.1,,0.01\n");
  EXPECT_TRUE(SameOdometry(ParseOdometry(text), odometry));
}

TEST(OdometryCsv, WriterRejectsWhatCannotBeReadBack) {
  Odometry empty;
  EXPECT_THROW((void)FormatOdometryCsv(empty), ContractError);
  Odometry mixed;
  mixed.steps.push_back({1.0, 1.0, BicycleControl{1.0, 0.0}});
  mixed.steps.push_back({2.0, 1.0, Se2(1.0, 0.0, 0.0)});
  EXPECT_THROW((void)FormatOdometryCsv(mixed), ContractError);
  Odometry gap;
  gap.steps.push_back({1.0, 1.0, BicycleControl{1.0, 0.0}});
  gap.steps.push_back({3.0, 1.0, BicycleControl{1.0, 0.0}});  // starts at 2, not 1
  EXPECT_THROW((void)FormatOdometryCsv(gap), ContractError);
  Odometry negative_std;
  negative_std.steps.push_back({1.0, 1.0, Se2(1.0, 0.0, 0.0), Vec3(-1.0, kNaN, kNaN)});
  EXPECT_THROW((void)FormatOdometryCsv(negative_std), ContractError);
}

TEST(OdometryCsv, FilesRoundTripPlainAndGzipped) {
  const testing::TempDir dir;
  Odometry odometry;
  odometry.start_time = 0.1;
  odometry.steps.push_back({0.35, 0.35 - 0.1, BicycleControl{14.0, 0.01}});
  for (const std::string name : {"odom.csv", "odom.csv.gz"}) {
    WriteOdometryCsv(odometry, dir / name);
    const auto read = ReadOdometryCsv(dir / name);
    ASSERT_TRUE(read.ok()) << read.error();
    EXPECT_TRUE(SameOdometry(read.value(), odometry)) << name;
  }
}

// ---- prior map GeoJSON ----

constexpr const char* kCity = R"({
  "type": "FeatureCollection",
  "std": 2.0,
  "features": [
    {"type": "Feature", "properties": {"name": "library", "std": 0.5},
     "geometry": {"type": "Polygon", "coordinates": [
       [[0, 0], [10, 0], [10, 5], [0, 5], [0, 0]],
       [[4, 2], [4, 3], [6, 3], [4, 2]]]}},
    {"type": "Feature", "properties": null, "id": "fence-7",
     "geometry": {"type": "LineString", "coordinates": [[20, 0], [20, 10, 3.5]]}},
    {"type": "Feature", "properties": {"id": 42},
     "geometry": {"type": "MultiLineString", "coordinates": [[[30, 0], [31, 0]], [[30, 1], [31, 1], [31, 2]]]}},
    {"type": "Feature", "properties": {"kind": "block", "name": null},
     "geometry": {"type": "MultiPolygon", "coordinates": [
       [[[50, 0], [52, 0], [52, 2], [50, 0]]],
       [[[60, 0], [62, 0], [62, 2], [60, 0]]]]}}
  ]
})";

TEST(PriorMapGeoJson, ReadsEverySupportedGeometry) {
  const PriorMap map = ParseMap(kCity, 1.0);
  EXPECT_THAT(map.buildings, ElementsAre("library", "fence-7", "42", "feature 3"));
  ASSERT_EQ(map.segments.size(), 4U + 3U + 1U + 3U + 6U);
  // The outline, closing point repeated, gives 4 walls; the courtyard 3 more.
  EXPECT_TRUE(Same(map.segments[0].a, Vec2(0, 0)));
  EXPECT_TRUE(Same(map.segments[0].b, Vec2(10, 0)));
  EXPECT_TRUE(Same(map.segments[3].b, Vec2(0, 0)));
  EXPECT_TRUE(Same(map.segments[4].a, Vec2(4, 2)));
  for (int i = 0; i < 7; ++i) {
    EXPECT_EQ(map.segments[i].building, 0);
    EXPECT_EQ(map.segments[i].std, 0.5);  // the feature's std
  }
  // The collection's std where a feature has none; the altitude is ignored.
  EXPECT_EQ(map.segments[7].building, 1);
  EXPECT_EQ(map.segments[7].std, 2.0);
  EXPECT_TRUE(Same(map.segments[7].b, Vec2(20, 10)));
  EXPECT_EQ(map.segments[8].building, 2);
  EXPECT_TRUE(Same(map.segments[9].a, Vec2(30, 1)));
  EXPECT_TRUE(Same(map.segments[10].b, Vec2(31, 2)));
  EXPECT_EQ(map.segments[11].building, 3);
  EXPECT_TRUE(Same(map.segments[14].a, Vec2(60, 0)));
}

TEST(PriorMapGeoJson, DefaultStdAppliesWhenNeitherFeatureNorCollectionHasOne) {
  const PriorMap map = ParseMap(
      R"({"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {},
          "geometry": {"type": "LineString", "coordinates": [[0, 0], [1, 0]]}}]})",
      0.75);
  ASSERT_EQ(map.segments.size(), 1U);
  EXPECT_EQ(map.segments[0].std, 0.75);
  EXPECT_THAT(map.buildings, ElementsAre("feature 0"));
}

TEST(PriorMapGeoJson, SegmentStdGivesEachSegmentItsOwn) {
  const PriorMap map = ParseMap(
      R"({"type": "FeatureCollection", "features": [{"type": "Feature",
          "properties": {"std": 9, "segment_std": [0.5, 1.5]},
          "geometry": {"type": "LineString", "coordinates": [[0, 0], [1, 0], [1, 1]]}}]})");
  ASSERT_EQ(map.segments.size(), 2U);
  EXPECT_EQ(map.segments[0].std, 0.5);
  EXPECT_EQ(map.segments[1].std, 1.5);
}

TEST(PriorMapGeoJson, LongitudeLatitudeIsReadAsIsNotReprojected) {
  // Degrees look like a tiny map in metres: no error and no guess (docs/formats.md).
  const PriorMap map = ParseMap(
      R"({"type": "FeatureCollection", "features": [{"type": "Feature", "properties": null,
          "geometry": {"type": "LineString", "coordinates": [[-0.1340, 51.5246], [-0.1335, 51.5247]]}}]})");
  ASSERT_EQ(map.segments.size(), 1U);
  EXPECT_EQ(map.segments[0].a.x(), -0.1340);
  EXPECT_EQ(map.segments[0].b.y(), 51.5247);
}

TEST(PriorMapGeoJson, WriterJoinsConnectedWallsIntoLines) {
  PriorMap map;
  map.buildings = {"a \"quoted\" name", "shed"};
  map.segments = {{Vec2(0, 0), Vec2(1, 0), 0.5, 0},
                  {Vec2(1, 0), Vec2(1, 1), 0.5, 0},
                  {Vec2(5, 5), Vec2(6, 5), 0.25, 1},
                  {Vec2(6, 5.5), Vec2(6, 6), 0.125, 1}};
  const std::string text = FormatPriorMapGeoJson(map);
  EXPECT_EQ(
      text,
      "{\"type\": \"FeatureCollection\", \"features\": [\n"
      R"({"type":"Feature","properties":{"name":"a \"quoted\" name","std":0.5},)"
      R"("geometry":{"type":"MultiLineString","coordinates":[[[0.0,0.0],[1.0,0.0],[1.0,1.0]]]}},)"
      "\n"
      R"({"type":"Feature","properties":{"name":"shed","segment_std":[0.25,0.125]},)"
      R"("geometry":{"type":"MultiLineString","coordinates":[[[5.0,5.0],[6.0,5.0]],[[6.0,5.5],[6.0,6.0]]]}})"
      "\n]}\n");
  EXPECT_TRUE(SameMap(ParseMap(text), map));
}

TEST(PriorMapGeoJson, WriterGroupsSegmentsByBuilding) {
  PriorMap map;
  map.buildings = {"a", "b", "empty"};
  map.segments = {{Vec2(0, 0), Vec2(1, 0), 1.0, 1},
                  {Vec2(2, 0), Vec2(3, 0), 1.0, 0},
                  {Vec2(1, 0), Vec2(1, 1), 1.0, 1}};
  const PriorMap read = ParseMap(FormatPriorMapGeoJson(map));
  EXPECT_THAT(read.buildings, ElementsAre("a", "b", "empty"));
  ASSERT_EQ(read.segments.size(), 3U);
  EXPECT_EQ(read.segments[0].building, 0);
  EXPECT_TRUE(Same(read.segments[0].a, Vec2(2, 0)));
  EXPECT_EQ(read.segments[1].building, 1);
  EXPECT_EQ(read.segments[2].building, 1);
}

TEST(PriorMapGeoJson, WriterRejectsWhatCannotBeReadBack) {
  EXPECT_THROW((void)FormatPriorMapGeoJson(PriorMap{}), ContractError);
  PriorMap map;
  map.buildings = {"a"};
  map.segments = {{Vec2(0, 0), Vec2(1, 0), 1.0, -1}};
  EXPECT_THROW((void)FormatPriorMapGeoJson(map), ContractError);
  map.segments = {{Vec2(0, 0), Vec2(0, 0), 1.0, 0}};
  EXPECT_THROW((void)FormatPriorMapGeoJson(map), ContractError);
  map.segments = {{Vec2(0, 0), Vec2(1, 0), 0.0, 0}};
  EXPECT_THROW((void)FormatPriorMapGeoJson(map), ContractError);
  map.segments = {{Vec2(0, 0), Vec2(1, 0), 2e9, 0}};  // beyond kMaxPriorStd
  EXPECT_THROW((void)FormatPriorMapGeoJson(map), ContractError);
  map.segments = {{Vec2(0, 0), Vec2(1, 0), kMaxPriorStd, 0}};
  EXPECT_NO_THROW((void)FormatPriorMapGeoJson(map));
}

TEST(PriorMapGeoJson, FilesRoundTripPlainAndGzipped) {
  const testing::TempDir dir;
  const PriorMap map = ParseMap(kCity);
  for (const std::string name : {"map.geojson", "map.geojson.gz"}) {
    WritePriorMapGeoJson(map, dir / name);
    const auto read = ReadPriorMapGeoJson(dir / name, 3.0);
    ASSERT_TRUE(read.ok()) << read.error();
    EXPECT_TRUE(SameMap(read.value(), map)) << name;
  }
}

// ---- properties: write -> read is the identity ----

// Finite doubles of every kind: special values, short decimals, and arbitrary bit patterns.
// A prior map's coordinates: metres in a local frame, at most 1e9 in magnitude (the reader's
// bound), its extremes and subnormals included.
rc::Gen<double> Coordinate() {
  return rc::gen::oneOf(
      rc::gen::element(0.0, -0.0, 0.1, 1.0 / 3.0, 5e-324, 1e-300, 1e9, -1e9, -2.5),
      rc::gen::map(rc::gen::arbitrary<int>(), [](int v) { return v / 1000.0; }));
}

rc::Gen<double> FiniteNumber() {
  return rc::gen::suchThat(
      rc::gen::oneOf(rc::gen::element(0.0, -0.0, 0.1, 1.0 / 3.0, 5e-324, 1e-300, 1e300, -2.5),
                     rc::gen::map(rc::gen::arbitrary<int>(), [](int v) { return v / 1000.0; }),
                     rc::gen::arbitrary<double>()),
      [](double v) { return std::isfinite(v); });
}

rc::Gen<double> Positive() {
  return rc::gen::map(rc::gen::suchThat(FiniteNumber(), [](double v) { return v != 0.0; }),
                      [](double v) { return std::abs(v); });
}

// Distances a file can hold: ranges and increments are bounded as world coordinates (1e9 m).
rc::Gen<double> WithinWorld(const rc::Gen<double>& numbers) {
  return rc::gen::suchThat(numbers, [](double v) { return std::abs(v) <= 1e9; });
}

rc::Gen<double> Angle() {
  return rc::gen::oneOf(
      rc::gen::element(-kPi, kPi, -0.0, 0.0, 5e-324),
      rc::gen::suchThat(FiniteNumber(), [](double v) { return std::abs(v) <= kPi; }),
      rc::gen::map(rc::gen::inRange(-3141592, 3141593), [](int v) { return v * 1e-6; }));
}

// `n` strictly increasing finite times whose differences are finite.
std::vector<double> IncreasingTimes(std::size_t n) {
  std::vector<double> times;
  double t = *rc::gen::suchThat(FiniteNumber(), [](double v) { return std::abs(v) < 1e300; });
  for (std::size_t i = 0; i < n; ++i) {
    times.push_back(t);
    const double step = *rc::gen::suchThat(Positive(), [](double v) { return v < 1e300; });
    const double next = t + step;
    t = next > t ? next : std::nextafter(t, 1e308);
  }
  return times;
}

RC_GTEST_PROP(ObservationsCsv, WriteThenReadIsTheIdentity, ()) {
  const std::size_t n = *rc::gen::inRange<std::size_t>(0, 8);
  const bool known = *rc::gen::arbitrary<bool>();
  std::vector<ObservationFrame> frames;
  for (double time : IncreasingTimes(n)) {
    ObservationFrame& frame = frames.emplace_back();
    frame.time = time;
    const std::size_t m = *rc::gen::inRange<std::size_t>(0, 5);
    const auto ids = *rc::gen::unique<std::vector<int>>(
        m, rc::gen::oneOf(rc::gen::inRange(0, 20), rc::gen::element(2147483647)));
    for (std::size_t i = 0; i < m; ++i)
      frame.observations.push_back({known ? ids[i] : -1, *WithinWorld(Positive()), *Angle()});
  }
  const std::string text = FormatObservationsCsv(frames);
  RC_LOG() << text;
  const auto read = ParseObservationsCsv(text, "written.csv");
  if (!read.ok()) RC_FAIL(read.error());
  const ::testing::AssertionResult same = SameFrames(read.value(), frames);
  if (!same) RC_FAIL(same.message());
  RC_ASSERT(FormatObservationsCsv(read.value()) == text);
}

RC_GTEST_PROP(OdometryCsv, WriteThenReadIsTheIdentity, ()) {
  const std::size_t n = *rc::gen::inRange<std::size_t>(1, 8);
  const bool bicycle = *rc::gen::arbitrary<bool>();
  const bool with_std = *rc::gen::arbitrary<bool>();
  const std::vector<double> times = IncreasingTimes(n + 1);
  Odometry odometry;
  odometry.start_time = times[0];
  for (std::size_t k = 0; k < n; ++k) {
    MotionStep step;
    step.time = times[k + 1];
    step.dt = times[k + 1] - times[k];
    if (bicycle) {
      // Within the reader's bounds: |speed| <= 1e9 m/s and 1e9 m per step, steer in [-pi, pi].
      double speed = *WithinWorld(FiniteNumber());
      if (!(std::abs(speed) * step.dt <= 1e9)) speed = 0.0;
      step.motion = BicycleControl{speed, *Angle()};
    } else {
      step.motion = Se2(*WithinWorld(FiniteNumber()), *WithinWorld(FiniteNumber()), *Angle());
      if (with_std) {
        for (int i = 0; i < 3; ++i) {
          step.increment_std[i] =
              *rc::gen::oneOf(rc::gen::just(kNaN), rc::gen::just(0.0), Positive());
        }
      }
    }
    odometry.steps.push_back(step);
  }
  const std::string text = FormatOdometryCsv(odometry);
  RC_LOG() << text;
  const auto read = ParseOdometryCsv(text, "written.csv");
  if (!read.ok()) RC_FAIL(read.error());
  const ::testing::AssertionResult same = SameOdometry(read.value(), odometry);
  if (!same) RC_FAIL(same.message());
  RC_ASSERT(FormatOdometryCsv(read.value()) == text);
}

RC_GTEST_PROP(PriorMapGeoJson, WriteThenReadIsTheIdentity, ()) {
  PriorMap map;
  const int buildings = *rc::gen::inRange(1, 5);
  const auto name = rc::gen::oneOf(
      rc::gen::element<std::string>("", "library", "\"quoted\" \\ name\n", "Zürich Hbf", "42"),
      rc::gen::container<std::string>(rc::gen::inRange<char>(' ', '~')));
  for (int b = 0; b < buildings; ++b) {
    map.buildings.push_back(*name);
    const double std_value = *WithinWorld(Positive());  // IsValidPriorStd
    const bool one_std = *rc::gen::arbitrary<bool>();
    const std::size_t m = *rc::gen::inRange<std::size_t>(b == 0 ? 1 : 0, 6);
    Vec2 previous(*Coordinate(), *Coordinate());
    for (std::size_t i = 0; i < m; ++i) {
      // Connected to the previous wall or not, as walls of a footprint and of clutter are.
      const Vec2 a = *rc::gen::arbitrary<bool>() ? previous : Vec2(*Coordinate(), *Coordinate());
      const Vec2 b_end = *rc::gen::suchThat(
          rc::gen::map(rc::gen::tuple(Coordinate(), Coordinate()),
                       [](const auto& xy) { return Vec2(std::get<0>(xy), std::get<1>(xy)); }),
          [&](const Vec2& p) { return p != a; });
      map.segments.push_back({a, b_end, one_std ? std_value : *WithinWorld(Positive()), b});
      previous = b_end;
    }
  }
  const std::string text = FormatPriorMapGeoJson(map);
  RC_LOG() << text;
  const auto read = ParsePriorMapGeoJson(text, "written.geojson", 1.0);
  if (!read.ok()) RC_FAIL(read.error());
  const ::testing::AssertionResult same = SameMap(read.value(), map);
  if (!same) RC_FAIL(same.message());
  RC_ASSERT(FormatPriorMapGeoJson(read.value()) == text);
}

// docs/formats.md's prior map, as examples/formats/prior-map.geojson: a building of 4 + 3 walls
// (outline and courtyard) and a fence.
TEST(SlamIo, ReadsThePriorMapExample) {
  const Result<PriorMap> map =
      ReadPriorMapGeoJson(PRIORMAP_EXAMPLES_DIR "/formats/prior-map.geojson", 1.0);
  ASSERT_TRUE(map.ok()) << map.error();
  EXPECT_EQ(map.value().segments.size(), 8u);
  EXPECT_EQ(map.value().buildings.size(), 2u);
}

}  // namespace
}  // namespace priormap::slam
