// CSM's laser_data JSON (ParseCsmLog, docs/formats.md): each object of the stream becomes a scan
// with the pose, angles, readings and statuses its fields say; the stream may be concatenated or
// one object per line; the format is sniffed; bad input is one Diagnostic at file:line:col.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <priormap/core/csm_io.hpp>
#include <priormap/core/file_io.hpp>
#include <priormap/core/json_io.hpp>
#include <priormap/core/log_io.hpp>

#include "testing/diagnostic_matchers.hpp"
#include "testing/log_equality.hpp"
#include "testing/temp_dir.hpp"

namespace priormap {
namespace {

using ::testing::ElementsAre;
using ::testing::Matcher;

constexpr const char* kName = "scans.json";
constexpr const char* kOmit = "<omit>";
constexpr double kInf = std::numeric_limits<double>::infinity();

// A laser_data object of 3 rays, one member per line; the value of `key` is replaced by `value`
// (kOmit leaves the member out). Line k + 2 holds member k, whose value starts at column
// 7 + the length of its key: nrays 2:12, min_theta 3:16, max_theta 4:16, theta 5:12,
// readings 6:15, valid 7:12, odometry 8:15, estimate 9:15, true_pose 10:16, timestamp 11:16.
std::string Document(const std::string& key = "", const std::string& value = "") {
  const std::vector<std::pair<std::string, std::string>> members = {
      {"nrays", "3"},
      {"min_theta", "-1"},
      {"max_theta", "1"},
      {"theta", "[-1, 0, 1]"},
      {"readings", "[1, 2, 3]"},
      {"valid", "[1, 1, 1]"},
      {"odometry", "[0, 0, 0]"},
      {"estimate", "[1, 2, 0.5]"},
      {"true_pose", "[null, null, null]"},
      {"timestamp", "[10, 500000]"}};
  std::string text = "{";
  bool first = true;
  for (const auto& [k, v] : members) {
    if (k == key && value == kOmit) continue;
    text += first ? "\n" : ",\n";
    text += "  \"" + k + "\": " + (k == key ? value : v);
    first = false;
  }
  return text + "\n}\n";
}

// A valid object on one line.
constexpr const char* kOneLine =
    R"({"nrays": 2, "min_theta": 0, "max_theta": 1, "readings": [1, 2], "odometry": [0, 0, 0]})";

Log Parse(const std::string& text, const CsmReadOptions& options = {}) {
  Result<Log> read = ParseCsmLog(text, kName, options);
  EXPECT_TRUE(read.ok()) << read.error() << "\n" << text;
  return read.ok() ? std::move(read).value() : Log{};
}

std::vector<Diagnostic> Errors(const std::string& text) {
  const Result<Log> read = ParseCsmLog(text, kName);
  EXPECT_FALSE(read.ok()) << "parsed without error:\n" << text;
  return read.diagnostics();
}

// A pose as (x, y, theta), for comparisons.
std::array<double, 3> Xyt(const Se2& pose) {
  return {pose.x(), pose.y(), pose.theta()};
}

Matcher<const Diagnostic&> DiagnosticAt(int line, int col, const std::string& message_part) {
  return testing::DiagnosticAt(kName, line, col, message_part);
}

// ---- values ----

TEST(CsmLog, ReadsTheKnownValuesOfAScan) {
  const Log log = Parse(Document());
  ASSERT_EQ(log.scans.size(), 1u);
  const Scan& scan = log.scans[0];
  EXPECT_EQ(scan.channel, "CSM");
  EXPECT_EQ(scan.angles, (std::vector<double>{-1, 0, 1}));
  EXPECT_EQ(scan.ranges, (std::vector<double>{1, 2, 3}));
  EXPECT_EQ(scan.sigma, (std::vector<double>{0.01, 0.01, 0.01}));
  EXPECT_EQ(scan.status, std::vector<BeamStatus>(3, BeamStatus::kValid));
  EXPECT_EQ(scan.min_range, 0.0);
  EXPECT_EQ(scan.max_range, kInf);
  EXPECT_EQ(scan.timestamp, 10.5);
  // true_pose is [null, null, null], CSM's "unknown": the pose is the estimate.
  EXPECT_EQ(Xyt(scan.pose), Xyt(Se2(1, 2, 0.5)));
  ASSERT_TRUE(scan.odom_pose);
  EXPECT_EQ(Xyt(*scan.odom_pose), Xyt(Se2(0, 0, 0)));
  EXPECT_FALSE(scan.robot_pose);
  EXPECT_EQ(log.pose_source, PoseSource::kCorrected);
  EXPECT_TRUE(log.Problems().empty());
}

TEST(CsmLog, PoseIsTheTruePoseElseTheEstimateElseTheOdometry) {
  Log log = Parse(Document("true_pose", "[3, 4, -0.25]"));
  EXPECT_EQ(Xyt(log.scans.at(0).pose), Xyt(Se2(3, 4, -0.25)));
  EXPECT_EQ(log.pose_source, PoseSource::kGroundTruth);

  log = Parse(Document("estimate", "[null, null, null]"));
  EXPECT_EQ(Xyt(log.scans.at(0).pose), Xyt(Se2(0, 0, 0)));
  EXPECT_EQ(log.pose_source, PoseSource::kOdometry);

  log = Parse(Document("odometry", kOmit));
  EXPECT_EQ(Xyt(log.scans.at(0).pose), Xyt(Se2(1, 2, 0.5)));
  EXPECT_FALSE(log.scans.at(0).odom_pose);
  EXPECT_EQ(log.pose_source, PoseSource::kCorrected);
}

TEST(CsmLog, OneKindOfPoseForTheWholeLogWhenEveryScanHasIt) {
  // The second scan has no estimate: both take their odometry.
  Log log = Parse(Document() + Document("estimate", "null"));
  ASSERT_EQ(log.scans.size(), 2u);
  EXPECT_EQ(log.pose_source, PoseSource::kOdometry);
  EXPECT_EQ(Xyt(log.scans[0].pose), Xyt(Se2(0, 0, 0)));
  EXPECT_EQ(Xyt(log.scans[1].pose), Xyt(Se2(0, 0, 0)));

  // No kind in both: each scan takes the first it has, and the log cannot say which.
  log = Parse(Document("odometry", kOmit) + Document("estimate", kOmit));
  EXPECT_EQ(log.pose_source, PoseSource::kUnknown);
  EXPECT_EQ(Xyt(log.scans.at(0).pose), Xyt(Se2(1, 2, 0.5)));
  EXPECT_EQ(Xyt(log.scans.at(1).pose), Xyt(Se2(0, 0, 0)));
}

TEST(CsmLog, NullFlaggedAndOutOfRangeReadingsAreNotValid) {
  const std::string text = Document("readings", "[null, 2, 3]") + Document("valid", "[1, 0, 1]") +
                           Document("readings", "[-1, \"nan\", 0]") +
                           Document("readings", "[0.05, 2, 30]");
  CsmReadOptions options;
  options.min_range = 0.1;
  options.max_range = 20.0;
  const Log log = Parse(text, options);
  ASSERT_EQ(log.scans.size(), 4u);
  using S = BeamStatus;
  // null is NaN, kept as read.
  EXPECT_TRUE(std::isnan(log.scans[0].ranges[0]));
  EXPECT_EQ(log.scans[0].status, (std::vector<S>{S::kInvalid, S::kValid, S::kValid}));
  // valid 0: invalid whatever the value, which is kept.
  EXPECT_EQ(log.scans[1].ranges[1], 2.0);
  EXPECT_EQ(log.scans[1].status, (std::vector<S>{S::kValid, S::kInvalid, S::kValid}));
  EXPECT_EQ(log.scans[2].status, (std::vector<S>{S::kInvalid, S::kInvalid, S::kInvalid}));
  // Below min_range, at or above max_range.
  EXPECT_EQ(log.scans[3].status, (std::vector<S>{S::kInvalid, S::kValid, S::kMaxRange}));
  EXPECT_EQ(log.scans[3].min_range, 0.1);
  EXPECT_EQ(log.scans[3].max_range, 20.0);
}

TEST(CsmLog, WithoutValidEveryReadingIsClassifiedByItsValue) {
  const Log log = Parse(Document("valid", kOmit) + Document("readings", "[1, null, -2]"));
  EXPECT_EQ(log.scans.at(0).status, std::vector<BeamStatus>(3, BeamStatus::kValid));
  EXPECT_EQ(
      log.scans.at(1).status,
      (std::vector<BeamStatus>{BeamStatus::kValid, BeamStatus::kInvalid, BeamStatus::kInvalid}));
}

TEST(CsmLog, ReadingsSigmaGivesTheNoiseOfEachReading) {
  CsmReadOptions options;
  options.sigma = 0.05;
  const Log log =
      Parse(Document("valid", "[1, 1, 1],\n  \"readings_sigma\": [0.02, null, 0.03]"), options);
  EXPECT_EQ(log.scans.at(0).sigma, (std::vector<double>{0.02, 0.05, 0.03}));
}

TEST(CsmLog, WithoutThetaTheAnglesGoFromMinThetaToMaxTheta) {
  for (const std::string& theta : {std::string(kOmit), std::string("[null, null, null]")}) {
    const Log log = Parse(Document("theta", theta) + kOneLine);
    ASSERT_EQ(log.scans.size(), 2u);
    EXPECT_EQ(log.scans[0].angles, (std::vector<double>{-1, 0, 1})) << theta;
    EXPECT_EQ(log.scans[1].angles, (std::vector<double>{0, 1}));
  }
  // theta, when given, wins over min_theta / max_theta.
  const Log log = Parse(Document("theta", "[-0.5, 0, 0.25]"));
  EXPECT_EQ(log.scans.at(0).angles, (std::vector<double>{-0.5, 0, 0.25}));
}

TEST(CsmLog, ObjectsMayBeConcatenatedOrOnePerLine) {
  const std::string one(kOneLine);
  for (const std::string& text :
       {one + one + one, one + "\n" + one + "\n" + one + "\n", one + "\r\n\r\n" + one + " \t" + one,
        Document() + one + "\n" + Document()}) {
    const Log log = Parse(text);
    EXPECT_EQ(log.scans.size(), 3u) << text;
  }
  // Strings holding braces do not end an object early.
  const Log log = Parse(Document("estimate", "[1, 2, 0.5], \"note\": \"}{ \\\" }\"") + one);
  EXPECT_EQ(log.scans.size(), 2u);
}

TEST(CsmLog, IgnoresTheFieldsItDoesNotInterpret) {
  const Log log = Parse(Document(
      "valid",
      "[1, 1, 1], \"cluster\": [0, 0, -1], \"alpha\": [0.1, null, 0.2], \"cov_alpha\": [1, 1, 1], "
      "\"alpha_valid\": [1, 0, 1], \"true_alpha\": [null, null, null], \"cov_readings\": [1, 1, "
      "1], "
      "\"corr\": [null, {\"j1\": 0, \"j2\": 1, \"type\": 0}, null], \"points\": \"x\""));
  EXPECT_EQ(log.scans.at(0).ranges, (std::vector<double>{1, 2, 3}));
}

// ---- sniffing and files ----

TEST(CsmLog, IsSniffedByItsNraysAndReadings) {
  EXPECT_EQ(SniffLogFormat(Document()), LogFormat::kCsm);
  EXPECT_EQ(SniffLogFormat(std::string("\n ") + kOneLine), LogFormat::kCsm);
  // priormap's own documents, and objects without both members, are priormap JSON.
  EXPECT_EQ(SniffLogFormat(FormatJsonLog(Parse(Document()))), LogFormat::kJson);
  EXPECT_EQ(SniffLogFormat(R"({"format": "priormap.scan", "nrays": 1, "readings": []})"),
            LogFormat::kJson);
  EXPECT_EQ(SniffLogFormat(R"({"nrays": 3, "ranges": [1, 2, 3]})"), LogFormat::kJson);
  EXPECT_EQ(SniffLogFormat(R"({"x": {"nrays": 3, "readings": [1]}})"), LogFormat::kJson);
  EXPECT_EQ(SniffLogFormat("{"), LogFormat::kJson);
  EXPECT_EQ(SniffLogFormat("FLASER 1 1.0 0 0 0 0 0 0\n"), LogFormat::kCarmen);
  EXPECT_EQ(LogFormatFromString("csm"), LogFormat::kCsm);
  EXPECT_STREQ(ToString(LogFormat::kCsm), "csm");
}

// The same three scans converted to our JSON log and to CARMEN (examples/formats/): every
// format's example reads back to the same readings.
TEST(FormatExamples, TheLogExamplesHoldTheSameReadings) {
  const std::filesystem::path dir = PRIORMAP_EXAMPLES_DIR "/formats";
  const Result<Log> csm = ReadLog(dir / "csm-laser-data.json");
  ASSERT_TRUE(csm.ok()) << csm.error();
  for (const char* name : {"log.json", "log.carmen"}) {
    const Result<Log> other = ReadLog(dir / name);
    ASSERT_TRUE(other.ok()) << name << ": " << other.error();
    ASSERT_EQ(other.value().scans.size(), csm.value().scans.size()) << name;
    for (std::size_t k = 0; k < csm.value().scans.size(); ++k) {
      const Scan& a = csm.value().scans[k];
      const Scan& b = other.value().scans[k];
      // CARMEN has no reading status: a reading CSM flags invalid but gives a value (scan 2)
      // is valid again when read back; the readings CSM calls valid come back equal.
      if (std::string(name) == "log.json") {
        EXPECT_EQ(b.NumValid(), a.NumValid()) << k;
      }
      for (std::size_t i = 0; i < a.size(); ++i) {
        if (!a.IsValid(i)) continue;
        EXPECT_TRUE(b.IsValid(i)) << name;
        EXPECT_NEAR(b.ranges[i], a.ranges[i], 1e-9) << name;
      }
    }
  }
}

TEST(CsmLog, ReadsTheExampleFile) {
  const std::filesystem::path path = PRIORMAP_EXAMPLES_DIR "/formats/csm-laser-data.json";
  const Result<Log> read = ReadLog(path);  // sniffed
  ASSERT_TRUE(read.ok()) << read.error();
  const Log& log = read.value();
  ASSERT_EQ(log.scans.size(), 3u);
  EXPECT_EQ(log.pose_source, PoseSource::kCorrected);  // true_pose null, estimate given
  std::size_t valid = 0, invalid = 0;
  for (const Scan& scan : log.scans) {
    EXPECT_EQ(scan.size(), 10u);
    EXPECT_EQ(scan.angles.front(), -std::numbers::pi / 2);
    EXPECT_EQ(scan.angles.back(), std::numbers::pi / 2);
    valid += scan.NumValid();
    invalid += static_cast<std::size_t>(
        std::count(scan.status.begin(), scan.status.end(), BeamStatus::kInvalid));
  }
  EXPECT_EQ(valid, 28u);
  EXPECT_EQ(invalid, 2u);
  EXPECT_EQ(Xyt(log.scans[1].pose), Xyt(Se2(0.2, 0.05, 0.1)));
  EXPECT_EQ(Xyt(*log.scans[1].odom_pose), Xyt(Se2(0.21, 0.04, 0.09)));
  EXPECT_EQ(log.scans[1].timestamp, 1200000001.25);
  // What priormap JSON makes of it reads back the same.
  const Result<Log> again = ParseJsonLog(FormatJsonLog(log), "again.json");
  ASSERT_TRUE(again.ok()) << again.error();
  EXPECT_TRUE(testing::SameLog(again.value(), log));
  // Forced, and through the CSM reader itself.
  const Result<Log> forced = ReadLog(path, LogFormat::kCsm);
  ASSERT_TRUE(forced.ok()) << forced.error();
  EXPECT_TRUE(testing::SameLog(forced.value(), log));
  const Result<Log> direct = ReadCsmLog(path);
  ASSERT_TRUE(direct.ok()) << direct.error();
  EXPECT_TRUE(testing::SameLog(direct.value(), log));
}

TEST(CsmLog, IsReadOnly) {
  const testing::TempDir dir;
  EXPECT_THROW(WriteLog(Parse(Document()), dir / "out.json", LogFormat::kCsm), IoError);
  EXPECT_TRUE(testing::FilesIn(dir.path()).empty());
}

// ---- malformed input ----

TEST(CsmLogMalformed, DocumentsUsedBelowAreValidAsGiven) {
  EXPECT_TRUE(ParseCsmLog(Document(), kName).ok());
  EXPECT_TRUE(ParseCsmLog(kOneLine, kName).ok());
}

TEST(CsmLogMalformed, NotJsonIsLocatedAtTheOffendingCharacter) {
  // The parser reads "nr" as the start of a literal and stops at the 'r' (as for priormap JSON).
  EXPECT_THAT(Errors("{nrays: 3}"),
              ElementsAre(DiagnosticAt(1, 3,
                                       "invalid JSON: syntax error while parsing object "
                                       "key - invalid literal; last read: '{nr'")));
  EXPECT_THAT(Errors(Document("readings", "[1, 2, 3,]")),
              ElementsAre(DiagnosticAt(6, 24, "invalid JSON")));
}

TEST(CsmLogMalformed, OnlyObjectsMayFollowEachOther) {
  EXPECT_THAT(Errors(std::string(kOneLine) + "\n  x y\n"),
              ElementsAre(DiagnosticAt(2, 3,
                                       "expected a CSM laser_data object ('{') or the end "
                                       "of the input, got 'x y'")));
  EXPECT_THAT(Errors(std::string("[") + kOneLine + "]"),
              ElementsAre(DiagnosticAt(1, 1, "expected a CSM laser_data object")));
  EXPECT_THAT(Errors(std::string(kOneLine) + ","), ElementsAre(DiagnosticAt(1, 88, "got ','")));
}

TEST(CsmLogMalformed, EmptyInputHasNoScans) {
  EXPECT_THAT(Errors(""), ElementsAre(DiagnosticAt(1, 1, "no CSM laser_data objects")));
  EXPECT_THAT(Errors("\n \n"), ElementsAre(DiagnosticAt(3, 1, "no CSM laser_data objects")));
}

TEST(CsmLogMalformed, TruncatedObjectIsLocatedAtTheEnd) {
  EXPECT_THAT(Errors(std::string(kOneLine) + "\n{\"nrays\": 2, "),
              ElementsAre(DiagnosticAt(2, 14, "unexpected end of input")));
}

TEST(CsmLogMalformed, MissingOrBadNrays) {
  EXPECT_THAT(Errors(Document("nrays", kOmit)),
              ElementsAre(DiagnosticAt(1, 1, "missing key \"nrays\"")));
  EXPECT_THAT(Errors(Document("nrays", "\"3\"")),
              ElementsAre(DiagnosticAt(2, 12,
                                       "expected \"nrays\" (an integer), got the string \"3\" "
                                       "(at /nrays)")));
  EXPECT_THAT(Errors(Document("nrays", "2.5")),
              ElementsAre(DiagnosticAt(2, 12, "expected \"nrays\" (an integer)")));
  EXPECT_THAT(Errors(Document("nrays", "0")),
              ElementsAre(DiagnosticAt(2, 12, "expected \"nrays\" in [1, 2147483647], got 0")));
}

TEST(CsmLogMalformed, ArraysOfTheWrongLengthAreReportedAtTheArray) {
  EXPECT_THAT(Errors(Document("readings", "[1, 2]")),
              ElementsAre(DiagnosticAt(6, 15,
                                       "expected nrays = 3 values in \"readings\", got 2 "
                                       "(at /readings)")));
  EXPECT_THAT(Errors(Document("nrays", "4")),
              ElementsAre(DiagnosticAt(6, 15, "expected nrays = 4 values in \"readings\", got 3")));
  EXPECT_THAT(Errors(Document("theta", "[0, 1]")),
              ElementsAre(DiagnosticAt(5, 12, "expected nrays = 3 values in \"theta\", got 2")));
  EXPECT_THAT(Errors(Document("valid", "[1, 1, 1, 1]")),
              ElementsAre(DiagnosticAt(7, 12, "expected nrays = 3 values in \"valid\", got 4")));
  EXPECT_THAT(Errors(Document("readings", "{\"0\": 1}")),
              ElementsAre(DiagnosticAt(6, 15, "expected \"readings\" (an array), got an object")));
}

TEST(CsmLogMalformed, NonNumericValuesAreReportedAtTheElement) {
  EXPECT_THAT(Errors(Document("readings", "[1, \"two\", 3]")),
              ElementsAre(DiagnosticAt(6, 19,
                                       "expected an element of \"readings\" (a number), got the "
                                       "string \"two\" (at /readings/1)")));
  EXPECT_THAT(Errors(Document("theta", "[-1, null, 1]")),
              ElementsAre(DiagnosticAt(5, 17,
                                       "expected an element of \"theta\" (a finite number), got "
                                       "null (at /theta/1)")));
  EXPECT_THAT(
      Errors(Document("valid", "[1, 2, 1]")),
      ElementsAre(DiagnosticAt(7, 16, "expected an element of \"valid\" in [0, 1], got 2")));
  EXPECT_THAT(Errors(Document("valid", "[1, true, 1]")),
              ElementsAre(DiagnosticAt(7, 16, "expected an element of \"valid\" (an integer)")));
  // min_theta is read only without theta.
  EXPECT_TRUE(ParseCsmLog(Document("min_theta", "\"-90deg\""), kName).ok());
  EXPECT_THAT(
      Errors(
          R"({"nrays": 1, "min_theta": "-90deg", "max_theta": 1, "readings": [1], "odometry": [0, 0, 0]})"),
      ElementsAre(DiagnosticAt(1, 27,
                               "expected \"min_theta\" (a number), got the string \"-90deg\" "
                               "(at /min_theta)")));
}

TEST(CsmLogMalformed, AnglesMustIncreaseAndBeGiven) {
  EXPECT_THAT(Errors(Document("theta", "[-1, 1, 0]")),
              ElementsAre(DiagnosticAt(5, 20,
                                       "expected increasing angles in \"theta\", got 0 "
                                       "after 1 (at /theta/2)")));
  EXPECT_THAT(
      Errors(
          R"({"nrays": 3, "min_theta": 1, "max_theta": 1, "readings": [1, 2, 3], "odometry": [0, 0, 0]})"),
      ElementsAre(DiagnosticAt(1, 43,
                               "expected \"max_theta\" above \"min_theta\" = 1, got 1 "
                               "(at /max_theta)")));
  // One ray needs no spread of angles.
  EXPECT_TRUE(
      ParseCsmLog(
          R"({"nrays": 1, "min_theta": 1, "max_theta": 1, "readings": [1], "odometry": [0, 0, 0]})",
          kName)
          .ok());
  EXPECT_THAT(
      Errors(R"({"nrays": 1, "readings": [1], "odometry": [0, 0, 0]})"),
      ElementsAre(DiagnosticAt(1, 1, "expected \"theta\", or \"min_theta\" and \"max_theta\"")));
}

TEST(CsmLogMalformed, PosesMustBeThreeNumbersOrUnknown) {
  EXPECT_THAT(Errors(Document("estimate", "[1, 2]")),
              ElementsAre(DiagnosticAt(9, 15,
                                       "expected \"estimate\" as [x, y, theta], got 2 values "
                                       "(at /estimate)")));
  EXPECT_THAT(Errors(Document("true_pose", "[1, null, 0]")),
              ElementsAre(DiagnosticAt(10, 16,
                                       "expected \"true_pose\" as [x, y, theta] of finite "
                                       "numbers, or [null, null, null] when unknown")));
  EXPECT_THAT(Errors(Document("odometry", "[0, \"0\", 0]")),
              ElementsAre(DiagnosticAt(8, 19, "expected \"odometry\" y (a number)")));
  EXPECT_THAT(
      Errors(R"({"nrays": 1, "theta": [0], "readings": [1], "estimate": [null, null, null]})"),
      ElementsAre(DiagnosticAt(1, 1,
                               "no pose: expected \"true_pose\", \"estimate\" or "
                               "\"odometry\" as [x, y, theta]")));
}

TEST(CsmLogMalformed, APositionBeyondTheWorldIsReportedAtTheCoordinate) {
  EXPECT_THAT(Errors(Document("odometry", "[0, 1e300, 0]")),
              ElementsAre(DiagnosticAt(8, 19,
                                       "expected \"odometry\" y in metres of a local frame, at "
                                       "most 1e+09 in magnitude, got 1e+300 (at /odometry/1)")));
  EXPECT_THAT(Errors(Document("estimate", "[-5e9, 0, 0]")),
              ElementsAre(DiagnosticAt(9, 16, "expected \"estimate\" x in metres")));
}

// A valid reading of 1e300 was read as a return 1e300 m away, and only `priormap plot` refused
// the file, naming no position: it is reported at the reading. Flagged invalid or at or above
// the caller's max range, it is kept as read.
TEST(CsmLogMalformed, AReturnLongerThanTheWorldsBoundIsReportedAtTheReading) {
  EXPECT_THAT(Errors(Document("readings", "[1, 1e300, 3]")),
              ElementsAre(DiagnosticAt(6, 19,
                                       "expected an element of \"readings\" in metres, at most "
                                       "1e+09 for a return or at or above the max range (inf m) "
                                       "for no return, got 1e+300 (at /readings/1)")));
  std::string flagged_document = Document("readings", "[1, 1e300, 3]");
  flagged_document.replace(flagged_document.find("[1, 1, 1]"), 9, "[1, 0, 1]");
  const Log flagged = Parse(flagged_document);
  ASSERT_EQ(flagged.scans.size(), 1U);
  EXPECT_EQ(flagged.scans[0].ranges[1], 1e300);
  CsmReadOptions options;
  options.max_range = 30.0;
  const Log beyond = Parse(Document("readings", "[1, 1e300, 3]"), options);
  ASSERT_EQ(beyond.scans.size(), 1U);
  EXPECT_EQ(beyond.scans[0].status[1], BeamStatus::kMaxRange);
}

TEST(CsmLogMalformed, BadSigmaOrTimestamp) {
  EXPECT_THAT(Errors(Document("valid", "[1, 1, 1], \"readings_sigma\": [0.1, -0.1, 0.1]")),
              ElementsAre(DiagnosticAt(7, 47,
                                       "expected an element of \"readings_sigma\" (a standard "
                                       "deviation > 0, m, or null), got -0.1")));
  EXPECT_THAT(
      Errors(Document("timestamp", "[1, 2, 3]")),
      ElementsAre(DiagnosticAt(11, 16, "expected \"timestamp\" as [seconds, microseconds]")));
}

TEST(CsmLogMalformed, ErrorsInLaterObjectsCountLinesAndColumnsFromTheStartOfTheFile) {
  // Columns of the bad object: "readings" value at 26.
  const std::string bad = R"({"nrays": 2, "readings": [1, 2, 3], "odometry": [0, 0, 0]})";
  const std::string one(kOneLine);
  EXPECT_THAT(Errors(one + "\n\n" + bad + "\n"),
              ElementsAre(DiagnosticAt(3, 26, "expected nrays = 2 values in \"readings\"")));
  EXPECT_THAT(Errors(one + " " + bad),
              ElementsAre(DiagnosticAt(1, static_cast<int>(one.size()) + 1 + 26,
                                       "expected nrays = 2 values in \"readings\"")));
  EXPECT_THAT(Errors(one + "\n   " + R"({"nrays": 2, "theta": [0, 1], "readings": [1, 2]})"),
              ElementsAre(DiagnosticAt(2, 4, "no pose")));
  // A value under a key written with escapes is located too (the key is decoded to match).
  EXPECT_THAT(Errors(one + "\n  " + R"({"nrays": 2, "re\u0061dings": [1], "odometry": [0, 0, 0]})"),
              ElementsAre(DiagnosticAt(2, 33, "expected nrays = 2 values in \"readings\"")));
}

TEST(CsmLogMalformed, ReadLogNamesTheFile) {
  const testing::TempDir dir;
  testing::WriteAll(dir / "scans.json", std::string(kOneLine) + "\n{\"nrays\": 1}\n");
  const Result<Log> read = ReadLog(dir / "scans.json");
  EXPECT_THAT(read.diagnostics(), ElementsAre(testing::DiagnosticAt((dir / "scans.json").string(),
                                                                    2, 1, "missing key")));
}

TEST(CsmLogMalformed, BadOptionsAreReported) {
  CsmReadOptions options;
  options.max_range = 0.0;
  EXPECT_FALSE(ParseCsmLog(kOneLine, kName, options).ok());
  options = {};
  options.sigma = 0.0;
  EXPECT_FALSE(ParseCsmLog(kOneLine, kName, options).ok());
}

}  // namespace
}  // namespace priormap
