// Bad files of `priormap slam run`: each problem is one Diagnostic at the line and column of the
// offending cell or value, saying what was expected; nothing throws, nothing crashes.
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <priormap/core/file_io.hpp>
#include <priormap/slam/slam_io.hpp>

#include "testing/diagnostic_matchers.hpp"

namespace priormap::slam {
namespace {

using ::testing::ElementsAre;
using ::testing::Matcher;

Matcher<const Diagnostic&> At(const std::string& file, int line, int col,
                              const std::string& message_part) {
  return testing::DiagnosticAt(file, line, col, message_part);
}

std::vector<Diagnostic> ObservationErrors(const std::string& text) {
  const auto result = ParseObservationsCsv(text, "obs.csv");
  EXPECT_FALSE(result.ok()) << "parsed without error:\n" << text;
  return result.diagnostics();
}

std::vector<Diagnostic> OdometryErrors(const std::string& text) {
  const auto result = ParseOdometryCsv(text, "odom.csv");
  EXPECT_FALSE(result.ok()) << "parsed without error:\n" << text;
  return result.diagnostics();
}

std::vector<Diagnostic> MapErrors(const std::string& text) {
  const auto result = ParsePriorMapGeoJson(text, "map.geojson", 1.0);
  EXPECT_FALSE(result.ok()) << "parsed without error:\n" << text;
  return result.diagnostics();
}

// A valid observations file whose line 3 (time 1, id 2) is replaced by `row`.
std::string Observations(const std::string& row) {
  return "time,id,range,bearing\n0,1,5,0.5\n" + row + "\n2,1,4,0.25\n";
}

// ---- the CSV structure (shared by both CSV formats) ----

TEST(CsvMalformed, AFileWithoutAHeaderRow) {
  EXPECT_THAT(ObservationErrors(""), ElementsAre(At("obs.csv", 1, 1, "no header row")));
  EXPECT_THAT(OdometryErrors("# only a comment\n\n"),
              ElementsAre(At("odom.csv", 3, 1,
                             "no header row (the first line that is neither blank nor a '#' "
                             "comment names the columns)")));
}

TEST(CsvMalformed, EmptyOrRepeatedColumnNames) {
  EXPECT_THAT(ObservationErrors("time,,range,bearing\n"),
              ElementsAre(At("obs.csv", 1, 6, "empty column name in the header")));
  EXPECT_THAT(ObservationErrors("time, id, time\n"),
              ElementsAre(At("obs.csv", 1, 11,
                             "column 'time' appears twice in the header (also at column 1)")));
}

TEST(CsvMalformed, RowsWithAnotherNumberOfCellsThanTheHeader) {
  EXPECT_THAT(ObservationErrors(Observations("1,2,3,0,5")),
              ElementsAre(At("obs.csv", 3, 9,
                             "expected 4 cells as in the header (time,id,range,bearing), "
                             "found 5")));
  EXPECT_THAT(ObservationErrors(Observations("1,2,3")),
              ElementsAre(At("obs.csv", 3, 6, "expected 4 cells as in the header")));
  EXPECT_THAT(ObservationErrors(Observations("1,2,3,0,")),
              ElementsAre(At("obs.csv", 3, 9, "found 5")));
}

TEST(CsvMalformed, BrokenQuotes) {
  EXPECT_THAT(ObservationErrors(Observations("1,\"2,3,0")),
              ElementsAre(At("obs.csv", 3, 3, "unterminated quoted cell")));
  EXPECT_THAT(ObservationErrors(Observations("1,\"2\" x,3,0")),
              ElementsAre(At("obs.csv", 3, 7,
                             "expected ',' or the end of the line after a quoted cell, "
                             "found 'x'")));
}

// Editors count characters, not bytes: the two-byte 'ü' takes one column, and a byte order mark
// takes none.
TEST(CsvMalformed, ColumnsCountCharactersAsEditorsShowThem) {
  EXPECT_THAT(ObservationErrors(Observations("1,2,\"Z\u00fcrich\",0,x")),
              ElementsAre(At("obs.csv", 3, 16, "found 5")));
  EXPECT_THAT(ObservationErrors(Observations("1,2,\"\u00fc\"x,0")),
              ElementsAre(At("obs.csv", 3, 8, "found 'x'")));
  // What follows the quote is quoted whole, as the user typed it.
  EXPECT_THAT(ObservationErrors(Observations("1,2,\"a\"\u00fc,0")),
              ElementsAre(At("obs.csv", 3, 8, "found '\u00fc'")));
  EXPECT_THAT(ObservationErrors("\xef\xbb\xbf\"\u00e9t\u00e9\",,range,bearing\n"),
              ElementsAre(At("obs.csv", 1, 7, "empty column name in the header")));
}

// A file with no line breaks is one long line: its cells' columns and the header's names are
// found in one walk along it (a column counted from the line's start for each cell, or each name
// compared with every one before it, would take hours here).
TEST(CsvMalformed, ALongLineIsCheckedInOneWalk) {
  constexpr int kNames = 400000;
  std::string header;
  int col = 1;  // of the next name
  for (int i = 0; i < kNames; ++i) {
    const std::string name = "\u00fc" + std::to_string(i);  // 'ü' counts one column, not two
    header += name + ",";
    col += 1 + static_cast<int>(std::to_string(i).size()) + 1;
  }
  EXPECT_THAT(ObservationErrors(header + "\u00fc7\n"),
              ElementsAre(At("obs.csv", 1, col,
                             "column '\u00fc7' appears twice in the header (also at column 22)")));

  std::string row = "\u00fc,2,3,0";
  for (int i = 0; i < kNames; ++i) row += ",x";
  EXPECT_THAT(ObservationErrors(Observations(row)),
              ElementsAre(At("obs.csv", 3, 9, "expected 4 cells as in the header")));
  std::string quoted = "1,2,3";
  for (int i = 0; i < kNames; ++i) quoted += ",\"\u00fc\"";
  EXPECT_THAT(ObservationErrors(Observations(quoted + ",\"\u00fc\"x")),
              ElementsAre(At("obs.csv", 3, 6 + 4 * kNames + 4, "found 'x'")));
}

TEST(CsvMalformed, CellsThatAreNotFiniteNumbers) {
  EXPECT_THAT(
      ObservationErrors(Observations("1,2,abc,0")),
      ElementsAre(At("obs.csv", 3, 5, "expected a finite number for column 'range', found 'abc'")));
  EXPECT_THAT(ObservationErrors(Observations("1,2, ,0")),
              ElementsAre(At("obs.csv", 3, 6,
                             "expected a finite number for column 'range', found an empty "
                             "cell")));
  EXPECT_THAT(ObservationErrors(Observations("1,2,3,0.5rad")),
              ElementsAre(At("obs.csv", 3, 7, "column 'bearing', found '0.5rad'")));
  EXPECT_THAT(ObservationErrors(Observations("x\x01,2,3,0")),
              ElementsAre(At("obs.csv", 3, 1, "column 'time', found 'x\\x01'")));
}

TEST(CsvMalformed, NanAndInfinitiesAreRejectedByName) {
  EXPECT_THAT(ObservationErrors(Observations("1,2,nan,0")),
              ElementsAre(At("obs.csv", 3, 5,
                             "expected a finite number for column 'range', found 'nan' (NaN is "
                             "not allowed)")));
  EXPECT_THAT(ObservationErrors(Observations("1,2,3,-NaN")),
              ElementsAre(At("obs.csv", 3, 7, "found '-NaN' (NaN is not allowed)")));
  EXPECT_THAT(ObservationErrors(Observations("inf,2,3,0")),
              ElementsAre(At("obs.csv", 3, 1,
                             "column 'time', found 'inf' (infinite values are not allowed)")));
  EXPECT_THAT(ObservationErrors(Observations("1,2,-Infinity,0")),
              ElementsAre(At("obs.csv", 3, 5, "found '-Infinity' (infinite values")));
  EXPECT_THAT(ObservationErrors(Observations("1,2,1e400,0")),
              ElementsAre(At("obs.csv", 3, 5, "found '1e400' (out of the range of double)")));
}

// ---- observations ----

TEST(ObservationsMalformed, UnknownOrMissingColumns) {
  EXPECT_THAT(ObservationErrors("time,id,range,bearing,intensity\n"),
              ElementsAre(At("obs.csv", 1, 23,
                             "unknown column 'intensity'; observations have the columns "
                             "time,id,range,bearing (id optional)")));
  EXPECT_THAT(
      ObservationErrors("# header next\ntime,id,range\n"),
      ElementsAre(At("obs.csv", 2, 1, "missing column 'bearing' in the header 'time,id,range'")));
}

TEST(ObservationsMalformed, RangeMustBePositive) {
  EXPECT_THAT(ObservationErrors(Observations("1,2,0,0")),
              ElementsAre(At("obs.csv", 3, 5, "range must be > 0 m, found '0'")));
  EXPECT_THAT(ObservationErrors(Observations("1,2,-0.5,0")),
              ElementsAre(At("obs.csv", 3, 5, "range must be > 0 m, found '-0.5'")));
}

TEST(ObservationsMalformed, RangeMustBeWithinTheWorld) {
  EXPECT_THAT(ObservationErrors(Observations("1,2,1e300,0")),
              ElementsAre(At("obs.csv", 3, 5,
                             "range must be at most 1e+09 m (the bound of world coordinates), "
                             "found '1e300'")));
  EXPECT_TRUE(ParseObservationsCsv(Observations("1,2,1e9,0"), "obs.csv").ok());
}

TEST(ObservationsMalformed, BearingMustBeWithinPlusMinusPi) {
  EXPECT_THAT(ObservationErrors(Observations("1,2,3,3.1416")),
              ElementsAre(At("obs.csv", 3, 7,
                             "bearing must be in [-pi, pi] rad, found '3.1416' (degrees?)")));
  EXPECT_THAT(ObservationErrors(Observations("1,2,3,-90")),
              ElementsAre(At("obs.csv", 3, 7, "found '-90'")));
}

TEST(ObservationsMalformed, TimeGoingBackwardsIsLocatedAtItsCell) {
  EXPECT_THAT(ObservationErrors(Observations("-1,2,3,0")),
              ElementsAre(At("obs.csv", 3, 1,
                             "time goes backwards: -1 is before 0 (line 2); rows must be in "
                             "time order")));
  EXPECT_THAT(ObservationErrors("time,id,range,bearing\n0,1,5,0\n1,1,5,0\n0.5,2,5,0\n"),
              ElementsAre(At("obs.csv", 4, 1, "0.5 is before 1 (line 3)")));
}

TEST(ObservationsMalformed, DuplicateIdInOneFrameNamesBothLines) {
  EXPECT_THAT(ObservationErrors("time,id,range,bearing\n"
                                "0.5,7,5,0\n"
                                "0.5,3,5,0\n"
                                "# comment\n"
                                "0.5,7,6,0.1\n"),
              ElementsAre(At("obs.csv", 5, 5,
                             "landmark id 7 appears twice in the frame at time 0.5 (lines 2 "
                             "and 5)")));
  // In another frame, the same id is fine.
  EXPECT_TRUE(ParseObservationsCsv("time,id,range,bearing\n0,7,5,0\n1,7,5,0\n", "ok.csv").ok());
}

TEST(ObservationsMalformed, KnownAndUnknownIdsMixedNameTheFirstRowOfTheOtherKind) {
  EXPECT_THAT(ObservationErrors(Observations("1,,3,0")),
              ElementsAre(At("obs.csv", 3, 3,
                             "the landmark id is unknown (''), but line 2 has a known id; the "
                             "ids of a file must be all known or all unknown (-1 or empty)")));
  EXPECT_THAT(
      ObservationErrors("time,id,range,bearing\n0,-1,5,0\n0,,5,0\n1,4,5,0\n"),
      ElementsAre(At("obs.csv", 4, 3, "landmark id 4 is known, but line 2 has an unknown id")));
}

TEST(ObservationsMalformed, AFrameWithoutObservationsHasNoId) {
  EXPECT_THAT(ObservationErrors(Observations("1,2,,")),
              ElementsAre(At("obs.csv", 3, 3,
                             "a row without range and bearing stands for a frame without "
                             "observations and has no landmark id, found '2'")));
  // Only range or only bearing missing is a missing number.
  EXPECT_THAT(ObservationErrors(Observations("1,2,,0")),
              ElementsAre(At("obs.csv", 3, 5, "column 'range', found an empty cell")));
}

TEST(ObservationsMalformed, IdsMustBeIntegersInRange) {
  const std::string expected =
      "expected a landmark id for column 'id' (an integer in [0, 2147483647], or -1 or an empty "
      "cell for an unknown landmark), found ";
  EXPECT_THAT(ObservationErrors(Observations("1,2.5,3,0")),
              ElementsAre(At("obs.csv", 3, 3, expected + "'2.5'")));
  EXPECT_THAT(ObservationErrors(Observations("1,-2,3,0")),
              ElementsAre(At("obs.csv", 3, 3, expected + "'-2'")));
  EXPECT_THAT(ObservationErrors(Observations("1,2147483648,3,0")),
              ElementsAre(At("obs.csv", 3, 3, expected + "'2147483648'")));
  EXPECT_THAT(ObservationErrors(Observations("1,99999999999999999999999,3,0")),
              ElementsAre(At("obs.csv", 3, 3, expected)));
  EXPECT_THAT(ObservationErrors(Observations("1,beacon,3,0")),
              ElementsAre(At("obs.csv", 3, 3, expected + "'beacon'")));
  EXPECT_THAT(ObservationErrors(Observations("1,nan,3,0")),
              ElementsAre(At("obs.csv", 3, 3, expected + "'nan'")));
}

TEST(ObservationsMalformed, MissingFileIsADiagnostic) {
  const auto result = ReadObservationsCsv("/nonexistent/obs.csv");
  ASSERT_FALSE(result.ok());
  EXPECT_THAT(result.diagnostics(),
              ElementsAre(::testing::Field(&Diagnostic::file, "/nonexistent/obs.csv")));
}

// ---- odometry ----

TEST(OdometryMalformed, UnknownColumnsListTheExpectedOnes) {
  EXPECT_THAT(OdometryErrors("time,v,steer\n0,1,0\n1,1,0\n"),
              ElementsAre(At("odom.csv", 1, 6,
                             "unknown column 'v'; odometry has the columns time,speed,steer "
                             "(bicycle controls) or time,dx,dy,dtheta[,sx,sy,stheta] "
                             "(increments)")));
}

TEST(OdometryMalformed, KindsOfColumnsCannotBeMixed) {
  EXPECT_THAT(OdometryErrors("time,speed,steer,dx\n"),
              ElementsAre(At("odom.csv", 1, 18, "column 'dx' cannot be mixed with 'speed'")));
  EXPECT_THAT(OdometryErrors("time,sx,speed\n"),
              ElementsAre(At("odom.csv", 1, 9, "column 'speed' cannot be mixed with 'sx'")));
  EXPECT_THAT(OdometryErrors("time\n0\n1\n"),
              ElementsAre(At("odom.csv", 1, 1,
                             "the header 'time' names neither bicycle controls nor increments")));
}

TEST(OdometryMalformed, MissingColumnsNameTheKind) {
  EXPECT_THAT(OdometryErrors("time,speed\n"),
              ElementsAre(At("odom.csv", 1, 1,
                             "missing column 'steer' in the header 'time,speed'; bicycle "
                             "controls need the columns time,speed,steer")));
  EXPECT_THAT(OdometryErrors("dx,dy,dtheta,sx\n"),
              ElementsAre(At("odom.csv", 1, 1,
                             "missing column 'time' in the header 'dx,dy,dtheta,sx'; increments "
                             "need the columns time,dx,dy,dtheta")));
  EXPECT_THAT(OdometryErrors("time,dx,dtheta\n"),
              ElementsAre(At("odom.csv", 1, 1, "missing column 'dy'")));
}

TEST(OdometryMalformed, CellsMustBeFiniteNumbers) {
  EXPECT_THAT(OdometryErrors("time,speed,steer\n0,fast,0\n1,1,0\n"),
              ElementsAre(At("odom.csv", 2, 3,
                             "expected a finite number for column 'speed', found 'fast'")));
  EXPECT_THAT(OdometryErrors("time,speed,steer\n0,1,0\n1,1,\n"),
              ElementsAre(At("odom.csv", 3, 5, "column 'steer', found an empty cell")));
  EXPECT_THAT(OdometryErrors("time,dx,dy,dtheta\n0,0,0,0\n1,nan,0,0\n"),
              ElementsAre(At("odom.csv", 3, 3, "column 'dx', found 'nan' (NaN is not allowed)")));
  EXPECT_THAT(OdometryErrors("time,dx,dy,dtheta,sx\n0,0,0,0,\n1,1,0,0,inf\n"),
              ElementsAre(At("odom.csv", 3, 9, "column 'sx', found 'inf' (infinite values")));
}

TEST(OdometryMalformed, TimesMustIncreaseStrictly) {
  EXPECT_THAT(OdometryErrors("time,speed,steer\n0,1,0\n0.5,1,0\n0.5,1,0\n"),
              ElementsAre(At("odom.csv", 4, 1,
                             "time must increase strictly: 0.5 is not after 0.5 (line 3)")));
  EXPECT_THAT(OdometryErrors("time,dx,dy,dtheta\n# start\n2,0,0,0\n1,1,0,0\n"),
              ElementsAre(At("odom.csv", 4, 1, "1 is not after 2 (line 3)")));
  EXPECT_THAT(OdometryErrors("time,speed,steer\n-1e308,1,0\n1e308,1,0\n"),
              ElementsAre(At("odom.csv", 3, 1,
                             "the step from time -1e+308 (line 2) to 1e+308 is too long to "
                             "represent")));
}

TEST(OdometryMalformed, TheFirstIncrementMustBeZero) {
  EXPECT_THAT(OdometryErrors("time,dx,dy,dtheta\n0,0,0.5,0\n1,1,0,0\n"),
              ElementsAre(At("odom.csv", 2, 5,
                             "the first row marks the start and its increment must be 0, found "
                             "'0.5'")));
  EXPECT_THAT(OdometryErrors("time,dtheta,dx,dy\n0,0.1,0,0\n1,0,1,0\n"),
              ElementsAre(At("odom.csv", 2, 3, "found '0.1'")));
}

TEST(OdometryMalformed, DthetaMustBeWithinPlusMinusPi) {
  EXPECT_THAT(
      OdometryErrors("time,dx,dy,dtheta\n0,0,0,0\n1,1,0,5\n"),
      ElementsAre(At("odom.csv", 3, 7, "dtheta must be in [-pi, pi] rad, found '5' (degrees?)")));
}

TEST(OdometryMalformed, IncrementsMustBeWithinTheWorld) {
  EXPECT_THAT(OdometryErrors("time,dx,dy,dtheta\n0,0,0,0\n1,0.5,-3e9,0\n"),
              ElementsAre(At("odom.csv", 3, 7,
                             "dy must be at most 1e+09 m in magnitude (the bound of world "
                             "coordinates), found '-3e9'")));
  EXPECT_THAT(OdometryErrors("time,dx,dy,dtheta\n0,0,0,0\n1,1e300,0,0\n"),
              ElementsAre(At("odom.csv", 3, 3, "dx must be at most 1e+09 m")));
}

TEST(OdometryMalformed, StandardDeviationsMustNotBeNegative) {
  EXPECT_THAT(
      OdometryErrors("time,dx,dy,dtheta,sx,sy,stheta\n0,0,0,0,,,\n1,1,0,0,0.1,-0.1,\n"),
      ElementsAre(At("odom.csv", 3, 13, "a standard deviation must be >= 0, found '-0.1'")));
}

TEST(OdometryMalformed, FewerThanTwoRows) {
  EXPECT_THAT(OdometryErrors("time,speed,steer\n"),
              ElementsAre(At("odom.csv", 1, 1,
                             "odometry needs at least two rows (the start and the end of a "
                             "step), found 0")));
  EXPECT_THAT(OdometryErrors("time,dx,dy,dtheta\n\n5,0,0,0\n# end\n"),
              ElementsAre(At("odom.csv", 3, 1, "found 1")));
}

// ---- prior map GeoJSON ----

// One building on line 2, its geometry on line 3:
//   {"type": "Feature", "properties": PROPERTIES,
//    "geometry": GEOMETRY}
std::string Map(const std::string& geometry,
                const std::string& properties = R"({"name": "b", "std": 0.5})",
                const std::string& collection_member = "") {
  return "{\"type\": \"FeatureCollection\", " + collection_member + "\"features\": [\n" +
         R"({"type": "Feature", "properties": )" + properties + ",\n" + R"("geometry": )" +
         geometry + "}\n]}\n";
}

const std::string kLine = R"({"type": "LineString", "coordinates": [[0, 0], [1, 0]]})";

TEST(GeoJsonMalformed, DocumentsUsedBelowAreValidAsGiven) {
  EXPECT_TRUE(ParsePriorMapGeoJson(Map(kLine), "ok.geojson", 1.0).ok());
  EXPECT_TRUE(ParsePriorMapGeoJson(Map(kLine, "null", R"("std": 2, )"), "ok.geojson", 1.0).ok());
}

TEST(GeoJsonMalformed, InvalidJsonIsLocatedAtTheOffendingCharacter) {
  EXPECT_THAT(MapErrors("{\"type\": \"FeatureCollection\",\n \"features\": [}\n"),
              ElementsAre(At("map.geojson", 2, 15, "invalid JSON: syntax error")));
  EXPECT_THAT(MapErrors(""), ElementsAre(At("map.geojson", 1, 1, "unexpected end of input")));
}

TEST(GeoJsonMalformed, NotAFeatureCollection) {
  EXPECT_THAT(MapErrors("[1, 2]"),
              ElementsAre(At("map.geojson", 1, 1,
                             "expected a GeoJSON FeatureCollection (an object), got an array")));
  EXPECT_THAT(MapErrors("{\"type\": \"Feature\", \"geometry\": null}"),
              ElementsAre(At("map.geojson", 1, 10,
                             "expected a GeoJSON FeatureCollection (of buildings), got a "
                             "\"Feature\" (at /type)")));
  EXPECT_THAT(MapErrors("{\"type\": \"FeatureCollection\"}"),
              ElementsAre(At("map.geojson", 1, 1, "missing key \"features\"")));
  EXPECT_THAT(MapErrors("{\"type\": \"FeatureCollection\", \"features\": {}}"),
              ElementsAre(At("map.geojson", 1, 43,
                             "expected \"features\" (an array), got an object (at /features)")));
}

TEST(GeoJsonMalformed, FeaturesMustBeFeatures) {
  EXPECT_THAT(MapErrors("{\"type\": \"FeatureCollection\", \"features\": [\n  42]}"),
              ElementsAre(At("map.geojson", 2, 3,
                             "expected a GeoJSON Feature (an object), got the number 42 (at "
                             "/features/0)")));
  EXPECT_THAT(MapErrors("{\"type\": \"FeatureCollection\", \"features\": [\n"
                        "  {\"type\": \"Point\", \"coordinates\": [0, 0]}]}"),
              ElementsAre(At("map.geojson", 2, 12,
                             "expected a GeoJSON Feature, got a \"Point\" (at /features/0/type)")));
  EXPECT_THAT(MapErrors(Map(kLine, "[1]")),
              ElementsAre(At("map.geojson", 2, 35,
                             "expected the feature's properties (or null) (an object), got an "
                             "array (at /features/0/properties)")));
}

TEST(GeoJsonMalformed, FeaturesWithoutASupportedGeometry) {
  EXPECT_THAT(MapErrors(Map("null")),
              ElementsAre(At("map.geojson", 3, 13,
                             "the feature has no geometry (null); expected LineString, "
                             "MultiLineString, Polygon or MultiPolygon (at "
                             "/features/0/geometry)")));
  EXPECT_THAT(MapErrors(Map(R"({"type": "Point", "coordinates": [1, 2]})")),
              ElementsAre(At("map.geojson", 3, 22,
                             "unsupported geometry type \"Point\": a prior map holds walls "
                             "(LineString, MultiLineString, Polygon or MultiPolygon) (at "
                             "/features/0/geometry/type)")));
  EXPECT_THAT(MapErrors(Map(R"({"type": "MultiPoint", "coordinates": [[1, 2]]})")),
              ElementsAre(At("map.geojson", 3, 22, "unsupported geometry type \"MultiPoint\"")));
  EXPECT_THAT(
      MapErrors(Map(R"({"type": "GeometryCollection", "geometries": []})")),
      ElementsAre(At("map.geojson", 3, 22, "unsupported geometry type \"GeometryCollection\"")));
  EXPECT_THAT(MapErrors(Map(R"({"type": "Circle", "coordinates": [1, 2]})")),
              ElementsAre(At("map.geojson", 3, 22,
                             "unknown geometry type \"Circle\"; expected LineString, "
                             "MultiLineString, Polygon or MultiPolygon")));
  EXPECT_THAT(MapErrors(Map(R"({"type": "LineString"})")),
              ElementsAre(At("map.geojson", 3, 13, "missing key \"coordinates\"")));
  EXPECT_THAT(MapErrors("{\"type\": \"FeatureCollection\", \"features\": [\n"
                        "  {\"type\": \"Feature\", \"properties\": null}]}"),
              ElementsAre(At("map.geojson", 2, 3, "missing key \"geometry\" (at /features/0)")));
}

TEST(GeoJsonMalformed, LinesNeedTwoPositions) {
  EXPECT_THAT(MapErrors(Map(R"({"type": "LineString", "coordinates": [[0, 0]]})")),
              ElementsAre(At("map.geojson", 3, 51,
                             "a line needs at least 2 positions, got 1 (at "
                             "/features/0/geometry/coordinates)")));
  EXPECT_THAT(
      MapErrors(Map(R"({"type": "MultiLineString", "coordinates": [[[0, 0], [1, 1]], []]})")),
      ElementsAre(At("map.geojson", 3, 75, "got 0 (at /features/0/geometry/coordinates/1)")));
}

TEST(GeoJsonMalformed, PositionsAreTwoOrThreeFiniteNumbers) {
  EXPECT_THAT(MapErrors(Map(R"({"type": "LineString", "coordinates": [[0, 0], [1]]})")),
              ElementsAre(At("map.geojson", 3, 60,
                             "expected a position [x, y] or [x, y, z], got an array of 1 "
                             "elements (at /features/0/geometry/coordinates/1)")));
  EXPECT_THAT(MapErrors(Map(R"({"type": "LineString", "coordinates": [[0, 0], [1, 2, 3, 4]]})")),
              ElementsAre(At("map.geojson", 3, 60, "got an array of 4 elements")));
  EXPECT_THAT(MapErrors(Map(R"({"type": "LineString", "coordinates": [[0, 0], [1, null]]})")),
              ElementsAre(At("map.geojson", 3, 64,
                             "expected y (a finite number), got null (at "
                             "/features/0/geometry/coordinates/1/1)")));
  EXPECT_THAT(MapErrors(Map(R"({"type": "LineString", "coordinates": [[0, 0], ["1", 2]]})")),
              ElementsAre(At("map.geojson", 3, 61, "expected x (a number), got the string \"1\"")));
  EXPECT_THAT(MapErrors(Map(R"({"type": "LineString", "coordinates": [[0, 0], [1, 2, "inf"]]})")),
              ElementsAre(At("map.geojson", 3, 67,
                             "expected z (a finite number), got the string \"inf\"")));
  // Finite, but so large that the map's extent would overflow.
  EXPECT_THAT(MapErrors(Map(R"({"type": "LineString", "coordinates": [[0, 0], [1e308, 2]]})")),
              ElementsAre(At("map.geojson", 3, 61,
                             "expected x in metres of a local frame, at most 1e+09")));
}

TEST(GeoJsonMalformed, ZeroLengthSegmentsAreLocatedAtTheRepeatedPosition) {
  EXPECT_THAT(MapErrors(Map(R"({"type": "LineString", "coordinates": [[0, 0], [1, 0], [1, 0]]})")),
              ElementsAre(At("map.geojson", 3, 68,
                             "zero-length segment: position 2 repeats position 1 (1, 0) (at "
                             "/features/0/geometry/coordinates/2)")));
}

TEST(GeoJsonMalformed, PolygonRingsAreClosedAndHaveFourPositions) {
  EXPECT_THAT(
      MapErrors(Map(R"({"type": "Polygon", "coordinates": [[[0, 0], [1, 0], [1, 1], [0, 1]]]})")),
      ElementsAre(At("map.geojson", 3, 74,
                     "a Polygon ring must end at its first position (0, 0), as RFC 7946 "
                     "(3.1.6) requires (at /features/0/geometry/coordinates/0/3)")));
  EXPECT_THAT(MapErrors(Map(R"({"type": "Polygon", "coordinates": [[[0, 0], [1, 0], [0, 0]]]})")),
              ElementsAre(At("map.geojson", 3, 49,
                             "a Polygon ring needs at least 4 positions (3 corners, then the "
                             "first again), got 3")));
  EXPECT_THAT(
      MapErrors(Map(R"({"type": "Polygon", "coordinates": []})")),
      ElementsAre(At("map.geojson", 3, 48, "a Polygon needs at least one ring (its outline)")));
  EXPECT_THAT(
      MapErrors(Map(
          R"({"type": "MultiPolygon", "coordinates": [[[[0, 0], [1, 0], [1, 1], [1, 1], [0, 0]]]]})")),
      ElementsAre(At("map.geojson", 3, 80,
                     "zero-length segment: position 3 repeats position 2 (1, 1) (at "
                     "/features/0/geometry/coordinates/0/0/3)")));
}

TEST(GeoJsonMalformed, StdMustBePositiveAndFinite) {
  EXPECT_THAT(MapErrors(Map(kLine, R"({"std": 0})")),
              ElementsAre(At("map.geojson", 2, 43,
                             "expected \"std\" > 0 m, got 0 (at /features/0/properties/std)")));
  EXPECT_THAT(MapErrors(Map(kLine, R"({"std": "inf"})")),
              ElementsAre(At("map.geojson", 2, 43,
                             "expected \"std\" (a finite number), got the string \"inf\"")));
  EXPECT_THAT(MapErrors(Map(kLine, "null", R"("std": -1, )")),
              ElementsAre(At("map.geojson", 1, 38, "expected \"std\" > 0 m, got -1 (at /std)")));
  EXPECT_THAT(MapErrors(Map(kLine, R"({"segment_std": [1, 2]})")),
              ElementsAre(At("map.geojson", 2, 51,
                             "expected one \"segment_std\" per segment of the feature (1), got "
                             "2 (at /features/0/properties/segment_std)")));
  EXPECT_THAT(MapErrors(Map(kLine, R"({"segment_std": [-1]})")),
              ElementsAre(At("map.geojson", 2, 52,
                             "expected an element of \"segment_std\" > 0 m, got -1")));
}

// The filter squares a std into a covariance and multiplies covariances: 1e200 would give an
// infinite variance, then NaN estimates, unless refused here at its place.
TEST(GeoJsonMalformed, StdMustBeWithinTheWorld) {
  EXPECT_THAT(MapErrors(Map(kLine, R"({"std": 1e200})")),
              ElementsAre(At("map.geojson", 2, 43,
                             "expected \"std\" of at most 1e+09 m, the world's bound, got 1e+200 "
                             "(at /features/0/properties/std)")));
  EXPECT_THAT(MapErrors(Map(kLine, "null", R"("std": 1.0000001e9, )")),
              ElementsAre(At("map.geojson", 1, 38, "got 1000000100 (at /std)")));
  EXPECT_THAT(MapErrors(Map(kLine, R"({"segment_std": [2e9]})")),
              ElementsAre(At("map.geojson", 2, 52,
                             "expected an element of \"segment_std\" of at most 1e+09 m")));
  const Result<PriorMap> largest =
      ParsePriorMapGeoJson(Map(kLine, R"({"std": 1e9})"), "map.geojson", 1.0);
  ASSERT_TRUE(largest.ok()) << largest.error();
  EXPECT_EQ(largest.value().segments.at(0).std, 1e9);
}

TEST(GeoJsonMalformed, NamesAreStringsAndIdsStringsOrNumbers) {
  EXPECT_THAT(MapErrors(Map(kLine, R"({"name": 7})")),
              ElementsAre(At("map.geojson", 2, 44,
                             "expected the building name (a string), got the number 7 (at "
                             "/features/0/properties/name)")));
  EXPECT_THAT(MapErrors(Map(kLine, R"({"id": [7]})")),
              ElementsAre(At("map.geojson", 2, 42,
                             "expected the feature id (a string or a number) (at "
                             "/features/0/properties/id)")));
}

TEST(GeoJsonMalformed, AMapWithoutSegments) {
  EXPECT_THAT(MapErrors("{\"type\": \"FeatureCollection\", \"features\": []}"),
              ElementsAre(At("map.geojson", 1, 43, "prior map has no segments (at /features)")));
  EXPECT_THAT(MapErrors(Map(R"({"type": "MultiLineString", "coordinates": []})")),
              ElementsAre(At("map.geojson", 1, 43, "prior map has no segments")));
}

TEST(GeoJsonMalformed, KeysWithEscapesAreLocatedAtTheirValue) {
  // A member whose key is written with escapes ("t\u0079pe" is "type") is found all the same:
  // the diagnostic points at its value.
  EXPECT_THAT(MapErrors(Map(R"({"t\u0079pe": "Point", "coordinates": [1, 2]})")),
              ElementsAre(At("map.geojson", 3, 27, "unsupported geometry type \"Point\"")));
}

TEST(GeoJsonMalformed, ColumnsCountCharactersAndAByteOrderMarkTakesNone) {
  // "é" is two bytes and one column, as an editor shows it; a byte order mark is no column.
  const std::string wide = "{\"type\": \"FeatureCollection\", \"features\": [\n" +
                           std::string(R"({"type": "Feature", "properties": {"name": "é"}, )") +
                           R"("geometry": 7}]})";
  EXPECT_THAT(MapErrors(wide), ElementsAre(At("map.geojson", 2, 62, "(at /features/0/geometry)")));
  EXPECT_THAT(MapErrors(std::string(kUtf8ByteOrderMark) + wide),
              ElementsAre(At("map.geojson", 2, 62, "(at /features/0/geometry)")));
}

TEST(GeoJsonMalformed, MissingFileIsADiagnostic) {
  const auto result = ReadPriorMapGeoJson("/nonexistent/map.geojson", 1.0);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.diagnostics().front().file, "/nonexistent/map.geojson");
}

// ---- whatever the text, a result or located diagnostics ----

RC_GTEST_PROP(SlamIoMalformed, ArbitraryTextNeverCrashesAndErrorsAreLocated,
              (const std::string& text)) {
  for (const std::vector<Diagnostic>& diagnostics :
       {ParseObservationsCsv(text, "a.csv").diagnostics(),
        ParseOdometryCsv(text, "b.csv").diagnostics(),
        ParsePriorMapGeoJson(text, "c.geojson", 1.0).diagnostics()}) {
    for (const Diagnostic& d : diagnostics) {
      RC_ASSERT(d.line >= 1);
      RC_ASSERT(d.col >= 1);
    }
  }
}

// Single-character edits of valid files give a result or located diagnostics.
RC_GTEST_PROP(SlamIoMalformed, MutatedFilesNeverCrash, ()) {
  std::string text = *rc::gen::element<std::string>(
      "time,id,range,bearing\n0,1,5,0.5\n0,2,4,-0.5\n1,1,5,0.25\n",
      "time,speed,steer\n0,14,0\n0.25,14,0.1\n0.5,14,0.1\n",
      "time,dx,dy,dtheta,sx,sy,stheta\n0,0,0,0,,,\n1,1,0,0.1,0.1,0.1,0.01\n",
      Map(R"({"type": "Polygon", "coordinates": [[[0, 0], [1, 0], [1, 1], [0, 0]]]})"));
  const int edits = *rc::gen::inRange(1, 4);
  for (int e = 0; e < edits && !text.empty(); ++e) {
    const std::size_t at = *rc::gen::inRange<std::size_t>(0, text.size());
    const char c = *rc::gen::element(',', '\n', '"', '#', '-', '0', '9', 'e', '.', ' ', '[', ']');
    switch (*rc::gen::inRange(0, 3)) {
      case 0:
        text[at] = c;
        break;
      case 1:
        text.insert(at, 1, c);
        break;
      default:
        text.erase(at, 1);
        break;
    }
  }
  RC_LOG() << text;
  for (const std::vector<Diagnostic>& diagnostics :
       {ParseObservationsCsv(text, "a.csv").diagnostics(),
        ParseOdometryCsv(text, "b.csv").diagnostics(),
        ParsePriorMapGeoJson(text, "c.geojson", 1.0).diagnostics()}) {
    for (const Diagnostic& d : diagnostics) {
      RC_ASSERT(d.line >= 1);
      RC_ASSERT(d.col >= 1);
    }
  }
}

}  // namespace
}  // namespace priormap::slam
