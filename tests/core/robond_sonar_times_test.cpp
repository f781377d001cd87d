// The RoboND sonar reader's times: the rings are a time series, so a time that repeats or goes
// back (a line copied or moved) is refused at its file:line:col, and the real files, whose times
// increase strictly, are still read.
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <priormap/core/robond_sonar_io.hpp>

#include "testing/diagnostic_matchers.hpp"
#include "testing/temp_dir.hpp"

namespace priormap {
namespace {

using testing::DiagnosticAt;
using ::testing::ElementsAre;

// A measurement line and its pose line at time `t_ms`.
std::string Ring(const std::string& t_ms) {
  return t_ms + " 1000 1100 1200 1300 1400 1500 1600 1700\n";
}
std::string Pose(const std::string& t_ms) {
  return t_ms + " 0 0 0\n";
}

std::vector<Diagnostic> Errors(const std::string& measurements, const std::string& poses) {
  const Result<Log> r = ParseRoboNdSonar(measurements, "m.txt", poses, "p.txt");
  EXPECT_FALSE(r.ok());
  return r.diagnostics();
}

TEST(RoboNdSonarTimes, ARepeatedTimeIsRefusedAtItsField) {
  EXPECT_THAT(
      Errors(Ring("100") + Ring("200") + Ring("200"), Pose("100") + Pose("200") + Pose("200")),
      ElementsAre(
          DiagnosticAt("m.txt", 3, 1,
                       "expected a time after the previous line's 200 ms (m.txt:2), got 200 ms")));
}

// Blank lines do not count as the previous line, and the column is the time's own.
TEST(RoboNdSonarTimes, ATimeThatGoesBackIsRefusedAtItsField) {
  EXPECT_THAT(Errors(Ring("100") + "\n" + "  " + Ring("99.5"), Pose("100") + Pose("99.5")),
              ElementsAre(DiagnosticAt(
                  "m.txt", 3, 3,
                  "expected a time after the previous line's 100 ms (m.txt:1), got 99.5 ms")));
}

// A line copied in the measurement file alone is reported at the copy, not as the poses' time
// that differs from it.
TEST(RoboNdSonarTimes, ALineRepeatedInTheMeasurementsIsReportedThere) {
  EXPECT_THAT(
      Errors(Ring("100") + Ring("100") + Ring("200"), Pose("100") + Pose("200") + Pose("300")),
      ElementsAre(DiagnosticAt("m.txt", 2, 1, "after the previous line's 100 ms")));
}

TEST(RoboNdSonarTimes, TimesThatIncreaseAreRead) {
  const Result<Log> read = ParseRoboNdSonar(Ring("100") + Ring("100.5") + Ring("3000"), "m.txt",
                                            Pose("100") + Pose("100.5") + Pose("3000"), "p.txt");
  ASSERT_TRUE(read.ok()) << read.error();
  EXPECT_EQ(read.value().scans.size(), 3u);
}

TEST(RoboNdSonarTimes, TheRealFilesTimesIncrease) {
  const auto shared = testing::SharedDataDir();
  if (!shared) GTEST_SKIP() << "../shared/data is absent: no real sonar files to read";
  const Result<Log> read =
      ReadRoboNdSonar(*shared / "sonar-roboND/measurement.txt", *shared / "sonar-roboND/poses.txt");
  ASSERT_TRUE(read.ok()) << read.error();
  EXPECT_EQ(read.value().scans.size(), 413u);
}

}  // namespace
}  // namespace priormap
