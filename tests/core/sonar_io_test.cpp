// Sonar logs on disk: our JSON keeps every sonar field through a round trip and rejects bad
// ones at file:line:col; the RoboND sonar files are read with their units converted, their bad
// lines reported at file:line:col, and the real files in ../shared/data read as documented.
#include <cmath>
#include <numbers>
#include <string>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/json_io.hpp>
#include <priormap/core/robond_sonar_io.hpp>
#include <priormap/core/sonar_simulate.hpp>

#include "testing/diagnostic_matchers.hpp"
#include "testing/temp_dir.hpp"

namespace priormap {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

TEST(SonarJson, ASimulatedSonarLogRoundTripsWithItsFieldsAndTruth) {
  const Scene scene = *BuiltinScene("l-office");
  const SonarSensor sensor = *SonarSensor::Preset("pioneer8");
  const auto trajectory = TrajectoryFromWaypoints(scene.waypoints, 1.0, 1.0);
  const Log log = SimulateSonarLog(scene, sensor, trajectory, 4);
  const std::string json = FormatJsonLog(log);
  const Result<Log> read = ParseJsonLog(json, "sonar.json");
  ASSERT_TRUE(read.ok()) << read.error();
  ASSERT_EQ(read.value().scans.size(), log.scans.size());
  for (std::size_t k = 0; k < log.scans.size(); ++k) {
    const Scan& a = log.scans[k];
    const Scan& b = read.value().scans[k];
    ASSERT_TRUE(b.sonar);
    EXPECT_EQ(b.sonar->spread, a.sonar->spread);
    EXPECT_EQ(b.sonar->origins, a.sonar->origins);
    EXPECT_EQ(b.sonar->true_echo, a.sonar->true_echo);
    EXPECT_EQ(b.sonar->true_feature, a.sonar->true_feature);
    EXPECT_EQ(b.ranges, a.ranges);
    EXPECT_EQ(b.angles, a.angles);
  }
  EXPECT_EQ(FormatJsonLog(read.value()), json);
}

constexpr const char* kName = "sonar.json";

// A ring of two readings, one member per line; `sonar` is the value of its "sonar" member,
// which starts on line 9 at column 12.
std::string RingDocument(const std::string& sonar) {
  return "{\n"
         "  \"format\": \"priormap.scan\",\n"
         "  \"version\": 1,\n"
         "  \"pose\": [0, 0, 0],\n"
         "  \"angles\": [0.5, -0.5],\n"
         "  \"ranges\": [1, 2],\n"
         "  \"sigma\": 0.01,\n"
         "  \"max_range\": 5,\n"
         "  \"sonar\": " +
         sonar +
         "\n"
         "}\n";
}

std::vector<Diagnostic> Errors(const std::string& text) {
  const Result<Log> result = ParseJsonLog(text, kName);
  EXPECT_FALSE(result.ok()) << "parsed without error:\n" << text;
  return result.diagnostics();
}

TEST(SonarJson, ReadsARingAndRejectsBadSonarFieldsWhereTheyAre) {
  const Result<Log> ok =
      ParseJsonLog(RingDocument("{\"spread\": 0.3, \"origins\": [[0.1, 0], [0.1, 0.2]]}"), kName);
  ASSERT_TRUE(ok.ok()) << ok.error();
  const Scan& ring = ok.value().scans[0];
  ASSERT_TRUE(ring.sonar);
  EXPECT_EQ(ring.sonar->spread, 0.3);
  EXPECT_EQ(ring.sonar->Origin(1), Vec2(0.1, 0.2));  // angles need not increase in a ring

  using testing::DiagnosticAt;
  EXPECT_THAT(Errors(RingDocument("{\"spread\": 3.5}")),
              ElementsAre(DiagnosticAt(kName, 9, 23, "full angle in (0, pi)")));
  EXPECT_THAT(Errors(RingDocument("{\"spread\": \"wide\"}")),
              ElementsAre(DiagnosticAt(kName, 9, 23, "spread")));
  EXPECT_THAT(Errors(RingDocument("{}")), ElementsAre(DiagnosticAt(kName, 9, 12, "spread")));
  EXPECT_THAT(Errors(RingDocument("{\"spread\": 0.3, \"origins\": [[0, 0]]}")),
              ElementsAre(DiagnosticAt(kName, 9, 39, "2 transducer origins")));
  EXPECT_THAT(Errors(RingDocument("{\"spread\": 0.3, \"origins\": [[0, 0], [0, \"x\"]]}")),
              ElementsAre(DiagnosticAt(kName, 9, 52, "expected y")));
  EXPECT_THAT(
      Errors(RingDocument(
          "{\"spread\": 0.3, \"true_echo\": [\"surface\", \"echo\"], \"true_feature\": [0, 1]}")),
      ElementsAre(DiagnosticAt(kName, 9, 53, "sonar echo kind")));
  EXPECT_THAT(Errors(RingDocument("{\"spread\": 0.3, \"true_echo\": [\"none\", \"none\"]}")),
              ElementsAre(DiagnosticAt(kName, 9, 12, "both")));
  EXPECT_THAT(
      Errors(RingDocument(
          "{\"spread\": 0.3, \"true_echo\": [\"none\", \"none\"], \"true_feature\": [0, -2]}")),
      ElementsAre(DiagnosticAt(kName, 9, 79, "true_feature")));
}

TEST(RoboNdSonar, ConvertsMillimetresTenthsOfDegreesAndTheNoEchoCode) {
  const std::string z = "100 5110 5110 2320 2360 5110 150 2160 1190\r\n200 1 2 3 4 5 6 7 8\n";
  const std::string p = "100 0 0 0\n\n200 1500 -250 3556\n";
  const Result<Log> read = ParseRoboNdSonar(z, "m.txt", p, "p.txt");
  ASSERT_TRUE(read.ok()) << read.error();
  const Log& log = read.value();
  ASSERT_EQ(log.scans.size(), 2u);
  const Scan& first = log.scans[0];
  EXPECT_TRUE(first.Problems().empty());
  ASSERT_TRUE(first.sonar);
  EXPECT_NEAR(first.sonar->spread, DegToRad(20.0), 1e-15);
  EXPECT_EQ(first.timestamp, 0.1);
  EXPECT_EQ(first.angles.size(), 8u);
  EXPECT_NEAR(first.angles[1], DegToRad(-37.5), 1e-15);
  EXPECT_EQ(first.ranges[3], 2.36);
  EXPECT_EQ(first.status[0], BeamStatus::kMaxRange);
  EXPECT_EQ(first.status[5], BeamStatus::kInvalid);  // 150 mm is below the 170 mm minimum
  EXPECT_EQ(first.status[7], BeamStatus::kValid);
  const Scan& second = log.scans[1];
  EXPECT_EQ(second.pose.x(), 1.5);
  EXPECT_EQ(second.pose.y(), -0.25);
  EXPECT_NEAR(second.pose.theta(), DegToRad(355.6 - 360.0), 1e-12);
}

// Both files with a byte order mark (a Windows editor's): the time of the first line was
// "'\xef\xbb\xbf100'", not a number, where the laser readers skip the mark.
TEST(RoboNdSonar, AByteOrderMarkIsSkippedAndColumnsCountFromAfterIt) {
  const std::string bom = "\xef\xbb\xbf";
  const std::string z = "100 5110 5110 2320 2360 5110 150 2160 1190\n";
  const std::string p = "100 0 0 0\n";
  const Result<Log> plain = ParseRoboNdSonar(z, "m.txt", p, "p.txt");
  const Result<Log> marked = ParseRoboNdSonar(bom + z, "m.txt", bom + p, "p.txt");
  ASSERT_TRUE(plain.ok()) << plain.error();
  ASSERT_TRUE(marked.ok()) << marked.error();
  EXPECT_EQ(marked.value().scans.at(0).ranges, plain.value().scans.at(0).ranges);
  EXPECT_EQ(marked.value().scans.at(0).timestamp, 0.1);
  EXPECT_THAT(
      ParseRoboNdSonar(bom + "100 5110 x 2320 2360 5110 150 2160 1190\n", "m.txt", p, "p.txt")
          .diagnostics(),
      ElementsAre(testing::DiagnosticAt("m.txt", 1, 10, "got 'x'")));
}

// A shorter max range makes longer readings max-range readings; their ranges stay as read, as
// the laser readers keep theirs.
TEST(RoboNdSonar, ReadingsBeyondAShorterMaxRangeKeepTheirRanges) {
  RoboNdSonarOptions options;
  options.no_echo_mm = 450.0;
  const Result<Log> read = ParseRoboNdSonar("1000 100 200 300 400 500 600 700 9000\n", "m.txt",
                                            "1000 0 0 0\n", "p.txt", options);
  ASSERT_TRUE(read.ok()) << read.error();
  const Scan& scan = read.value().scans.at(0);
  EXPECT_EQ(scan.max_range, 0.45);
  EXPECT_EQ(scan.ranges[4], 0.5);
  EXPECT_EQ(scan.ranges[7], 9.0);
  EXPECT_EQ(scan.status[4], BeamStatus::kMaxRange);
  EXPECT_EQ(scan.status[3], BeamStatus::kValid);
}

TEST(RoboNdSonar, ReportsBadLinesAtFileLineAndColumn) {
  const std::string good_z = "100 1 2 3 4 5 6 7 8\n";
  const std::string good_p = "100 0 0 0\n";
  const auto errors = [](const std::string& z, const std::string& p) {
    const Result<Log> r = ParseRoboNdSonar(z, "m.txt", p, "p.txt");
    EXPECT_FALSE(r.ok());
    return r.diagnostics();
  };
  using testing::DiagnosticAt;
  EXPECT_THAT(errors("100 1 2 3 4 5 6 7\n", good_p),
              ElementsAre(DiagnosticAt("m.txt", 1, 18, "expected 9 fields")));
  EXPECT_THAT(errors("100 1 2 3 4 5 6 7 8 9\n", good_p),
              ElementsAre(DiagnosticAt("m.txt", 1, 21, "found more")));
  EXPECT_THAT(errors("100 1 2 x 4 5 6 7 8\n", good_p),
              ElementsAre(DiagnosticAt("m.txt", 1, 9, "a range in mm")));
  EXPECT_THAT(errors("100 1 2 -3 4 5 6 7 8\n", good_p),
              ElementsAre(DiagnosticAt("m.txt", 1, 9, ">= 0")));
  EXPECT_THAT(errors("100 1 2 nan 4 5 6 7 8\n", good_p),
              ElementsAre(DiagnosticAt("m.txt", 1, 9, "finite")));
  EXPECT_THAT(errors(good_z, "  101 0 0 0\n"),
              ElementsAre(DiagnosticAt("p.txt", 1, 3, "differs from the 100 ms of m.txt:1")));
  EXPECT_THAT(errors(good_z, "100 0 0\n"),
              ElementsAre(DiagnosticAt("p.txt", 1, 8, "expected 4 fields")));
  EXPECT_THAT(errors(good_z + "200 1 2 3 4 5 6 7 8\n", good_p),
              ElementsAre(DiagnosticAt("m.txt", 2, 1, "p.txt has 1")));
  EXPECT_THAT(errors("", good_p), ElementsAre(DiagnosticAt("m.txt", 1, 1, "no measurement")));
  // A position beyond priormap's bound on world coordinates (1e9 m), at its field.
  EXPECT_THAT(errors(good_z, "100 1e300 0 0\n"),
              ElementsAre(DiagnosticAt("p.txt", 1, 5,
                                       "expected x in mm at most 1e+12 in magnitude (priormap's "
                                       "bound of 1e+09 m on world coordinates), got '1e300'")));
  EXPECT_THAT(errors(good_z, "100 0 -2e12 0\n"),
              ElementsAre(DiagnosticAt("p.txt", 1, 7, "expected y in mm at most 1e+12")));
  EXPECT_TRUE(ParseRoboNdSonar(good_z, "m.txt", "100 1e12 -1e12 0\n", "p.txt").ok());
}

// A line garbled in the middle of one file (split in two, joined to the next, or lost) is
// reported where the two files go out of step, not as a count mismatch at the end of the
// longer file, hundreds of lines from the damage.
TEST(RoboNdSonar, AGarbledLineIsReportedWhereTheFilesGoOutOfStep) {
  std::string z, p;
  for (int k = 1; k <= 5; ++k) {
    z += fmt::format("{}00 1000 1100 1200 1300 1400 1500 1600 1700\n", k);
    p += fmt::format("{}00 {}0 0 0\n", k, k);
  }
  const auto errors = [](const std::string& measurements, const std::string& poses) {
    const Result<Log> r = ParseRoboNdSonar(measurements, "m.txt", poses, "p.txt");
    EXPECT_FALSE(r.ok());
    return r.diagnostics();
  };
  using testing::DiagnosticAt;
  // Line 2 of the measurements split after its fourth field: 6 lines against 5.
  std::string split = z;
  split[split.find(" 1300", split.find("\n200 "))] = '\n';
  EXPECT_THAT(errors(split, p),
              ElementsAre(DiagnosticAt("m.txt", 2, 19, "expected 9 fields (t_ms and 8 ranges")));
  // Lines 2 and 3 of the poses joined: 4 lines against 5.
  std::string joined = p;
  joined[joined.find('\n', joined.find("\n200 ") + 1)] = ' ';
  EXPECT_THAT(errors(z, joined), ElementsAre(DiagnosticAt("p.txt", 2, 12, "expected 4 fields")));
  // Line 3 of the poses lost: line 3 is the fourth ring's pose.
  std::string lost = p;
  const std::size_t third = lost.find("\n300 ") + 1;
  lost.erase(third, lost.find('\n', third) + 1 - third);
  EXPECT_THAT(errors(z, lost), ElementsAre(DiagnosticAt("p.txt", 3, 1,
                                                        "time 400 ms differs from the 300 ms of "
                                                        "m.txt:3")));
  // Files that are only of different lengths still say so, at the first unmatched line.
  EXPECT_THAT(errors(z, p.substr(0, p.find("500 "))),
              ElementsAre(DiagnosticAt("m.txt", 5, 1, "p.txt has 4")));
}

// The sensor's no-echo code (5110 mm) keeps returns short; a caller's no-echo value beyond the
// world's bound would let a return of 1e300 mm through, as the laser readers did: it is refused
// at the reading, and a no-echo reading is kept whatever its value.
TEST(RoboNdSonar, AReturnLongerThanTheWorldsBoundIsReportedAtTheReading) {
  using testing::DiagnosticAt;
  RoboNdSonarOptions options;
  options.no_echo_mm = 1e300;
  const Result<Log> read =
      ParseRoboNdSonar("100 1 2 3 4 5 2e12 7 8\n", "m.txt", "100 0 0 0\n", "p.txt", options);
  EXPECT_THAT(read.diagnostics(),
              ElementsAre(DiagnosticAt("m.txt", 1, 15,
                                       "expected a range in metres, at most 1e+09 for a return or "
                                       "at or above the max range (1e+297 m) for no return, got "
                                       "2000000000000 mm")));
  options.no_echo_mm = 5110.0;
  const Result<Log> no_echo =
      ParseRoboNdSonar("100 1 2 3 4 5 2e12 7 8\n", "m.txt", "100 0 0 0\n", "p.txt", options);
  ASSERT_TRUE(no_echo.ok()) << no_echo.error();
  EXPECT_EQ(no_echo.value().scans.at(0).ranges.at(5), 2e9);
}

TEST(RoboNdSonar, RejectsRangeLimitsThatLeaveNoReadingValid) {
  const std::string z = "100 1 2 3 4 5 6 7 8\n";
  const std::string p = "100 0 0 0\n";
  for (const auto& [min_range, no_echo_mm] : {std::pair{6.0, 5110.0}, std::pair{0.17, 100.0},
                                              std::pair{0.2, 200.0}, std::pair{-0.1, 5110.0}}) {
    RoboNdSonarOptions options;
    options.min_range = min_range;
    options.no_echo_mm = no_echo_mm;
    const Result<Log> r = ParseRoboNdSonar(z, "m.txt", p, "p.txt", options);
    ASSERT_FALSE(r.ok()) << min_range << " m, " << no_echo_mm << " mm";
    EXPECT_THAT(r.error(), HasSubstr("need 0 <= min range < max range"));
  }
}

TEST(RoboNdSonar, ReadsTheRealFiles) {
  const auto shared = testing::SharedDataDir();
  if (!shared) GTEST_SKIP() << "../shared/data is absent: no real sonar files to read";
  const Result<Log> read =
      ReadRoboNdSonar(*shared / "sonar-roboND/measurement.txt", *shared / "sonar-roboND/poses.txt");
  ASSERT_TRUE(read.ok()) << read.error();
  const Log& log = read.value();
  ASSERT_EQ(log.scans.size(), 413u);
  EXPECT_TRUE(log.Problems().empty());
  std::size_t no_echo = 0;
  Box2 path;
  for (const Scan& ring : log.scans) {
    ASSERT_EQ(ring.size(), 8u);
    for (BeamStatus s : ring.status) no_echo += s == BeamStatus::kMaxRange;
    path.extend(ring.pose.translation());
  }
  EXPECT_EQ(no_echo, 1068u);  // the readings of 5110 mm
  // The README's L-shaped corridor of about 17 x 9.4 m: the robot's path spans most of it.
  EXPECT_GT(path.sizes().x(), 14.0);
  EXPECT_GT(path.sizes().y(), 7.0);
}

}  // namespace
}  // namespace priormap
