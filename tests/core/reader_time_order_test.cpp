// Scans stamped before the scan before them (scan_time_order.hpp): every log reader keeps them in
// the file's order, which every command follows, and warns of each at its timestamp, naming both
// timestamps and where the earlier-read scan is; equal timestamps, scans without one, other
// channels and other records are not compared. The real logs that have such scans are read, with
// their warnings.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <priormap/core/carmen_io.hpp>
#include <priormap/core/csm_io.hpp>
#include <priormap/core/json_io.hpp>
#include <priormap/core/log_io.hpp>

#include "testing/diagnostic_matchers.hpp"
#include "testing/temp_dir.hpp"

namespace priormap {
namespace {

using testing::DiagnosticAt;
using ::testing::ElementsAre;
using ::testing::IsEmpty;
using ::testing::SizeIs;

constexpr const char* kName = "t.log";

// A FLASER (or `channel`) line of 3 readings stamped `stamp`; its ipc_timestamp is at column 28
// (for a 6-letter channel).
std::string Laser(const std::string& stamp, const std::string& channel = "FLASER") {
  return fmt::format("{} 3 1 2 3 0 0 0 0 0 0 {} nohost {}\n", channel, stamp, stamp);
}

Result<Log> Carmen(const std::string& text) {
  Result<Log> log = ParseCarmenLog(text, kName);
  EXPECT_TRUE(log.ok()) << log.error();
  return log;
}

std::vector<double> Stamps(const Log& log) {
  std::vector<double> stamps;
  for (const Scan& scan : log.scans) stamps.push_back(scan.timestamp);
  return stamps;
}

// ---- CARMEN ----

TEST(ReaderTimeOrder, CarmenWarnsOfAScanStampedBeforeThePreviousOneAndKeepsItsPlace) {
  const Result<Log> log =
      Carmen(Laser("1") + "ODOM 0 0 0 0 0 0 5 nohost 5\n" + Laser("2") + Laser("1.5") + Laser("3"));
  EXPECT_THAT(Stamps(log.value()), ElementsAre(1.0, 2.0, 1.5, 3.0));
  EXPECT_THAT(log.warnings(),
              ElementsAre(DiagnosticAt(kName, 4, 28,
                                       "scan 2 is stamped 1.5 s, 0.5 s before the previous "
                                       "FLASER scan (scan 1 at line 3, stamped 2 s); the scans "
                                       "are kept in the file's order")));
}

TEST(ReaderTimeOrder, EqualStampsOtherChannelsAndOtherRecordsAreNotWarnedOf) {
  // Equal timestamps (several real logs stamp runs of scans alike).
  EXPECT_THAT(Carmen(Laser("1") + Laser("1") + Laser("1")).warnings(), IsEmpty());
  // A rear laser's own clock interleaved with the front one's.
  EXPECT_THAT(
      Carmen(Laser("1") + Laser("0.5", "RLASER") + Laser("2") + Laser("0.7", "RLASER")).warnings(),
      IsEmpty());
  // Odometry out of order (the corrected Radish logs have thousands of such ODOM records).
  EXPECT_THAT(
      Carmen("ODOM 0 0 0 0 0 0 5 nohost 5\nODOM 0 0 0 0 0 0 1 nohost 1\n" + Laser("1")).warnings(),
      IsEmpty());
  // Lines without timestamps read as 0: they have no time to compare.
  EXPECT_THAT(Carmen(Laser("5") + "FLASER 3 1 2 3 0 0 0 0 0 0\n" + Laser("6")).warnings(),
              IsEmpty());
  // A scan is compared with the last stamped one of its channel, across other channels' scans.
  EXPECT_THAT(Carmen(Laser("5") + Laser("9", "RLASER") + Laser("4")).warnings(),
              ElementsAre(DiagnosticAt(kName, 3, 28,
                                       "scan 2 is stamped 4 s, 1 s before the "
                                       "previous FLASER scan (scan 0 at line 1")));
}

TEST(ReaderTimeOrder, ALogWithErrorsHasDiagnosticsOnly) {
  const Result<Log> log = ParseCarmenLog(Laser("2") + Laser("1") + "FLASER 3 1 2\n", kName);
  EXPECT_FALSE(log.ok());
  EXPECT_THAT(log.warnings(), IsEmpty());
}

TEST(ReaderTimeOrder, AfterFiveWarningsTheRestAreSummedUpAtTheFirstOfThem) {
  std::string text;
  for (int k = 0; k < 9; ++k) text += Laser(fmt::format("{}", 100 - k));  // 8 scans go back
  const Result<Log> log = Carmen(text);
  ASSERT_THAT(log.warnings(), SizeIs(6));
  EXPECT_THAT(log.warnings()[4], DiagnosticAt(kName, 6, 28, "scan 5 is stamped 95 s"));
  EXPECT_THAT(log.warnings()[5],
              DiagnosticAt(kName, 7, 28,
                           "3 more scans are stamped before the previous scan of their channel, "
                           "the first of them scan 6 here"));
}

TEST(ReaderTimeOrder, OneScanBeyondTheListedIsSummedUpInTheSingular) {
  std::string text;
  for (int k = 0; k < 7; ++k) text += Laser(fmt::format("{}", 100 - k));  // 6 scans go back
  const Result<Log> log = Carmen(text);
  ASSERT_THAT(log.warnings(), SizeIs(6));
  EXPECT_THAT(log.warnings()[5],
              DiagnosticAt(kName, 7, 28,
                           "1 more scan is stamped before the previous scan of its channel, "
                           "scan 6 here; the scans are kept in the file's order"));
}

TEST(ReaderTimeOrder, ReadLogHandsTheWarningsOn) {
  const testing::TempDir dir;
  testing::WriteAll(dir / "t.log", Laser("2") + Laser("1"));
  const std::string path = (dir / "t.log").string();
  EXPECT_THAT(ReadLog(dir / "t.log").warnings(),
              ElementsAre(DiagnosticAt(path, 2, 28, "scan 1 is stamped 1 s")));
  EXPECT_THAT(ReadCarmenLog(dir / "t.log").warnings(), SizeIs(1));
}

// ---- priormap JSON ----

TEST(ReaderTimeOrder, JsonWarnsAtTheTimestampOfTheRecord) {
  const Log carmen =
      Carmen(Laser("1") + "ODOM 0 0 0 0 0 0 5 nohost 5\n" + Laser("2") + Laser("1.5")).value();
  // One record per line after the header line: record i is on line i + 2.
  const std::string text = FormatJsonLog(carmen);
  const Result<Log> json = ParseJsonLog(text, "t.json");
  ASSERT_TRUE(json.ok()) << json.error();
  EXPECT_THAT(Stamps(json.value()), ElementsAre(1.0, 2.0, 1.5));
  ASSERT_THAT(json.warnings(), SizeIs(1));
  const Diagnostic& d = json.warnings().front();
  EXPECT_EQ(d.line, 5);
  EXPECT_EQ(d.col, static_cast<int>(testing::Lines(text)[4].find("\"timestamp\":")) + 13);
  EXPECT_EQ(d.message,
            "scan 2 is stamped 1.5 s, 0.5 s before the previous FLASER scan (scan 1 at line 4, "
            "stamped 2 s); the scans are kept in the file's order (at /records/3/timestamp)");
}

TEST(ReaderTimeOrder, JsonListsFiveWarningsAndSumsUpTheRest) {
  std::string text;
  for (int k = 0; k < 9; ++k) text += Laser(fmt::format("{}", 100 - k));
  const Result<Log> json = ParseJsonLog(FormatJsonLog(Carmen(text).value()), "t.json");
  ASSERT_THAT(json.warnings(), SizeIs(6));
  // Scan k is record k, on line k + 2.
  for (std::size_t k = 1; k <= 5; ++k) {
    EXPECT_EQ(json.warnings()[k - 1].line, static_cast<int>(k) + 2);
    EXPECT_THAT(json.warnings()[k - 1].message,
                ::testing::HasSubstr(
                    fmt::format("(scan {} at line {}, stamped {} s)", k - 1, k + 1, 101 - k)));
  }
  EXPECT_EQ(json.warnings()[5].line, 8);
  EXPECT_THAT(json.warnings()[5].message,
              ::testing::StartsWith("3 more scans are stamped before the previous scan of their "
                                    "channel, the first of them scan 6 here"));
  EXPECT_THAT(json.warnings()[5].message, ::testing::EndsWith("(at /records/6/timestamp)"));
}

TEST(ReaderTimeOrder, JsonScansWithoutATimestampAreNotCompared) {
  const std::string header = R"({"format": "priormap.log", "version": 1, "records": [)";
  const auto scan = [](const std::string& stamp) {
    return R"({"type": "scan", "pose": [0, 0, 0], "angles": [0], "ranges": [1])" + stamp + "}";
  };
  // No "timestamp", null, or a CARMEN line that had none (written as 0).
  EXPECT_THAT(ParseJsonLog(header + scan(R"(, "timestamp": 5)") + "," + scan("") + "," +
                               scan(R"(, "timestamp": null)") + "," +
                               scan(R"(, "timestamp": 0, "carmen": {"has_timestamps": false})") +
                               "," + scan(R"(, "timestamp": 6)") + "]}",
                           "t.json")
                  .warnings(),
              IsEmpty());
  EXPECT_THAT(ParseJsonLog(
                  header + scan(R"(, "timestamp": 5)") + ",\n" + scan(R"(, "timestamp": 4)") + "]}",
                  "t.json")
                  .warnings(),
              ElementsAre(DiagnosticAt("t.json", 2, 80, "(scan 0 at line 1, stamped 5 s)")));
  // A priormap.scan document is one scan.
  EXPECT_THAT(ParseJsonLog(R"({"format": "priormap.scan", "version": 1, "timestamp": 3, )"
                           R"("pose": [0, 0, 0], "angles": [0], "ranges": [1]})",
                           "t.json")
                  .warnings(),
              IsEmpty());
}

// ---- CSM laser_data ----

TEST(ReaderTimeOrder, CsmWarnsAtTheTimestampOfTheObject) {
  const auto object = [](const std::string& stamp) {
    return R"({"nrays": 1, "theta": [0], "readings": [1], "odometry": [0, 0, 0], "timestamp": )" +
           stamp + "}\n";
  };
  const Result<Log> log =
      ParseCsmLog(object("[10, 0]") + object("[9, 500000]") + object("null"), "c.json");
  ASSERT_TRUE(log.ok()) << log.error();
  EXPECT_THAT(Stamps(log.value()), ElementsAre(10.0, 9.5, 0.0));
  EXPECT_THAT(log.warnings(),
              ElementsAre(DiagnosticAt("c.json", 2, 81,
                                       "scan 1 is stamped 9.5 s, 0.5 s before the previous CSM "
                                       "scan (scan 0 at line 1, stamped 10 s)")));
  std::string backwards;
  for (int k = 0; k < 9; ++k) backwards += object(fmt::format("[{}, 0]", 100 - k));
  const Result<Log> many = ParseCsmLog(backwards, "c.json");
  ASSERT_THAT(many.warnings(), SizeIs(6));
  EXPECT_THAT(many.warnings()[4],
              DiagnosticAt("c.json", 6, 81, "(scan 4 at line 5, stamped 96 s)"));
  EXPECT_THAT(many.warnings()[5], DiagnosticAt("c.json", 7, 81, "3 more scans"));
}

// ---- the real logs ----

// Two of the real logs have scans stamped before the previous one: intel-corrected 4 (up to
// 0.86 s), infinite-corridor-corrected 3 (its clock runs backwards from 0 before it wraps). They
// are read, with a warning for each; the others have none.
TEST(ReaderTimeOrder, RealLogsAreReadWithAWarningForEachScanStampedBackwards) {
  const std::optional<std::filesystem::path> data = testing::SharedDataDir();
  if (!data) GTEST_SKIP() << "shared data directory " << PRIORMAP_SHARED_DATA_DIR << " not found";
  for (const auto& entry : std::filesystem::directory_iterator(*data / "laser-corrected")) {
    if (entry.path().extension() != ".gz") continue;
    const std::string name = entry.path().filename().string();
    const Result<Log> log = ReadLog(entry.path());
    ASSERT_TRUE(log.ok()) << log.error();
    const std::size_t expected = name == "intel-corrected.log.gz"               ? 4
                                 : name == "infinite-corridor-corrected.log.gz" ? 3
                                                                                : 0;
    EXPECT_THAT(log.warnings(), SizeIs(expected)) << name;
  }
  const Result<Log> intel = ReadLog(*data / "laser-corrected/intel-corrected.log.gz");
  ASSERT_THAT(intel.warnings(), SizeIs(4));
  EXPECT_THAT(intel.warnings().front(),
              DiagnosticAt((*data / "laser-corrected/intel-corrected.log.gz").string(), 5647, 955,
                           "scan 295 is stamped 940.54 s, 0.114 s before the previous FLASER "
                           "scan (scan 294 at line 5638, stamped 940.654 s)"));
}

}  // namespace
}  // namespace priormap
