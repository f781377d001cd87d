// Bad JSON documents: each problem is one Diagnostic at the line and column of the offending
// value (or of the object that lacks a key), saying what was expected; nothing throws.
#include <exception>
#include <ostream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <priormap/core/json_io.hpp>
#include <priormap/core/log_io.hpp>
#include <priormap/core/scene.hpp>

#include "testing/diagnostic_matchers.hpp"
#include "testing/temp_dir.hpp"

namespace priormap {
namespace {

using ::testing::AllOf;
using ::testing::ElementsAre;
using ::testing::Field;
using ::testing::HasSubstr;
using testing::Lines;
using ::testing::Matcher;

constexpr const char* kName = "bad.json";

// A diagnostic of the document under test (kName).
Matcher<const Diagnostic&> DiagnosticAt(int line, int col, const std::string& message_part) {
  return testing::DiagnosticAt(kName, line, col, message_part);
}

std::vector<Diagnostic> LogErrors(const std::string& text) {
  const Result<Log> result = ParseJsonLog(text, kName);
  EXPECT_FALSE(result.ok()) << "parsed without error:\n" << text;
  return result.diagnostics();
}

std::vector<Diagnostic> SceneErrors(const std::string& text) {
  const Result<Scene> result = ParseJsonScene(text, kName);
  EXPECT_FALSE(result.ok()) << "parsed without error:\n" << text;
  return result.diagnostics();
}

// A valid scan document, one member per line; the value of `key` is replaced by `value`.
// Values start at column 8 + the length of the key: format 2:13, version 3:14, pose 4:11,
// angles 5:13, ranges 6:13, sigma 7:12.
std::string ScanDocument(const std::string& key = "", const std::string& value = "") {
  const std::vector<std::pair<std::string, std::string>> members = {
      {"format", "\"priormap.scan\""}, {"version", "1"},        {"pose", "[0, 0, 0]"},
      {"angles", "[0, 0.5, 1]"},       {"ranges", "[1, 2, 3]"}, {"sigma", "[0.1, 0.1, 0.1]"}};
  std::string text = "{\n";
  for (std::size_t i = 0; i < members.size(); ++i) {
    const auto& [k, v] = members[i];
    text += "  \"" + k + "\": " + (k == key ? value : v) + (i + 1 < members.size() ? ",\n" : "\n");
  }
  return text + "}\n";
}

// Line 2 is a valid polyline; line 3 a circle whose radius is at column 50.
std::string SceneDocument(const std::string& circle_radius = "0.5",
                          const std::string& polyline_points = "[[0, 0], [4, 0], [4, 3]]") {
  return "{\"format\": \"priormap.scene\", \"version\": 1, \"surfaces\": [\n"
         "  {\"type\": \"polyline\", \"points\": " +
         polyline_points +
         ", \"closed\": true},\n"
         "  {\"type\": \"circle\", \"center\": [1, 1], \"radius\": " +
         circle_radius +
         "}\n"
         "]}\n";
}

TEST(JsonMalformed, DocumentsUsedBelowAreValidAsGiven) {
  EXPECT_TRUE(ParseJsonLog(ScanDocument(), kName).ok());
  EXPECT_TRUE(ParseJsonScene(SceneDocument(), kName).ok());
}

// ---- syntax ----

TEST(JsonMalformed, SyntaxErrorIsLocatedAtTheOffendingCharacter) {
  EXPECT_THAT(LogErrors("{\"format\": \"priormap.log\",\n"
                        " \"version\": 1,\n"
                        " \"records\": [}\n"),
              ElementsAre(DiagnosticAt(3, 14,
                                       "invalid JSON: syntax error while parsing value - "
                                       "unexpected '}'; expected '[', '{', or a literal")));
}

TEST(JsonMalformed, MissingCommaIsLocatedAtTheNextKey) {
  // nlohmann stops at the last character of the unexpected token: the closing quote of "version".
  EXPECT_THAT(LogErrors("{\"format\": \"priormap.log\"\n \"version\": 1}"),
              ElementsAre(DiagnosticAt(2, 10,
                                       "invalid JSON: syntax error while parsing object - "
                                       "unexpected string literal; expected '}'")));
}

TEST(JsonMalformed, TruncatedDocumentIsLocatedAtTheEnd) {
  EXPECT_THAT(LogErrors("{\"format\": \"priormap.log\", \"version\": 1, \"records\": [\n"),
              ElementsAre(DiagnosticAt(2, 1, "unexpected end of input")));
  EXPECT_THAT(LogErrors(""), ElementsAre(DiagnosticAt(1, 1, "unexpected end of input")));
}

TEST(JsonMalformed, TrailingGarbageMessageIsKeptWhole) {
  // nlohmann's message quotes the text it read, which itself contains ": ".
  EXPECT_THAT(LogErrors(R"({"format": "priormap.log", "version": 1, "records": []} x)"),
              ElementsAre(DiagnosticAt(1, 57,
                                       "invalid JSON: syntax error while parsing value - invalid "
                                       "literal; last read: '\"records\": []} x'; expected end "
                                       "of input")));
}

// A Latin-1 byte in a string: nlohmann saw the sequence fail at the '"' after it and quoted the
// raw byte, which a terminal shows as garbage. The error is at the byte, and the byte escaped.
TEST(JsonMalformed, AByteThatIsNotUtf8IsLocatedAtItselfAndEscaped) {
  const std::string latin1 =
      "{\"format\": \"priormap.log\", \"version\": 1, \"name\": \"caf\xe9\"}";
  EXPECT_THAT(LogErrors(latin1),
              ElementsAre(DiagnosticAt(1, 54,
                                       "invalid JSON: syntax error while parsing value - invalid "
                                       "string: ill-formed UTF-8 byte; last read: "
                                       "'\"caf\\xe9\"'")));
  // Valid UTF-8 in what nlohmann quotes is kept as it is (it shows a control character itself).
  // The column counts characters: the 'é' before the control character takes one.
  EXPECT_THAT(LogErrors("{\"format\": \"priormap.log\", \"caf\u00e9\x01\": 1}"),
              ElementsAre(DiagnosticAt(1, 33,
                                       "invalid JSON: syntax error while parsing object key - "
                                       "invalid string: control character U+0001 (SOH) must be "
                                       "escaped to \\u0001; last read: '\"caf\u00e9<U+0001>'")));
}

TEST(JsonMalformed, NumberBeyondDoubleRangeIsADiagnosticNotAnException) {
  EXPECT_THAT(LogErrors(ScanDocument("ranges", "[1, 1e400, 3]")),
              ElementsAre(DiagnosticAt(6, 17, "invalid JSON: number overflow parsing '1e400'")));
  EXPECT_THAT(SceneErrors(SceneDocument("-1e99999")),
              ElementsAre(DiagnosticAt(3, 50, "invalid JSON: number overflow parsing '-1e99999'")));
}

// ---- document type ----

TEST(JsonMalformed, DocumentMustBeAnObject) {
  EXPECT_THAT(LogErrors("[1, 2]"),
              ElementsAre(DiagnosticAt(1, 1,
                                       "expected a priormap.log or priormap.scan document (an "
                                       "object), got an array")));
}

TEST(JsonMalformed, WrongFormatIsReportedAtTheFormatValue) {
  EXPECT_THAT(LogErrors(ScanDocument("format", "\"priormap.scene\"")),
              ElementsAre(DiagnosticAt(2, 13,
                                       "expected format \"priormap.log\" or \"priormap.scan\", got "
                                       "\"priormap.scene\" (at /format)")));
  EXPECT_THAT(SceneErrors(ScanDocument()),
              ElementsAre(DiagnosticAt(
                  2, 13, "expected format \"priormap.scene\", got \"priormap.scan\"")));
  EXPECT_THAT(LogErrors(ScanDocument("format", "42")),
              ElementsAre(DiagnosticAt(2, 13,
                                       "expected the document format (a string), got the "
                                       "number 42")));
}

TEST(JsonMalformed, MissingFormatIsReportedAtTheDocument) {
  EXPECT_THAT(LogErrors("\n  {\"version\": 1}"),
              ElementsAre(DiagnosticAt(2, 3, "missing key \"format\"")));
}

TEST(JsonMalformed, UnsupportedVersionIsReportedAtTheVersionValue) {
  EXPECT_THAT(LogErrors(ScanDocument("version", "2")),
              ElementsAre(DiagnosticAt(3, 14,
                                       "unsupported priormap.scan version 2 (this priormap reads "
                                       "version 1) (at /version)")));
  EXPECT_THAT(LogErrors(ScanDocument("version", "\"1\"")),
              ElementsAre(DiagnosticAt(3, 14,
                                       "expected the format version (an integer), got the "
                                       "string \"1\"")));
}

// ---- scans ----

TEST(JsonMalformed, MissingRangesIsReportedAtTheScan) {
  EXPECT_THAT(LogErrors(R"({"format": "priormap.scan", "version": 1, "pose": [0, 0, 0]})"),
              ElementsAre(DiagnosticAt(1, 1, "missing key \"ranges\"")));
}

TEST(JsonMalformed, RangesThatAreNotAnArrayAreReportedAtTheValue) {
  EXPECT_THAT(LogErrors(ScanDocument("ranges", "\"1 2 3\"")),
              ElementsAre(DiagnosticAt(6, 13,
                                       "expected \"ranges\" (an array), got the string "
                                       "\"1 2 3\" (at /ranges)")));
}

TEST(JsonMalformed, StringInsideRangesIsReportedAtTheElement) {
  EXPECT_THAT(LogErrors(ScanDocument("ranges", "[1, \"two\", 3]")),
              ElementsAre(DiagnosticAt(6, 17,
                                       "expected an element of \"ranges\" (a number), got "
                                       "the string \"two\" (at /ranges/1)")));
}

TEST(JsonMalformed, SigmaOfTheWrongSizeIsReportedAtTheArray) {
  EXPECT_THAT(
      LogErrors(ScanDocument("sigma", "[0.1, 0.1]")),
      ElementsAre(DiagnosticAt(7, 12, "expected 3 values in \"sigma\", got 2 (at /sigma)")));
}

TEST(JsonMalformed, AnglesOfTheWrongSizeAreReportedAtTheArray) {
  EXPECT_THAT(LogErrors(ScanDocument("angles", "[0, 1]")),
              ElementsAre(DiagnosticAt(5, 13, "expected 3 values in \"angles\", got 2")));
}

TEST(JsonMalformed, ScanWithoutAnglesIsReportedAtTheScan) {
  EXPECT_THAT(LogErrors(R"({"format": "priormap.scan", "version": 1, "pose": [0, 0, 0],
                            "ranges": [1], "angle_min": 0})"),
              ElementsAre(DiagnosticAt(1, 1,
                                       "expected \"angles\", or \"angle_min\" and "
                                       "\"angle_increment\"")));
}

TEST(JsonMalformed, PoseWithTwoElementsIsReportedAtThePose) {
  EXPECT_THAT(
      LogErrors(ScanDocument("pose", "[0, 0]")),
      ElementsAre(DiagnosticAt(4, 11, "expected the sensor pose as [x, y, theta] (at /pose)")));
}

TEST(JsonMalformed, NonFinitePoseIsReportedAtTheElement) {
  EXPECT_THAT(LogErrors(ScanDocument("pose", "[0, \"inf\", 0]")),
              ElementsAre(DiagnosticAt(4, 15,
                                       "expected y (a finite number), got the string "
                                       "\"inf\" (at /pose/1)")));
}

// A finite but absurd position is reported at the coordinate, with the bound it breaks, not
// later as a grid too large to make.
TEST(JsonMalformed, APositionBeyondTheWorldIsReportedAtTheCoordinate) {
  EXPECT_THAT(LogErrors(ScanDocument("pose", "[1e300, 0, 0]")),
              ElementsAre(DiagnosticAt(4, 12,
                                       "expected x in metres of a local frame, at most 1e+09 in "
                                       "magnitude, got 1e+300 (at /pose/0)")));
  EXPECT_THAT(LogErrors(ScanDocument("pose", "[0, -2e9, 0]")),
              ElementsAre(DiagnosticAt(4, 15, "expected y in metres of a local frame")));
  EXPECT_THAT(LogErrors(ScanDocument("pose", "[0, 0, 0], \"odom_pose\": [0, 1e10, 0]")),
              ElementsAre(DiagnosticAt(4, 39, "expected y in metres of a local frame")));
  EXPECT_THAT(LogErrors("{\"format\": \"priormap.log\", \"version\": 1, \"records\": [\n"
                        "{\"type\": \"odometry\", \"pose\": [-1e300, 0, 0]}]}"),
              ElementsAre(DiagnosticAt(2, 31, "got -1e+300 (at /records/0/pose/0)")));
  EXPECT_THAT(LogErrors("{\"format\": \"priormap.log\", \"version\": 1, \"records\": [\n"
                        "{\"type\": \"true_pose\", \"true_pose\": [0, 0, 0], "
                        "\"odom_pose\": [0, 1e300, 0]}]}"),
              ElementsAre(DiagnosticAt(2, 64, "got 1e+300 (at /records/0/odom_pose/1)")));
  // The bound itself is inside, and theta, an angle, has none.
  EXPECT_TRUE(ParseJsonLog(ScanDocument("pose", "[1e9, -1e9, 1e300]"), kName).ok());
}

// A reading of 1e300 in a scan without a max range was read as a return 1e300 m away, and only
// `priormap plot` refused the file, naming no position: it is reported at the reading.
TEST(JsonMalformed, AReturnLongerThanTheWorldsBoundIsReportedAtTheReading) {
  EXPECT_THAT(LogErrors(ScanDocument("ranges", "[1, 1e300, 3]")),
              ElementsAre(DiagnosticAt(6, 17,
                                       "expected an element of \"ranges\" in metres, at most "
                                       "1e+09 for a return or at or above the max range (inf m) "
                                       "for no return, got 1e+300 (at /ranges/1)")));
  EXPECT_THAT(LogErrors(ScanDocument("ranges", "[1, 2, 1.5e9], \"max_range\": 2e9")),
              ElementsAre(DiagnosticAt(6, 20, "(2000000000 m) for no return, got 1500000000")));
  // The simulator's truth is a distance to a surface too (null where nothing was hit).
  EXPECT_THAT(LogErrors(ScanDocument("ranges",
                                     "[1, 2, 3], \"true_range\": [1, null, -2e9], "
                                     "\"true_alpha\": [0, 0, 0], \"true_surface\": "
                                     "[0, 0, 0], \"true_region\": [0, 0, 0]")),
              ElementsAre(DiagnosticAt(6, 48,
                                       "expected an element of \"true_range\" in metres, at most "
                                       "1e+09, or null where nothing was hit, got -2000000000 (at "
                                       "/true_range/2)")));
}

// A no-return (at or above the max range) or a reading flagged invalid says nothing of where a
// surface is: any value is kept as read.
TEST(JsonMalformed, AReadingBeyondTheWorldsBoundThatIsNoReturnIsKeptAsRead) {
  for (const std::string ranges :
       {"[1, 1e300, 3], \"max_range\": 30", "[1, 1e300, 3], \"max_range\": 1e300",
        "[1, 1e300, 3], \"status\": [\"valid\", \"invalid\", \"valid\"]",
        "[1, 1e300, 3], \"status\": [\"valid\", \"max_range\", \"valid\"]"}) {
    const Result<Log> log = ParseJsonLog(ScanDocument("ranges", ranges), kName);
    ASSERT_TRUE(log.ok()) << log.error();
    EXPECT_EQ(log.value().scans.at(0).ranges.at(1), 1e300) << ranges;
    EXPECT_FALSE(log.value().scans.at(0).IsValid(1)) << ranges;
  }
  // The bound itself is a return.
  EXPECT_TRUE(ParseJsonLog(ScanDocument("ranges", "[1, 1e9, 3]"), kName).ok());
}

TEST(JsonMalformed, InconsistentScanIsReportedAtTheMemberItIsAbout) {
  EXPECT_THAT(LogErrors(ScanDocument("angles", "[0, 1, 0.5]")),
              ElementsAre(DiagnosticAt(5, 13,
                                       "inconsistent scan: angles must increase (beam 1 "
                                       "to 2)")));
  EXPECT_THAT(LogErrors(ScanDocument("sigma", "[0.1, 0, 0.1]")),
              ElementsAre(DiagnosticAt(7, 12,
                                       "inconsistent scan: sigma must be positive and "
                                       "finite")));
}

TEST(JsonMalformed, BadStatusStringIsReportedAtTheElement) {
  EXPECT_THAT(LogErrors(R"({"format": "priormap.scan", "version": 1, "pose": [0, 0, 0],
  "angles": [0, 1], "ranges": [1, 2], "status": ["valid", "broken"]})"),
              ElementsAre(DiagnosticAt(2, 59,
                                       "expected a beam status (\"valid\", \"max_range\" "
                                       "or \"invalid\"), got \"broken\" (at /status/1)")));
}

// A flag cannot make a NaN or a negative range a measurement (the grids would map it).
TEST(JsonMalformed, ValidStatusOnAnUnusableRangeIsReportedAtTheElement) {
  EXPECT_THAT(
      LogErrors(R"({"format": "priormap.scan", "version": 1, "pose": [0, 0, 0],
  "angles": [0, 1], "ranges": [1, null], "status": ["valid", "valid"]})"),
      ElementsAre(DiagnosticAt(2, 62, "reading 1 is nan: \"valid\" needs a finite range > 0")));
  EXPECT_THAT(LogErrors(R"({"format": "priormap.scan", "version": 1, "pose": [0, 0, 0],
  "angles": [0, 1], "ranges": [-1, 2], "status": ["valid", "valid"]})"),
              ElementsAre(DiagnosticAt(2, 51, "reading 0 is -1")));
}

// Nor a reading beyond the max range (a no-return) or below the min range a wall.
TEST(JsonMalformed, ValidStatusOutsideTheRangeLimitsIsReportedAtTheElement) {
  EXPECT_THAT(LogErrors(R"({"format": "priormap.scan", "version": 1, "pose": [0, 0, 0],
  "angles": [0, 1], "ranges": [1, 50], "max_range": 30, "status": ["valid", "valid"]})"),
              ElementsAre(DiagnosticAt(2, 77,
                                       "reading 1 is 50 m: \"valid\" needs a range in "
                                       "[min_range, max_range) = [0, 30) m")));
  EXPECT_THAT(LogErrors(R"({"format": "priormap.scan", "version": 1, "pose": [0, 0, 0],
  "angles": [0, 1], "ranges": [0.05, 2], "min_range": 0.1, "status": ["valid", "valid"]})"),
              ElementsAre(DiagnosticAt(2, 71, "reading 0 is 0.05 m")));
}

TEST(JsonMalformed, PrecisionThatIsNotFiniteOrNotPositiveDefiniteIsRefused) {
  const std::string head = R"({"format": "priormap.scan", "version": 1, "pose": [0, 0, 0],
  "angles": [0, 1], "ranges": [1, 2], "precision": )";
  EXPECT_THAT(LogErrors(head + R"({"bandwidth": 1, "bands": [[1, 1], [null, 0]]}})"),
              ElementsAre(DiagnosticAt(2, 88, "expected a finite number in precision band 1")));
  // Eigenvalues 5 and -4.
  EXPECT_THAT(LogErrors(head + R"({"bandwidth": 1, "bands": [[1, 1], [5, 0]]}})"),
              ElementsAre(DiagnosticAt(2, 52, "precision is not a finite positive definite")));
  // Band 1's last entry lies outside the matrix: it is not read, so null is fine there.
  EXPECT_TRUE(
      ParseJsonLog(head + R"({"bandwidth": 1, "bands": [[2, 2], [1, null]]}})", kName).ok());
}

TEST(JsonMalformed, AnIntegerBeyondSixtyFourSignedBitsIsRefusedNotWrapped) {
  EXPECT_THAT(LogErrors(R"({"format": "priormap.scan", "version": 1, "pose": [0, 0, 0],
  "angles": [0, 1], "ranges": [1, 2], "true_range": [1, 2], "true_alpha": [0, 0],
  "true_surface": [18446744073709551615, 0], "true_region": [0, 0]})"),
              ElementsAre(DiagnosticAt(3, 20, "18446744073709551615, which is too large")));
}

// Without true_range the other truth members were dropped unread: they are refused at themselves.
TEST(JsonMalformed, TruthWithoutTrueRangeIsRefusedNotDropped) {
  EXPECT_THAT(LogErrors(ScanDocument("sigma", "[0.1, 0.1, 0.1], \"true_alpha\": [0, 0, 0]")),
              ElementsAre(DiagnosticAt(7, 43,
                                       "\"true_alpha\" needs \"true_range\": a scan's ground "
                                       "truth is read only with its true ranges")));
  EXPECT_THAT(LogErrors(ScanDocument("sigma", "[0.1, 0.1, 0.1], \"true_outlier\": [0, 1, 0]")),
              ElementsAre(DiagnosticAt(7, 45, "\"true_outlier\" needs \"true_range\"")));
}

// A misspelt key is refused at itself, with the key it was likely meant to be, not read as
// absent (max_range absent means no reading is a max-range reading).
TEST(JsonMalformed, AnUnknownKeyIsRefusedWithTheNearestKnownOne) {
  EXPECT_THAT(LogErrors(ScanDocument("sigma", "[0.1, 0.1, 0.1], \"max_rnage\": 30")),
              ElementsAre(DiagnosticAt(7, 42,
                                       "unknown key \"max_rnage\" in a scan (did you mean "
                                       "\"max_range\"?)")));
  EXPECT_THAT(LogErrors(ScanDocument("sigma", "[0.1, 0.1, 0.1], \"comment\": \"x\"")),
              ElementsAre(DiagnosticAt(7, 40, "unknown key \"comment\" in a scan (at /comment)")));
  EXPECT_THAT(LogErrors(R"({"format": "priormap.log", "version": 1, "records": [
  {"type": "odometry", "pose": [0, 0, 0], "tv": 0, "accell": 1}]})"),
              ElementsAre(DiagnosticAt(2, 62,
                                       "unknown key \"accell\" in a \"odometry\" record "
                                       "(did you mean \"accel\"?)")));
}

// The same in scenes: a misspelt "clutter" would make an object a wall for the priors, a
// misspelt "default_pose" would simulate from the origin.
TEST(JsonMalformed, AnUnknownKeyOfASceneIsRefusedWithTheNearestKnownOne) {
  EXPECT_THAT(SceneErrors(R"({"format": "priormap.scene", "version": 1, "surfaces": [
  {"type": "circle", "center": [0, 0], "radius": 1, "cluter": true}]})"),
              ElementsAre(DiagnosticAt(2, 63,
                                       "unknown key \"cluter\" in a circle surface (did you mean "
                                       "\"clutter\"?) (at /surfaces/0/cluter)")));
  EXPECT_THAT(SceneErrors(R"({"format": "priormap.scene", "version": 1, "surfaces": [
  {"type": "polyline", "points": [[0, 0], [1, 0]], "radius": 1}]})"),
              ElementsAre(DiagnosticAt(2, 62, "unknown key \"radius\" in a polyline surface")));
  EXPECT_THAT(SceneErrors(R"({"format": "priormap.scene", "version": 1, "surfaces": [],
  "defualt_pose": [1, 2, 0]})"),
              ElementsAre(DiagnosticAt(2, 19,
                                       "unknown key \"defualt_pose\" in a priormap.scene document "
                                       "(did you mean \"default_pose\"?)")));
}

TEST(JsonMalformed, AByteOrderMarkIsSkipped) {
  const std::string text = "\xef\xbb\xbf" + ScanDocument();
  EXPECT_EQ(SniffLogFormat(text), LogFormat::kJson);
  EXPECT_TRUE(ParseJsonLog(text, kName).ok());
}

TEST(JsonMalformed, StatusOfTheWrongSizeIsReportedAtTheArray) {
  EXPECT_THAT(LogErrors(R"({"format": "priormap.scan", "version": 1, "pose": [0, 0, 0],
  "angles": [0, 1], "ranges": [1, 2], "status": ["valid"]})"),
              ElementsAre(DiagnosticAt(2, 49, "expected 2 entries in \"status\"")));
}

TEST(JsonMalformed, PrecisionBandwidthOutOfRangeIsReportedAtThePrecision) {
  EXPECT_THAT(LogErrors(R"({"format": "priormap.scan", "version": 1, "pose": [0, 0, 0],
  "angles": [0, 1], "ranges": [1, 2], "precision": {"bandwidth": 2, "bands": []}})"),
              ElementsAre(DiagnosticAt(2, 52, "precision bandwidth must be in [0, 2), got 2")));
}

TEST(JsonMalformed, PrecisionBandOfTheWrongSizeIsReportedAtTheBand) {
  EXPECT_THAT(LogErrors(R"({"format": "priormap.scan", "version": 1, "pose": [0, 0, 0],
  "angles": [0, 1], "ranges": [1, 2],
  "precision": {"bandwidth": 1, "bands": [[1, 1], [0.5]]}})"),
              ElementsAre(DiagnosticAt(3, 51, "expected 2 values in each precision band")));
}

TEST(JsonMalformed, LargePrecisionBandwidthOfAShortDocumentIsRejectedWithoutAllocating) {
  // 200000 readings and bandwidth 199999 would be a 320 GB band matrix (std::bad_alloc); the
  // bands of this 1 MB document, all empty, are checked first.
  const std::size_t n = 200000;
  std::string ranges = "1", bands = "[]";
  for (std::size_t i = 1; i < n; ++i) {
    ranges += ",1";
    bands += ",[]";
  }
  const std::string text =
      "{\"format\": \"priormap.scan\", \"version\": 1, \"pose\": [0, 0, 0], \"angle_min\": 0,\n"
      "\"angle_increment\": 1e-6, \"ranges\": [" +
      ranges +
      "],\n"
      "\"precision\": {\"bandwidth\": 199999, \"bands\": [" +
      bands + "]}}";
  EXPECT_THAT(LogErrors(text),
              ElementsAre(DiagnosticAt(3, 46,
                                       "expected 200000 values in each precision band (at "
                                       "/precision/bands/0)")));
}

TEST(JsonMalformed, DuplicateKeyIsReportedAtTheValueThatIsUsed) {
  // nlohmann keeps the last of duplicate keys.
  EXPECT_THAT(LogErrors(R"({"format": "priormap.scan", "version": 1, "pose": [0, 0, 0],
  "angles": [0], "ranges": [1],
  "ranges": ["x"]})"),
              ElementsAre(DiagnosticAt(3, 14, "got the string \"x\" (at /ranges/0)")));
}

// ---- logs ----

const std::string kLogWithUnknownRecord =
    "{\"format\": \"priormap.log\", \"version\": 1, \"records\": [\n"
    "{\"type\": \"odometry\", \"pose\": [0, 0, 0]},\n"
    "{\"type\": \"laser\", \"pose\": [0, 0, 0]}\n"
    "]}\n";

TEST(JsonMalformed, UnknownRecordTypeIsReportedAtTheType) {
  EXPECT_THAT(LogErrors(kLogWithUnknownRecord),
              ElementsAre(DiagnosticAt(3, 10,
                                       "expected a record type (\"scan\", \"odometry\", "
                                       "\"true_pose\" or \"param\"), got \"laser\" (at "
                                       "/records/1/type)")));
}

TEST(JsonMalformed, RecordWithoutTypeIsReportedAtTheRecord) {
  EXPECT_THAT(LogErrors("{\"format\": \"priormap.log\", \"version\": 1, \"records\": [\n"
                        "  {\"pose\": [0, 0, 0]}]}"),
              ElementsAre(DiagnosticAt(2, 3, "missing key \"type\" (at /records/0)")));
}

TEST(JsonMalformed, UnknownPoseSourceIsReportedAtTheValue) {
  EXPECT_THAT(
      LogErrors(
          R"({"format": "priormap.log", "version": 1, "pose_source": "slam", "records": []})"),
      ElementsAre(DiagnosticAt(1, 57,
                               "expected a pose source (unknown, odometry, "
                               "corrected, ground_truth), got \"slam\"")));
}

TEST(JsonMalformed, RecordsThatAreNotAnArrayAreReportedAtTheValue) {
  EXPECT_THAT(LogErrors(R"({"format": "priormap.log", "version": 1, "records": {}})"),
              ElementsAre(DiagnosticAt(1, 53, "expected \"records\" (an array), got an object")));
}

TEST(JsonMalformed, ErrorsInsideCarmenFieldsAreLocated) {
  EXPECT_THAT(
      LogErrors("{\"format\": \"priormap.log\", \"version\": 1, \"records\": [\n"
                "{\"type\": \"odometry\", \"pose\": [0, 0, 0], \"carmen\": {\"host\": 7}}]}"),
      ElementsAre(DiagnosticAt(2, 60, "expected host (a string), got the number 7")));
}

// ---- scenes ----

TEST(JsonMalformed, ZeroRadiusIsReportedAtTheRadius) {
  EXPECT_THAT(SceneErrors(SceneDocument("0")),
              ElementsAre(DiagnosticAt(3, 50,
                                       "radius must be positive, got 0 (at "
                                       "/surfaces/1/radius)")));
  EXPECT_THAT(SceneErrors(SceneDocument("null")),
              ElementsAre(DiagnosticAt(3, 50, "expected the radius (a finite number), got null")));
}

TEST(JsonMalformed, PolylineWithOnePointIsReportedAtThePoints) {
  EXPECT_THAT(SceneErrors(SceneDocument("0.5", "[[0, 0]]")),
              ElementsAre(DiagnosticAt(2, 34,
                                       "a polyline needs at least 2 points (at "
                                       "/surfaces/0/points)")));
}

TEST(JsonMalformed, PointWithThreeCoordinatesIsReportedAtThePoint) {
  EXPECT_THAT(SceneErrors(SceneDocument("0.5", "[[0, 0], [4, 0, 1]]")),
              ElementsAre(DiagnosticAt(2, 43,
                                       "expected a point [x, y] as [x, y] (at "
                                       "/surfaces/0/points/1)")));
}

// A scene point 1e300 away was read as a zero-length segment (1e300 + 4 == 1e300) and, drawn
// with a log, blamed the log for lying too far away: it is reported at the coordinate.
TEST(JsonMalformed, ASceneBeyondTheWorldIsReportedWhereItLeavesIt) {
  EXPECT_THAT(SceneErrors(SceneDocument("0.5", "[[1e300, 0], [4, 0]]")),
              ElementsAre(DiagnosticAt(2, 36,
                                       "expected x in metres of a local frame, at most 1e+09 in "
                                       "magnitude, got 1e+300 (at /surfaces/0/points/0/0)")));
  EXPECT_THAT(SceneErrors(SceneDocument("0.5", "[[0, 0], [4, -2e9]]")),
              ElementsAre(DiagnosticAt(2, 47, "got -2000000000 (at /surfaces/0/points/1/1)")));
  EXPECT_THAT(SceneErrors("{\"format\": \"priormap.scene\", \"version\": 1, \"surfaces\": [\n"
                          "  {\"type\": \"circle\", \"center\": [3e9, 1], \"radius\": 1}]}"),
              ElementsAre(DiagnosticAt(2, 33, "got 3000000000 (at /surfaces/0/center/0)")));
  // A circle whose centre is inside but whose far side is not.
  EXPECT_THAT(SceneErrors("{\"format\": \"priormap.scene\", \"version\": 1, \"surfaces\": [\n"
                          "  {\"type\": \"circle\", \"center\": [9e8, 1], \"radius\": 2e8}]}"),
              ElementsAre(DiagnosticAt(2, 52,
                                       "expected a radius of at most 100000000 m, which keeps "
                                       "x and y of every point of the circle about (900000000, "
                                       "1) within ±1e+09 m, got 200000000 (at "
                                       "/surfaces/0/radius)")));
  // A centre on the bound leaves no radius to ask for ("at most 0 m"): the centre must move.
  EXPECT_THAT(SceneErrors("{\"format\": \"priormap.scene\", \"version\": 1, \"surfaces\": [\n"
                          "  {\"type\": \"circle\", \"center\": [1, -1e9], \"radius\": 2}]}"),
              ElementsAre(DiagnosticAt(2, 53,
                                       "the circle about (1, -1000000000) cannot lie within "
                                       "±1e+09 m in x and y with any radius, as its centre is on "
                                       "that bound: move the centre inwards by at least the "
                                       "radius 2 (at /surfaces/0/radius)")));
  EXPECT_THAT(SceneErrors("{\"format\": \"priormap.scene\", \"version\": 1, \"surfaces\": [],\n"
                          " \"default_pose\": [0, 5e9, 0]}"),
              ElementsAre(DiagnosticAt(2, 22, "got 5000000000 (at /default_pose/1)")));
  EXPECT_THAT(SceneErrors("{\"format\": \"priormap.scene\", \"version\": 1, \"surfaces\": [],\n"
                          " \"waypoints\": [[0, 0], [-1e20, 0]]}"),
              ElementsAre(DiagnosticAt(2, 25, "got -1e+20 (at /waypoints/1/0)")));
}

TEST(JsonMalformed, DegeneratePolylineIsReportedAtTheSurface) {
  EXPECT_THAT(SceneErrors(SceneDocument("0.5", "[[0, 0], [0, 0]]")),
              ElementsAre(DiagnosticAt(2, 3, "segment 0 has zero length (at /surfaces/0)")));
}

TEST(JsonMalformed, UnknownSurfaceTypeIsReportedAtTheType) {
  EXPECT_THAT(SceneErrors("{\"format\": \"priormap.scene\", \"version\": 1, \"surfaces\": [\n"
                          "  {\"type\": \"box\", \"size\": [1, 1]}]}"),
              ElementsAre(DiagnosticAt(2, 12,
                                       "expected a surface type (\"polyline\" or "
                                       "\"circle\"), got \"box\"")));
}

TEST(JsonMalformed, DefaultPoseWithTwoElementsIsReportedAtThePose) {
  EXPECT_THAT(SceneErrors("{\"format\": \"priormap.scene\", \"version\": 1, \"surfaces\": [],\n"
                          " \"default_pose\": [1, 2]}"),
              ElementsAre(DiagnosticAt(2, 18, "expected the default pose as [x, y, theta]")));
}

// ---- files ----

TEST(JsonMalformed, FileErrorsNameTheFile) {
  const testing::TempDir dir;
  const std::filesystem::path path = dir / "missing.json";
  EXPECT_THAT(ReadJsonLog(path).diagnostics(),
              ElementsAre(AllOf(Field(&Diagnostic::file, path.string()),
                                Field(&Diagnostic::message, HasSubstr("no such file")))));
  testing::WriteAll(dir / "bad.json", kLogWithUnknownRecord);
  EXPECT_THAT(ReadJsonLog(dir / "bad.json").diagnostics(),
              ElementsAre(AllOf(Field(&Diagnostic::file, (dir / "bad.json").string()),
                                Field(&Diagnostic::line, 3), Field(&Diagnostic::col, 10))));
  testing::WriteAll(dir / "bad-scene.json", SceneDocument("0"));
  EXPECT_THAT(ReadJsonScene(dir / "bad-scene.json").diagnostics(),
              ElementsAre(AllOf(Field(&Diagnostic::file, (dir / "bad-scene.json").string()),
                                Field(&Diagnostic::line, 3), Field(&Diagnostic::col, 50))));
}

// ---- no input makes the readers throw ----

template <typename T>
void CheckDiagnosticsPointIntoText(const Result<T>& result, const std::string& text) {
  if (result.ok()) return;
  const std::vector<std::string> lines = Lines(text);
  RC_ASSERT(!result.diagnostics().empty());
  for (const Diagnostic& d : result.diagnostics()) {
    RC_ASSERT(d.file == kName);
    RC_ASSERT(!d.message.empty());
    RC_ASSERT(d.line >= 0);
    RC_ASSERT(d.line <= static_cast<int>(lines.size()));
    if (d.line > 0) {
      RC_ASSERT(d.col >= 1);
      RC_ASSERT(d.col <= static_cast<int>(lines[static_cast<std::size_t>(d.line - 1)].size()) + 1);
    }
  }
}

void CheckReadersAreWellBehaved(const std::string& text) {
  try {
    CheckDiagnosticsPointIntoText(ParseJsonLog(text, kName), text);
    CheckDiagnosticsPointIntoText(ParseJsonScene(text, kName), text);
  } catch (const std::exception& e) {
    RC_FAIL(std::string("exception: ") + e.what());
  }
}

// Valid documents with a few bytes deleted, duplicated or replaced by JSON-ish fragments.
RC_GTEST_PROP(JsonMalformed, MutatedDocumentsNeverThrow, ()) {
  const std::vector<std::string> documents = {
      ScanDocument(), SceneDocument(), kLogWithUnknownRecord,
      R"({"format": "priormap.scan", "version": 1, "pose": [0, 0, 0], "angle_min": -1,
          "angle_increment": 0.5, "ranges": [1, null, "inf", 2], "status": ["valid", "invalid",
          "invalid", "max_range"], "precision": {"bandwidth": 1, "bands": [[1, 1, 1, 1],
          [0.1, 0.1, 0.1, 0]]}, "true_range": [1, 1, 1, 1], "true_alpha": [0, 0, 0, 0],
          "true_surface": [0, 0, 0, 0], "true_region": [1, 1, 1, 1], "true_outlier": [0, 1, 0, 0],
          "carmen": {"host": "h", "remissions": [1]}})"};
  const std::vector<std::string> fragments = {"{",
                                              "}",
                                              "[",
                                              "]",
                                              ",",
                                              ":",
                                              "\"",
                                              "null",
                                              "1e400",
                                              "-1",
                                              "0",
                                              "\"inf\"",
                                              "\"x\"",
                                              "[]",
                                              "{}",
                                              "\\u0000",
                                              "\\",
                                              "\n",
                                              "\xff",
                                              "true",
                                              "\"format\"",
                                              "1.5e-400",
                                              "9223372036854775808"};
  std::string text = *rc::gen::elementOf(documents);
  const int edits = *rc::gen::inRange(1, 4);
  for (int e = 0; e < edits; ++e) {
    const std::size_t at = *rc::gen::inRange<std::size_t>(0, text.size() + 1);
    const std::size_t length = std::min(*rc::gen::inRange<std::size_t>(0, 6), text.size() - at);
    switch (*rc::gen::inRange(0, 3)) {
      case 0:
        text.erase(at, length);
        break;
      case 1:
        text.insert(at, text.substr(at, length));
        break;
      default:
        text.replace(at, length, *rc::gen::elementOf(fragments));
        break;
    }
  }
  RC_LOG() << text;
  CheckReadersAreWellBehaved(text);
}

RC_GTEST_PROP(JsonMalformed, ArbitraryTextNeverThrows, (const std::string& text)) {
  CheckReadersAreWellBehaved(text);
  CheckReadersAreWellBehaved("{\"format\": \"priormap.log\", \"version\": 1, \"records\": [" +
                             text);
}

}  // namespace
}  // namespace priormap
