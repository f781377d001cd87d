// The real CARMEN logs in ../shared/data (see its README.md): each is read without a single
// diagnostic, has the documented number of scans and beams, gets a sensible max range, and is
// written back (JSON and CARMEN) and read again without changing a bit. Skipped when the data
// directory is absent.
#include <cctype>
#include <cmath>
#include <filesystem>
#include <optional>
#include <ostream>
#include <set>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/carmen_io.hpp>
#include <priormap/core/json_io.hpp>
#include <priormap/core/log_io.hpp>

#include "testing/log_equality.hpp"
#include "testing/temp_dir.hpp"

namespace priormap {
namespace {

namespace fs = std::filesystem;
using testing::SameLog;

// ---- the data ----

struct RealLog {
  std::string path;  ///< relative to the shared data directory
  std::size_t scans;
  std::size_t beams;
  /// The "no return" value of the sensor, when the log uses one.
  std::optional<double> sentinel;
};

void PrintTo(const RealLog& log, std::ostream* os) {
  *os << log.path;
}

// From ../shared/data/README.md; the sentinels are the values that the README names (or, for
// the ~51 m clusters, the cluster each log has).
const std::vector<RealLog> kRealLogs = {
    {"laser-corrected/intel-corrected.log.gz", 910, 180, 81.83},
    {"laser-corrected/aces-corrected.log.gz", 440, 180, 50.0},
    {"laser-corrected/freiburg-079-corrected.log.gz", 4791, 360, 81.91},
    {"laser-corrected/csail-corrected.log.gz", 406, 361, 81.91},
    {"laser-corrected/freiburg-campus-corrected.log.gz", 2008, 360, 81.91},
    {"laser-corrected/freiburg-101-corrected.log.gz", 292, 360, 81.91},
    {"laser-corrected/infinite-corridor-corrected.log.gz", 1941, 180, 51.12},
    {"laser-corrected/seattle-corrected.log.gz", 241, 361, 81.91},
    {"laser-corrected/orebro-corrected.log.gz", 237, 181, 32.77},
    {"laser-corrected/belgioioso-corrected.log.gz", 395, 361, 81.91},
    {"laser-corrected/fhw-corrected.log.gz", 488, 180, 51.1},
    {"laser-corrected/edmonton-corrected.log.gz", 340, 180, 51.16},
    {"laser-corrected/acapulco-corrected.log.gz", 861, 181, 51.16},
    {"laser-raw-mbicp/laserazosSM3.log.gz", 778, 361, std::nullopt},
};

class RealLogTest : public ::testing::TestWithParam<RealLog> {
 protected:
  void SetUp() override {
    const std::optional<fs::path> data = testing::SharedDataDir();
    if (!data) GTEST_SKIP() << "shared data directory " << PRIORMAP_SHARED_DATA_DIR << " not found";
    path_ = *data / GetParam().path;
    ASSERT_TRUE(fs::exists(path_)) << path_ << " is listed in the data README but missing";
  }

  // The log, read with ReadLog and no diagnostics at all.
  Log Read() const {
    Result<Log> result = ReadLog(path_);
    if (!result.ok()) ADD_FAILURE() << result.error();
    return result.ok() ? std::move(result).value() : Log{};
  }

  fs::path path_;
};

TEST_P(RealLogTest, ReadsWithTheDocumentedScansAndBeams) {
  const Log log = Read();
  ASSERT_EQ(log.scans.size(), GetParam().scans);
  const std::vector<double> angles = FlaserBeamAngles(GetParam().beams, kPi);
  for (std::size_t k = 0; k < log.scans.size(); ++k) {
    const Scan& scan = log.scans[k];
    ASSERT_EQ(scan.size(), GetParam().beams) << "scan " << k;
    ASSERT_EQ(scan.channel, "FLASER") << "scan " << k;
    ASSERT_EQ(scan.angles, angles) << "scan " << k;
    ASSERT_TRUE(scan.odom_pose) << "scan " << k;
    ASSERT_TRUE(scan.Problems().empty()) << "scan " << k << ": " << scan.Problems().front();
  }
  EXPECT_EQ(log.RecordOrder().size(), log.NumRecords());
}

TEST_P(RealLogTest, MaxRangeReadingsAreRecognised) {
  const Log log = Read();
  ASSERT_FALSE(log.scans.empty());
  const std::optional<double> sentinel = GetParam().sentinel;
  std::size_t max_range = 0, invalid = 0, not_finite = 0, at_sentinel = 0;
  for (const Scan& scan : log.scans) {
    if (sentinel) {
      // Readings from half a metre below the sentinel on are "no return".
      ASSERT_DOUBLE_EQ(scan.max_range, *sentinel - 0.5);
    } else {
      ASSERT_EQ(scan.max_range, std::numeric_limits<double>::infinity());
    }
    for (std::size_t i = 0; i < scan.size(); ++i) {
      const double r = scan.ranges[i];
      if (!std::isfinite(r)) ++not_finite;
      if (sentinel && std::abs(r - *sentinel) < 0.005) {
        ++at_sentinel;
        ASSERT_EQ(scan.status[i], BeamStatus::kMaxRange) << r;
      }
      if (std::isfinite(r) && r > 0 && r < scan.max_range) {
        ASSERT_EQ(scan.status[i], BeamStatus::kValid) << r;
      }
      max_range += scan.status[i] == BeamStatus::kMaxRange;
      invalid += scan.status[i] == BeamStatus::kInvalid;
    }
  }
  if (sentinel) {
    EXPECT_GE(at_sentinel, 10U);
    EXPECT_GE(max_range, at_sentinel);
  } else {
    EXPECT_EQ(max_range, 0U);
  }
  // Only the raw log marks invalid readings (with NaN); they are all of its invalid readings.
  EXPECT_EQ(invalid, not_finite);
  EXPECT_EQ(invalid > 0, !sentinel) << invalid << " invalid readings";
}

TEST_P(RealLogTest, JsonRoundTripIsExact) {
  const Log log = Read();
  const std::string text = FormatJsonLog(log);
  const Result<Log> again = ParseJsonLog(text, "round-trip.json");
  ASSERT_TRUE(again.ok()) << again.error();
  EXPECT_TRUE(SameLog(again.value(), log));
}

TEST_P(RealLogTest, CarmenRoundTripIsExact) {
  const Log log = Read();
  const testing::TempDir dir;
  WriteCarmenLog(log, dir / "round-trip.log.gz");
  const Result<Log> again = ReadLog(dir / "round-trip.log.gz");
  ASSERT_TRUE(again.ok()) << again.error();
  EXPECT_TRUE(SameLog(again.value(), log));
}

std::string ParamName(const ::testing::TestParamInfo<RealLog>& info) {
  std::string name = fs::path(info.param.path).filename().string();
  name = name.substr(0, name.find('.'));
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return name;
}

INSTANTIATE_TEST_SUITE_P(SharedData, RealLogTest, ::testing::ValuesIn(kRealLogs), ParamName);

TEST(RealLogs, EveryLogFileOfTheDataIsTested) {
  const std::optional<fs::path> data = testing::SharedDataDir();
  if (!data) GTEST_SKIP() << "shared data directory " << PRIORMAP_SHARED_DATA_DIR << " not found";
  std::set<std::string> listed;
  for (const RealLog& log : kRealLogs) listed.insert(log.path);
  std::set<std::string> found;
  for (const char* folder : {"laser-corrected", "laser-raw-mbicp"}) {
    for (const fs::directory_entry& entry : fs::directory_iterator(*data / folder)) {
      const std::string name = entry.path().filename().string();
      if (name.ends_with(".log.gz")) found.insert(std::string(folder) + "/" + name);
    }
  }
  EXPECT_EQ(found, listed);
}

}  // namespace
}  // namespace priormap
