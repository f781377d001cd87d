// Well-formed CARMEN logs: every record type, beam angle conventions, reading statuses, max-range
// detection, and writing logs back without changing a bit.
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/carmen_io.hpp>
#include <priormap/core/file_io.hpp>
#include <priormap/core/log_io.hpp>
#include <priormap/core/world_bounds.hpp>

#include "testing/log_equality.hpp"
#include "testing/temp_dir.hpp"

namespace priormap {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::Pair;
using testing::SameLog;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// ---- helpers ----

Log Parse(const std::string& text, const CarmenReadOptions& options = {},
          CarmenReadStats* stats = nullptr) {
  Result<Log> result = ParseCarmenLog(text, "test.log", options, stats);
  if (!result.ok()) ADD_FAILURE() << result.error();
  return result.ok() ? std::move(result).value() : Log{};
}

std::string Flaser(const std::vector<double>& ranges, const std::string& tail = " 0 0 0 0 0 0") {
  std::ostringstream line;
  line.precision(17);
  line << "FLASER " << ranges.size();
  for (double r : ranges) line << ' ' << r;
  line << tail << '\n';
  return line.str();
}

constexpr const char* kRobotLaser =
    "ROBOTLASER1 3 -1.2 2.4 0.6 20 0.01 1 5 1 2.5 nan 25 3 2 0.7 0.8 "
    "1 2 0.5 1.5 2.5 0.75 0.2 0.3 0.4 0.5 0.6 100.5 robot 100.75\n";

// ---- record types ----

TEST(Carmen, FlaserRecordFieldsAreRead) {
  const Log log = Parse("FLASER 3 1.5 2.5 3.5 1 2 0.5 1.1 2.1 0.6 1234.5 myhost 1234.75\n");
  ASSERT_EQ(log.scans.size(), 1U);
  const Scan& scan = log.scans[0];
  EXPECT_EQ(scan.channel, "FLASER");
  EXPECT_THAT(scan.ranges, ElementsAre(1.5, 2.5, 3.5));
  EXPECT_EQ(scan.angles, FlaserBeamAngles(3, kPi));
  EXPECT_THAT(scan.sigma, ElementsAre(0.01, 0.01, 0.01));
  EXPECT_THAT(scan.status, ElementsAre(BeamStatus::kValid, BeamStatus::kValid, BeamStatus::kValid));
  EXPECT_EQ(scan.pose.vector(), Vec3(1, 2, 0.5));
  ASSERT_TRUE(scan.odom_pose);
  EXPECT_EQ(scan.odom_pose->vector(), Vec3(1.1, 2.1, 0.6));
  EXPECT_FALSE(scan.robot_pose);
  EXPECT_EQ(scan.timestamp, 1234.5);
  ASSERT_TRUE(scan.carmen);
  EXPECT_TRUE(scan.carmen->has_timestamps);
  EXPECT_EQ(scan.carmen->host, "myhost");
  EXPECT_EQ(scan.carmen->logger_timestamp, 1234.75);
  EXPECT_EQ(scan.min_range, 0.0);
  EXPECT_EQ(scan.max_range, kInf);  // no sentinel in three readings
  EXPECT_FALSE(scan.precision);
  EXPECT_FALSE(scan.truth);
  EXPECT_TRUE(scan.Problems().empty());
  EXPECT_EQ(log.pose_source, PoseSource::kUnknown);
  EXPECT_THAT(log.order, ElementsAre(Log::RecordRef{Log::RecordKind::kScan, 0}));
}

TEST(Carmen, RlaserKeepsItsChannel) {
  const Log log = Parse("RLASER 2 4 5 1 2 0.5 1.1 2.1 0.6\n");
  ASSERT_EQ(log.scans.size(), 1U);
  EXPECT_EQ(log.scans[0].channel, "RLASER");
  EXPECT_THAT(log.scans[0].ranges, ElementsAre(4, 5));
  EXPECT_EQ(log.scans[0].angles, FlaserBeamAngles(2, kPi));
}

TEST(Carmen, RobotLaserRecordFieldsAreRead) {
  const Log log = Parse(kRobotLaser);
  ASSERT_EQ(log.scans.size(), 1U);
  const Scan& scan = log.scans[0];
  EXPECT_EQ(scan.channel, "ROBOTLASER1");
  EXPECT_EQ(scan.ranges.size(), 5U);
  EXPECT_EQ(scan.ranges[0], 1.0);
  EXPECT_TRUE(std::isnan(scan.ranges[2]));
  // Angles are start_angle + i * angular_resolution, evaluated exactly so.
  ASSERT_EQ(scan.angles.size(), 5U);
  for (std::size_t i = 0; i < 5; ++i)
    EXPECT_EQ(scan.angles[i], -1.2 + static_cast<double>(i) * 0.6);
  EXPECT_EQ(scan.pose.vector(), Vec3(1, 2, 0.5));
  ASSERT_TRUE(scan.robot_pose);
  EXPECT_EQ(scan.robot_pose->vector(), Vec3(1.5, 2.5, 0.75));
  EXPECT_FALSE(scan.odom_pose);
  EXPECT_EQ(scan.timestamp, 100.5);
  // The record's own maximum range applies when the log shows no sentinel.
  EXPECT_EQ(scan.max_range, 20.0);
  EXPECT_THAT(scan.status, ElementsAre(BeamStatus::kValid, BeamStatus::kValid, BeamStatus::kInvalid,
                                       BeamStatus::kMaxRange, BeamStatus::kValid));
  ASSERT_TRUE(scan.carmen);
  const CarmenLaserFields& c = *scan.carmen;
  EXPECT_EQ(c.laser_type, 3);
  EXPECT_EQ(c.start_angle, -1.2);
  EXPECT_EQ(c.fov, 2.4);
  EXPECT_EQ(c.angular_resolution, 0.6);
  EXPECT_EQ(c.accuracy, 0.01);
  EXPECT_EQ(c.remission_mode, 1);
  EXPECT_THAT(c.remissions, ElementsAre(0.7, 0.8));
  EXPECT_EQ(c.tv, 0.2);
  EXPECT_EQ(c.rv, 0.3);
  EXPECT_EQ(c.forward_safety_dist, 0.4);
  EXPECT_EQ(c.side_safety_dist, 0.5);
  EXPECT_EQ(c.turn_axis, 0.6);
  EXPECT_TRUE(c.has_timestamps);
  EXPECT_EQ(c.host, "robot");
  EXPECT_EQ(c.logger_timestamp, 100.75);
}

TEST(Carmen, OdometryRecordFieldsAreRead) {
  const Log log = Parse("ODOM 1 2 0.5 0.1 -0.2 0.3 13 host 13.5\n");
  ASSERT_EQ(log.odometry.size(), 1U);
  const OdometryRecord& r = log.odometry[0];
  EXPECT_EQ(r.pose.vector(), Vec3(1, 2, 0.5));
  EXPECT_EQ(r.tv, 0.1);
  EXPECT_EQ(r.rv, -0.2);
  EXPECT_EQ(r.accel, 0.3);
  EXPECT_EQ(r.timestamp, 13.0);
  ASSERT_TRUE(r.carmen);
  EXPECT_TRUE(r.carmen->has_timestamps);
  EXPECT_EQ(r.carmen->host, "host");
  EXPECT_EQ(r.carmen->logger_timestamp, 13.5);
  EXPECT_THAT(log.order, ElementsAre(Log::RecordRef{Log::RecordKind::kOdometry, 0}));
}

TEST(Carmen, TruePoseRecordFieldsAreRead) {
  const Log log = Parse("TRUEPOS 1 2 0.5 4 5 -0.5 14 host 14.5\n");
  ASSERT_EQ(log.true_poses.size(), 1U);
  const TruePoseRecord& r = log.true_poses[0];
  EXPECT_EQ(r.true_pose.vector(), Vec3(1, 2, 0.5));
  EXPECT_EQ(r.odom_pose.vector(), Vec3(4, 5, -0.5));
  EXPECT_EQ(r.timestamp, 14.0);
  ASSERT_TRUE(r.carmen);
  EXPECT_EQ(r.carmen->logger_timestamp, 14.5);
  EXPECT_THAT(log.order, ElementsAre(Log::RecordRef{Log::RecordKind::kTruePose, 0}));
}

TEST(Carmen, PoseAnglesAreWrapped) {
  const Log log = Parse("ODOM 0 0 7 0 0 0\n");
  ASSERT_EQ(log.odometry.size(), 1U);
  EXPECT_NEAR(log.odometry[0].pose.theta(), 7 - kTwoPi, 1e-15);
}

TEST(Carmen, ParamValueIsTheRestOfTheLine) {
  const Log log = Parse(
      "PARAM robot_front_laser_max 81.9\n"
      "PARAM robot_name a robot  with spaces \n"
      "PARAM\tempty_value\n"
      "PARAM\n");  // no name: nothing to keep
  EXPECT_THAT(log.params,
              ElementsAre(Pair("robot_front_laser_max", "81.9"),
                          Pair("robot_name", "a robot  with spaces"), Pair("empty_value", "")));
}

TEST(Carmen, CommentsAndUnknownRecordsAreCountedAndSkipped) {
  CarmenReadStats stats;
  const Log log = Parse(
      "# comment\n"
      "#PARAM commented_out 1\n"
      "NEFF 1 2 3\n"
      "ODOM 1 2 3 0 0 0\n"
      "SONAR 8 garbage that is not checked\n"
      "NEFF 4\n"
      "  # indented comment\n",
      {}, &stats);
  EXPECT_EQ(stats.comment_lines, 3);
  EXPECT_THAT(stats.records, ElementsAre(Pair("NEFF", 2), Pair("ODOM", 1), Pair("SONAR", 1)));
  EXPECT_EQ(log.NumRecords(), 1U);
  EXPECT_EQ(log.odometry.size(), 1U);
}

TEST(Carmen, RecordOrderIsKept) {
  CarmenReadStats stats;
  const Log log = Parse(
      "PARAM a 1\n"
      "ODOM 1 2 3 0 0 0\n" +
          Flaser({1, 2}) +
          "TRUEPOS 1 2 3 4 5 6\n"
          "ODOM 1 2 3 0 0 0\n" +
          kRobotLaser,
      {}, &stats);
  using K = Log::RecordKind;
  EXPECT_THAT(log.order, ElementsAre(Log::RecordRef{K::kParam, 0}, Log::RecordRef{K::kOdometry, 0},
                                     Log::RecordRef{K::kScan, 0}, Log::RecordRef{K::kTruePose, 0},
                                     Log::RecordRef{K::kOdometry, 1}, Log::RecordRef{K::kScan, 1}));
  EXPECT_THAT(stats.records, ElementsAre(Pair("FLASER", 1), Pair("ODOM", 2), Pair("PARAM", 1),
                                         Pair("ROBOTLASER1", 1), Pair("TRUEPOS", 1)));
}

TEST(Carmen, RecordsWithAndWithoutTimestampsMix) {
  const Log log = Parse(Flaser({1, 2}) + Flaser({1, 2}, " 0 0 0 0 0 0 5.5 h 6.5") +
                        "ODOM 1 2 3 0 0 0\nTRUEPOS 1 2 3 4 5 6\n");
  ASSERT_EQ(log.scans.size(), 2U);
  EXPECT_FALSE(log.scans[0].carmen->has_timestamps);
  EXPECT_EQ(log.scans[0].timestamp, 0.0);
  EXPECT_TRUE(log.scans[1].carmen->has_timestamps);
  EXPECT_EQ(log.scans[1].timestamp, 5.5);
  EXPECT_FALSE(log.odometry[0].carmen->has_timestamps);
  EXPECT_FALSE(log.true_poses[0].carmen->has_timestamps);
}

TEST(Carmen, PoseSourceComesFromTheOptions) {
  CarmenReadOptions options;
  options.pose_source = PoseSource::kCorrected;
  EXPECT_EQ(Parse(Flaser({1}), options).pose_source, PoseSource::kCorrected);
}

TEST(Carmen, SigmaAndMinRangeComeFromTheOptions) {
  CarmenReadOptions options;
  options.sigma = 0.05;
  options.min_range = 0.2;
  const Log log = Parse(Flaser({0.1, 0.2, 0.3}), options);
  const Scan& scan = log.scans.at(0);
  EXPECT_THAT(scan.sigma, ElementsAre(0.05, 0.05, 0.05));
  EXPECT_EQ(scan.min_range, 0.2);
  EXPECT_THAT(scan.status,
              ElementsAre(BeamStatus::kInvalid, BeamStatus::kValid, BeamStatus::kValid));
}

// ---- beam angles ----

TEST(Carmen, NothingIsLostFromALogReadFromCarmen) {
  const Result<Log> log = ParseCarmenLog(
      "FLASER 3 1 nan 81.83 0 0 0 0 0 0\nODOM 1 2 0.5 0 0 0\n"
      "ROBOTLASER1 0 -1.5 3 0.01 80 0.01 0 3 1 2 3 0 0 0 0 0 0 0 0 0 0 0 0\n",
      "in.log");
  ASSERT_TRUE(log.ok()) << log.error();
  EXPECT_THAT(CarmenLosses(log.value()), ::testing::IsEmpty());
}

TEST(Carmen, WhatCarmenCannotHoldIsNamedWithItsCount) {
  Log log =
      ParseCarmenLog("FLASER 3 1 2 3 0 0 0 0 0 0\nFLASER 3 1 2 3 0 0 0 0 0 0\n", "in.log").value();
  for (Scan& scan : log.scans) scan.truth.emplace();
  log.scans[0].sigma.assign(3, 0.05);
  log.scans[0].precision = SymmetricBandedMatrix::Ar1Precision(log.scans[0].sigma, 0.5);
  log.scans[1].min_range = 0.5;
  log.scans[1].status[1] = BeamStatus::kInvalid;  // 2 m: reads back valid
  log.scans[1].angles = {-1.0, 0.0, 1.0};         // not FLASER's: a ROBOTLASER1 line
  log.scans[1].odom_pose = Se2(1, 2, 0);
  EXPECT_THAT(CarmenLosses(log),
              ElementsAre("the range noise of 1 scan (read back as sigma 0.01 m)",
                          "the correlated noise of 1 scan", "the ground truth of 2 scans",
                          "the odometry pose of 1 scan (ROBOTLASER1 has no field for it)",
                          "the minimum range of 1 scan",
                          "the status of 1 reading (read back from its value)"));
  // ODOM records carry the odometry that ROBOTLASER1 lines cannot.
  log.odometry.push_back({});
  EXPECT_THAT(CarmenLosses(log), ::testing::Not(::testing::Contains(HasSubstr("odometry"))));
}

// FLASER lines have no max range: a shorter one given when reading (--max-range) is lost, and
// the readings beyond it read back as walls.
TEST(Carmen, AShorterMaxRangeOfFlaserLinesIsALoss) {
  std::string text;
  for (int k = 0; k < 20; ++k) text += "FLASER 4 81.83 81.83 30 2 0 0 0 0 0 0\n";
  CarmenReadOptions options;
  options.max_range = 20.0;
  const Log log = ParseCarmenLog(text, "in.log", options).value();
  EXPECT_THAT(CarmenLosses(log),
              ElementsAre("the max range of 20 scans (read back as the 81.33 m detected from the "
                          "no-return readings)",
                          "the status of 20 readings (read back from its value)"));
  EXPECT_THAT(CarmenLosses(ParseCarmenLog(text, "in.log").value()), ::testing::IsEmpty());
}

TEST(Carmen, TheLogFormatOfAFileNameIgnoresCaseAndGzipAndKnowsNoOthers) {
  EXPECT_EQ(LogFormatFromPath("a.json"), LogFormat::kJson);
  EXPECT_EQ(LogFormatFromPath("a.JSON.gz"), LogFormat::kJson);
  EXPECT_EQ(LogFormatFromPath("dir.x/a.log.gz"), LogFormat::kCarmen);
  EXPECT_EQ(LogFormatFromPath("a.clf"), LogFormat::kCarmen);
  EXPECT_EQ(LogFormatFromPath("a.png"), std::nullopt);
  EXPECT_EQ(LogFormatFromPath("a"), std::nullopt);
}

TEST(Carmen, FlaserAnglesOf180Or360BeamsStepFovOverN) {
  for (const std::size_t n : {180U, 360U}) {
    const std::vector<double> angles =
        Parse(Flaser(std::vector<double>(n, 1.0))).scans.at(0).angles;
    ASSERT_EQ(angles.size(), n);
    const double step = kPi / static_cast<double>(n);
    for (std::size_t i = 0; i < n; ++i) {
      EXPECT_EQ(angles[i], -kPi / 2 + static_cast<double>(i) * step)
          << "n = " << n << ", i = " << i;
    }
    EXPECT_EQ(angles.front(), -kPi / 2);
    EXPECT_NEAR(angles.back(), kPi / 2 - step, 1e-14);  // the last beam stops one step short
  }
}

TEST(Carmen, FlaserAnglesOf181Or361BeamsSpanTheWholeFov) {
  for (const std::size_t n : {181U, 361U}) {
    const std::vector<double> angles =
        Parse(Flaser(std::vector<double>(n, 1.0))).scans.at(0).angles;
    ASSERT_EQ(angles.size(), n);
    const double step = kPi / static_cast<double>(n - 1);
    for (std::size_t i = 0; i < n; ++i) {
      EXPECT_EQ(angles[i], -kPi / 2 + static_cast<double>(i) * step)
          << "n = " << n << ", i = " << i;
    }
    EXPECT_NEAR(angles.back(), kPi / 2, 1e-14);
  }
  EXPECT_NEAR(FlaserBeamAngles(181, kPi)[1] - FlaserBeamAngles(181, kPi)[0], DegToRad(1.0), 1e-15);
  EXPECT_NEAR(FlaserBeamAngles(361, kPi)[1] - FlaserBeamAngles(361, kPi)[0], DegToRad(0.5), 1e-15);
}

TEST(Carmen, FieldOfViewOptionScalesFlaserAngles) {
  CarmenReadOptions options;
  options.fov = DegToRad(100);
  const std::vector<double> angles = Parse(Flaser({1, 1, 1, 1, 1}), options).scans.at(0).angles;
  ASSERT_EQ(angles.size(), 5U);
  EXPECT_EQ(angles.front(), -DegToRad(50));
  EXPECT_NEAR(angles.back(), DegToRad(50), 1e-15);
  EXPECT_EQ(angles, FlaserBeamAngles(5, DegToRad(100)));
}

// ---- reading statuses ----

TEST(Carmen, NonFiniteZeroAndNegativeReadingsAreInvalid) {
  const Log log = Parse("FLASER 7 nan inf -inf 0 -1 -0 2.5 0 0 0 0 0 0\n");
  const Scan& scan = log.scans.at(0);
  EXPECT_TRUE(std::isnan(scan.ranges[0]));
  EXPECT_EQ(scan.ranges[1], kInf);
  EXPECT_EQ(scan.ranges[2], -kInf);
  EXPECT_THAT(scan.status,
              ElementsAre(BeamStatus::kInvalid, BeamStatus::kInvalid, BeamStatus::kInvalid,
                          BeamStatus::kInvalid, BeamStatus::kInvalid, BeamStatus::kInvalid,
                          BeamStatus::kValid));
  EXPECT_EQ(scan.NumValid(), 1U);
}

TEST(Carmen, ReadingsAtOrAboveTheMaxRangeOptionAreMaxRange) {
  CarmenReadOptions options;
  options.max_range = 5.0;
  const Scan scan = Parse(Flaser({4.99, 5.0, 5.01, 80, kNaN}), options).scans.at(0);
  EXPECT_EQ(scan.max_range, 5.0);
  EXPECT_THAT(scan.status,
              ElementsAre(BeamStatus::kValid, BeamStatus::kMaxRange, BeamStatus::kMaxRange,
                          BeamStatus::kMaxRange, BeamStatus::kInvalid));
}

// n readings spread over [0.5, top) m in 1 cm steps, each value as often as the others: a
// continuous distribution with no sentinel.
std::vector<double> Continuous(std::size_t n, double top = 30.0) {
  const auto span = static_cast<std::size_t>(std::llround((top - 0.5) * 100));
  std::vector<double> readings(n);
  for (std::size_t i = 0; i < n; ++i) {
    readings[i] = 0.5 + static_cast<double>((i * 7919) % span) / 100;
  }
  return readings;
}

std::vector<double> WithSentinel(std::vector<double> readings, double sentinel, int count) {
  readings.insert(readings.end(), static_cast<std::size_t>(count), sentinel);
  return readings;
}

TEST(Carmen, DetectsTheSickSentinels) {
  for (const double sentinel : {81.83, 81.91, 50.0, 32.77, 51.16}) {
    const std::optional<double> detected =
        DetectMaxRangeSentinel(WithSentinel(Continuous(2000), sentinel, 50));
    ASSERT_TRUE(detected) << sentinel;
    EXPECT_DOUBLE_EQ(*detected, sentinel - 0.5);
  }
}

TEST(Carmen, SentinelNeedsTenOccurrences) {
  EXPECT_TRUE(DetectMaxRangeSentinel(WithSentinel(Continuous(100), 81.83, 10)));
  EXPECT_FALSE(DetectMaxRangeSentinel(WithSentinel(Continuous(100), 81.83, 9)));
}

TEST(Carmen, SentinelReadingsWithinACentimetreCountTogether) {
  // Orebro writes 32.767; values that round to the same centimetre form one cluster.
  std::vector<double> readings = Continuous(1000);
  for (int i = 0; i < 6; ++i) readings.push_back(32.767);
  for (int i = 0; i < 6; ++i) readings.push_back(32.771);
  const std::optional<double> detected = DetectMaxRangeSentinel(readings);
  ASSERT_TRUE(detected);
  EXPECT_DOUBLE_EQ(*detected, 32.77 - 0.5);
}

TEST(Carmen, ContinuousDistributionHasNoSentinel) {
  // Every centimetre value from 0.5 to 30 m occurs often, the largest one included, but it is
  // not isolated from the readings just below it.
  EXPECT_EQ(DetectMaxRangeSentinel(Continuous(100000)), std::nullopt);
  EXPECT_EQ(DetectMaxRangeSentinel(std::vector<double>{}), std::nullopt);
}

TEST(Carmen, SentinelMustStandApartFromTheReadingsBelowIt) {
  // 50 readings at 20.0 m above returns up to 15 m; then 10 more in [17.5, 19.5): isolation
  // 50 / 10 = 5 < 10.
  std::vector<double> readings = WithSentinel(Continuous(100, 15.0), 20.0, 50);
  std::vector<double> crowded = readings;
  for (int i = 0; i < 10; ++i) crowded.push_back(18.0 + 0.1 * i);
  EXPECT_TRUE(DetectMaxRangeSentinel(readings));
  EXPECT_FALSE(DetectMaxRangeSentinel(crowded));
}

TEST(Carmen, NonFiniteReadingsDoNotMakeASentinel) {
  std::vector<double> readings = Continuous(1000);
  readings.insert(readings.end(), 100, kNaN);
  readings.insert(readings.end(), 100, kInf);
  EXPECT_EQ(DetectMaxRangeSentinel(readings), std::nullopt);
  readings.insert(readings.end(), 20, 81.91);
  EXPECT_DOUBLE_EQ(DetectMaxRangeSentinel(readings).value_or(0.0), 81.41);
}

TEST(Carmen, AbsurdlyLargeReadingsDoNotMakeASentinel) {
  // Found by the fuzzer: readings whose centimetres overflow a long long.
  std::vector<double> readings = Continuous(1000);
  readings.insert(readings.end(), 20, 1e300);
  readings.insert(readings.end(), 20, 9.3e16);
  EXPECT_EQ(DetectMaxRangeSentinel(readings), std::nullopt);
  readings.insert(readings.end(), 20, 81.91);
  EXPECT_DOUBLE_EQ(DetectMaxRangeSentinel(readings).value_or(0.0), 81.41);
}

// A log whose readings include 12 sentinels of 81.83 m among ordinary returns.
std::string LogWithSentinel() {
  std::string text;
  for (int k = 0; k < 6; ++k) text += Flaser({1.0 + k, 81.83, 25.0, 81.83, 0.5 * k + 0.3});
  return text;
}

TEST(Carmen, DetectedSentinelReadingsAreMaxRange) {
  CarmenReadStats stats;
  const Log log = Parse(LogWithSentinel(), {}, &stats);
  ASSERT_TRUE(stats.detected_max_range);
  EXPECT_DOUBLE_EQ(*stats.detected_max_range, 81.33);
  for (const Scan& scan : log.scans) {
    EXPECT_EQ(scan.max_range, *stats.detected_max_range);
    EXPECT_THAT(scan.status,
                ElementsAre(BeamStatus::kValid, BeamStatus::kMaxRange, BeamStatus::kValid,
                            BeamStatus::kMaxRange, BeamStatus::kValid));
  }
}

TEST(Carmen, AShorterMaxRangeOptionOverridesDetection) {
  CarmenReadOptions options;
  options.max_range = 20.0;
  CarmenReadStats stats;
  const Log log = Parse(LogWithSentinel(), options, &stats);
  EXPECT_TRUE(stats.detected_max_range);  // still reported
  for (const Scan& scan : log.scans) {
    EXPECT_EQ(scan.max_range, 20.0);
    EXPECT_EQ(scan.status[2], BeamStatus::kMaxRange);  // 25 m
  }
}

// A longer one would make the no-return readings walls at 81.83 m: the sensor's stays.
TEST(Carmen, ALongerMaxRangeOptionDoesNotMakeTheSentinelsReturns) {
  CarmenReadOptions options;
  options.max_range = 100.0;
  const Log log = Parse(LogWithSentinel() + kRobotLaser, options);
  for (const Scan& scan : log.scans) EXPECT_LE(scan.max_range, 81.33) << scan.channel;
  EXPECT_EQ(log.scans.front().status[1], BeamStatus::kMaxRange);  // a sentinel
  EXPECT_DOUBLE_EQ(log.scans.back().max_range, 20.0);             // ROBOTLASER1's own
  // Where the sensor has none, the option is the max range.
  const Log plain = Parse(Flaser({1, 100, 1000}), options);
  EXPECT_EQ(plain.scans.at(0).max_range, 100.0);
  EXPECT_EQ(plain.scans.at(0).status[2], BeamStatus::kMaxRange);
}

// A record's own max range is data; sentinel detection is a heuristic for records without one.
TEST(Carmen, RobotLaserOwnMaxRangeWinsOverTheDetectedSentinel) {
  const Log log = Parse(LogWithSentinel() + kRobotLaser);
  const Scan& robot_laser = log.scans.back();
  EXPECT_EQ(robot_laser.channel, "ROBOTLASER1");
  EXPECT_DOUBLE_EQ(robot_laser.max_range, 20.0);
  EXPECT_EQ(robot_laser.status[3], BeamStatus::kMaxRange);  // 25 m, beyond the record's 20 m
  EXPECT_DOUBLE_EQ(log.scans.front().max_range, 81.33);     // the FLASER scans keep the sentinel
}

TEST(Carmen, NoSentinelAndNoOptionMeansNoMaxRange) {
  CarmenReadStats stats;
  const Log log = Parse(Flaser({1, 100, 1000}), {}, &stats);
  EXPECT_EQ(stats.detected_max_range, std::nullopt);
  EXPECT_EQ(log.scans.at(0).max_range, kInf);
  EXPECT_EQ(log.scans.at(0).NumValid(), 3U);
}

// ---- writing ----

const std::string kEveryRecordType =
    "PARAM robot_front_laser_max 81.9\n"
    "PARAM robot_name a robot  with spaces\n"
    "PARAM empty\n"
    "FLASER 3 1.5 nan 2.5 1 2 0.5 1.1 2.1 0.6 12.5 host 12.75\n"
    "RLASER 2 4 -0 1 2 0.5 1.1 2.1 0.6\n"
    "ODOM 1 2 3 0.1 0.2 0.3 13 host 13.5\n"
    "ODOM -1e-300 1e9 -3.14159 nan inf -inf\n"
    "TRUEPOS 1 2 3 4 5 6 14 host 14.5\n"
    "TRUEPOS 0.1 0.2 0.3 0.4 0.5 0.6\n" +
    Flaser(Continuous(181)) +
    "FLASER 0 0 0 0 0 0 0\n"
    "ROBOTLASER1 0 0.25 0 0 inf 0 0 1 3 0 0 0 0 0 0 0 0 0 0 0 0\n" +
    kRobotLaser;

TEST(Carmen, FormatThenParseGivesTheSameLog) {
  const Log log = Parse(kEveryRecordType);
  ASSERT_EQ(log.scans.size(), 6U);
  const std::string text = FormatCarmenLog(log);
  const Log again = Parse(text);
  EXPECT_TRUE(SameLog(again, log)) << text;
  EXPECT_EQ(FormatCarmenLog(again), text);
}

TEST(Carmen, FormatThenParseKeepsDetectedMaxRange) {
  const Log log = Parse(LogWithSentinel());
  EXPECT_TRUE(SameLog(Parse(FormatCarmenLog(log)), log));
}

TEST(Carmen, NegativeNanIsReadAsThePlainNan) {
  // A NaN's sign means nothing, and JSON (null) cannot keep it: "-nan" is written back "nan".
  const Log log = Parse("ODOM 1 2 0.5 0.1 -nan 0.3\nFLASER 2 -nan 1.5 1 2 0.5 1.1 2.1 0.6\n");
  EXPECT_FALSE(std::signbit(log.odometry.at(0).rv));
  EXPECT_FALSE(std::signbit(log.scans.at(0).ranges[0]));
  EXPECT_THAT(FormatCarmenLog(log),
              HasSubstr("ODOM 1 2 0.5 0.1 nan 0.3\nFLASER 2 nan 1.5 1 2 0.5 1.1 2.1 0.6\n"));
}

TEST(Carmen, FormatWritesEveryRecordInOrder) {
  const std::string text = FormatCarmenLog(
      Parse("ODOM 1 2 0.5 0 0 0 1 h 2\nPARAM a b c\nFLASER 2 1.5 nan 1 2 0.5 1.1 2.1 0.6\n"));
  EXPECT_EQ(text,
            "# written by priormap; record formats as in docs/formats.md\n"
            "ODOM 1 2 0.5 0 0 0 1 h 2\n"
            "PARAM a b c\n"
            "FLASER 2 1.5 nan 1 2 0.5 1.1 2.1 0.6\n");
}

// A log built in code, with the fields a CARMEN reader would give it.
Log BuiltLog() {
  Log log;
  Scan scan;
  scan.channel = "FLASER";
  scan.timestamp = 7.25;
  scan.pose = Se2(1, 2, 3);
  scan.odom_pose = Se2(-1, -2, -3);
  scan.ranges = {1.0 / 3, 2.0 / 3, kNaN, 4};
  scan.angles = FlaserBeamAngles(4, kPi);
  scan.sigma.assign(4, 0.01);
  scan.ClassifyAll();
  scan.carmen = CarmenLaserFields{};
  scan.carmen->host = "built";
  scan.carmen->logger_timestamp = 7.5;
  log.scans.push_back(scan);
  OdometryRecord odom;
  odom.timestamp = 8;
  odom.pose = Se2(0.1, 0.2, 0.3);
  odom.tv = 1.0 / 7;
  odom.carmen = CarmenRecordFields{};
  log.odometry.push_back(odom);
  TruePoseRecord truth;
  truth.true_pose = Se2(4, 5, 6);
  truth.odom_pose = Se2(7, 8, 9);
  truth.carmen = CarmenRecordFields{false, "nohost", 0.0};
  log.true_poses.push_back(truth);
  log.params.emplace_back("name", "value with spaces");
  return log;
}

TEST(Carmen, BuiltLogSurvivesFormatThenParse) {
  const Log log = BuiltLog();
  Log again = Parse(FormatCarmenLog(log));
  EXPECT_TRUE(SameLog(again, log));
}

TEST(Carmen, EvenlySpacedNonFlaserAnglesAreWrittenAsRobotLaser) {
  // Simulated scans carry angles from EvenlySpacedAngles; CARMEN keeps them bit for bit.
  for (const std::size_t n : {2U, 7U, 541U, 1081U}) {
    Log log;
    Scan scan;
    scan.channel = "SIM";
    scan.angles = EvenlySpacedAngles(n, -DegToRad(135), DegToRad(135));
    scan.ranges.resize(n);
    for (std::size_t i = 0; i < n; ++i) scan.ranges[i] = 1.0 + 0.01 * static_cast<double>(i);
    scan.sigma.assign(n, 0.01);
    scan.max_range = 30.0;
    scan.ClassifyAll();
    log.scans.push_back(scan);
    const std::string text = FormatCarmenLog(log);
    EXPECT_THAT(text, HasSubstr("\nROBOTLASER1 "));
    const Scan again = Parse(text).scans.at(0);
    EXPECT_EQ(again.channel, "ROBOTLASER1");
    EXPECT_EQ(again.angles, scan.angles) << "n = " << n;
    EXPECT_EQ(again.max_range, 30.0);
  }
}

TEST(Carmen, WriterRefusesUnevenlySpacedAngles) {
  Log log = BuiltLog();
  Scan& scan = log.scans[0];
  scan.channel = "SIM";
  scan.angles = {0.0, 0.1, 0.3, 0.4};
  try {
    (void)FormatCarmenLog(log);
    FAIL() << "expected IoError";
  } catch (const IoError& e) {
    EXPECT_THAT(e.what(), HasSubstr("scan 0 has unevenly spaced beam angles"));
  }
  const testing::TempDir dir;
  EXPECT_THROW(WriteCarmenLog(log, dir / "uneven.log"), IoError);
  EXPECT_FALSE(std::filesystem::exists(dir / "uneven.log"));
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

// Expects FormatCarmenLog(log) to throw an IoError whose message contains `message_part`.
void ExpectRefused(const Log& log, const std::string& message_part) {
  try {
    (void)FormatCarmenLog(log);
    ADD_FAILURE() << "expected IoError containing: " << message_part;
  } catch (const IoError& e) {
    EXPECT_THAT(e.what(), HasSubstr(message_part));
  }
}

TEST(Carmen, WriterRefusesWhatACarmenLineCannotHold) {
  // Such logs come from JSON or code; written as they are, they would be rejected or misread.
  Log log = BuiltLog();
  log.params[0].first = "two words";
  ExpectRefused(
      log, "param 0 has name 'two words', which a CARMEN log cannot hold (it must be one word)");
  log = BuiltLog();
  log.params[0].first = "";
  ExpectRefused(log, "param 0 has name ''");
  log = BuiltLog();
  log.params[0].second = "line\nbreak";
  ExpectRefused(log, "param 0 (name) has a line break in its value");
  log = BuiltLog();
  log.scans[0].carmen->host = "my host";
  ExpectRefused(log, "scan 0 has host 'my host'");
  log = BuiltLog();
  log.odometry[0].carmen->host = "";
  ExpectRefused(log, "odometry record 0 has host ''");
  log = BuiltLog();
  log.odometry[0].timestamp = kNaN;
  ExpectRefused(
      log,
      "odometry record 0 has timestamp nan, which a CARMEN log cannot hold (it must be finite)");
  log = BuiltLog();
  log.true_poses[0].carmen.reset();
  log.true_poses[0].timestamp = kInf;
  ExpectRefused(log, "true pose record 0 has timestamp inf");
  log = BuiltLog();
  log.scans[0].carmen->logger_timestamp = -kInf;
  ExpectRefused(log, "scan 0 has logger_timestamp -inf");
  log = BuiltLog();
  log.scans[0].odom_pose = Se2(kNaN, 0, 0);
  ExpectRefused(log, "scan 0 has a non-finite odometry pose");
  log = BuiltLog();
  log.true_poses[0].odom_pose = Se2(0, kInf, 0);
  ExpectRefused(log, "true pose record 0 has a non-finite odometry pose");
  log = BuiltLog();
  log.scans[0].channel = "ROBOTLASER1";
  log.scans[0].carmen->fov = kInf;
  ExpectRefused(log, "scan 0 has field of view inf");
  log = BuiltLog();
  log.scans[0].channel = "SIM";
  log.scans[0].angles = {0.3, 0.2, 0.1, 0.0};
  ExpectRefused(log, "scan 0 has beam angles that do not increase");
  log.scans[0].angles = {0.0, kNaN, 0.2, 0.3};
  ExpectRefused(log, "scan 0 has unevenly spaced beam angles");
  // Records without timestamps need none of those fields.
  log = BuiltLog();
  log.true_poses[0].timestamp = kNaN;  // has_timestamps is false: not written
  EXPECT_NO_THROW((void)FormatCarmenLog(log));
}

// A program could build a log with a position of 1e300 and write it, making a file that the
// reader refuses: the writer refuses it, naming the record and field, and writes nothing.
TEST(Carmen, WriterRefusesWhatTheReaderWouldAndKeepsTheOldFile) {
  Log log = BuiltLog();
  log.scans[0].pose = Se2(1e300, 0, 0);
  ExpectRefused(log, "cannot write the log: scan 0: pose x = 1e+300, beyond 1e+09 m in magnitude");
  log = BuiltLog();
  log.odometry[0].pose = Se2(0, -2e9, 0);
  ExpectRefused(log, "odometry record 0: pose y = -2000000000");
  log = BuiltLog();
  log.true_poses[0].true_pose = Se2(1.5e9, 0, 0);
  ExpectRefused(log, "true pose record 0: true_pose x = 1500000000");
  log = BuiltLog();
  log.scans[0].max_range = kInf;
  log.scans[0].ranges[1] = 1e300;  // a return
  log.scans[0].ClassifyAll();
  ExpectRefused(log, "scan 0: reading 1 = 1e+300 m, a return (below max_range inf m)");
  const testing::TempDir dir;
  testing::WriteAll(dir / "log.log", "old");
  EXPECT_THROW(WriteCarmenLog(log, dir / "log.log"), IoError);
  EXPECT_EQ(testing::ReadAll(dir / "log.log"), "old");
  EXPECT_EQ(testing::FilesIn(dir.path()), std::vector<std::string>{"log.log"});
}

// A no-return of 1e300 m is kept by the reader, but a FLASER line cannot hold its max range: read
// back, it would be a return, which the reader refuses. ROBOTLASER1 holds the max range.
TEST(Carmen, WriterRefusesANoReturnBeyondTheWorldThatWouldReadBackAsAReturn) {
  Log log = BuiltLog();
  log.scans[0].max_range = 30.0;
  log.scans[0].ranges[1] = 1e300;
  log.scans[0].ClassifyAll();
  ASSERT_EQ(log.scans[0].status[1], BeamStatus::kMaxRange);
  ExpectRefused(log,
                "cannot write the log as CARMEN: scan 0: reading 1 = 1e+300 m would read back as "
                "a return (below the max range inf m that the reader would find)");
  log.scans[0].channel = "ROBOTLASER1";
  const Log again = Parse(FormatCarmenLog(log));
  EXPECT_EQ(again.scans.at(0).ranges.at(1), 1e300);
  EXPECT_EQ(again.scans.at(0).status.at(1), BeamStatus::kMaxRange);
}

TEST(Carmen, ReadsGzipCompressedLogs) {
  const testing::TempDir dir;
  WriteTextFileAtomically(dir / "log.gz", kEveryRecordType);
  const std::string bytes = testing::ReadAll(dir / "log.gz");
  ASSERT_GE(bytes.size(), 2U);
  EXPECT_EQ(bytes.substr(0, 2), "\x1f\x8b");  // really compressed
  const Result<Log> read = ReadCarmenLog(dir / "log.gz");
  ASSERT_TRUE(read.ok()) << read.error();
  EXPECT_TRUE(SameLog(read.value(), Parse(kEveryRecordType)));
}

TEST(Carmen, WriteThenReadGivesTheSameLog) {
  const testing::TempDir dir;
  const Log log = Parse(kEveryRecordType);
  for (const std::string name : {"out.log", "out.log.gz"}) {
    WriteCarmenLog(log, dir / name);
    CarmenReadStats stats;
    const Result<Log> read = ReadCarmenLog(dir / name, {}, &stats);
    ASSERT_TRUE(read.ok()) << read.error();
    EXPECT_TRUE(SameLog(read.value(), log)) << name;
    EXPECT_EQ(stats.comment_lines, 1);  // the writer's header
  }
}

// Any log the reader accepts is written back so that reading it again gives the same log.
RC_GTEST_PROP(Carmen, FormatInvertsParseForRandomLogs, ()) {
  const auto number =
      rc::gen::oneOf(rc::gen::element(0.0, -0.0, 1.5, kNaN, kInf, -kInf, 81.83, 1e-300, 1e300),
                     rc::gen::map(rc::gen::arbitrary<int>(), [](int v) { return v / 1000.0; }),
                     rc::gen::arbitrary<double>());
  const auto finite = rc::gen::suchThat(number, [](double v) { return std::isfinite(v); });
  // Positions within the world, as the reader requires: any finite number folded into it.
  const auto coordinate = rc::gen::map(
      finite, [](double v) { return IsWithinWorld(v) ? v : std::fmod(v, kMaxWorldCoordinate); });
  // Readings too, as the reader refuses a return longer than the world's bound (a longer
  // no-return reading is kept as read: CarmenMalformed tests it).
  const auto reading = rc::gen::map(number, [](double v) {
    return IsReturnWithinWorld(v) || !std::isfinite(v) ? v : std::fmod(v, kMaxWorldCoordinate);
  });
  std::ostringstream text;
  text.precision(17);
  const int records = *rc::gen::inRange(1, 8);
  for (int k = 0; k < records; ++k) {
    const auto pose = [&] { text << ' ' << *coordinate << ' ' << *coordinate << ' ' << *finite; };
    const auto timestamps = [&] {
      if (*rc::gen::arbitrary<bool>()) {
        text << ' ' << *finite << ' ' << *rc::gen::element<std::string>("nohost", "h", "1") << ' '
             << *finite;
      }
    };
    switch (*rc::gen::inRange(0, 5)) {
      case 0: {
        const std::size_t n =
            *rc::gen::elementOf(std::vector<std::size_t>{0, 1, 3, 180, 181, 360, 361});
        text << *rc::gen::element<std::string>("FLASER", "RLASER") << ' ' << n;
        for (std::size_t i = 0; i < n; ++i) text << ' ' << *reading;
        pose();
        pose();
        timestamps();
        break;
      }
      case 1: {
        const std::size_t n = *rc::gen::inRange<std::size_t>(0, 20);
        const std::size_t m = *rc::gen::inRange<std::size_t>(0, 3);
        text << "ROBOTLASER1 " << *rc::gen::inRange(-5, 5) << ' '
             << *rc::gen::map(rc::gen::inRange(-400, 400), [](int v) { return v / 100.0; }) << ' '
             << *finite << ' '
             << *rc::gen::map(rc::gen::inRange(1, 1000), [](int v) { return v / 1000.0; }) << ' '
             << *number << ' ' << *number << ' ' << *rc::gen::inRange(0, 3) << ' ' << n;
        for (std::size_t i = 0; i < n; ++i) text << ' ' << *reading;
        text << ' ' << m;
        for (std::size_t i = 0; i < m; ++i) text << ' ' << *number;
        pose();
        pose();
        for (int i = 0; i < 5; ++i) text << ' ' << *number;
        timestamps();
        break;
      }
      case 2:
        text << "ODOM";
        pose();
        for (int i = 0; i < 3; ++i) text << ' ' << *number;
        timestamps();
        break;
      case 3:
        text << "TRUEPOS";
        pose();
        pose();
        timestamps();
        break;
      default:
        text << "PARAM " << *rc::gen::element<std::string>("a", "b_c", "#x") << ' '
             << *rc::gen::element<std::string>("", "1", "two words", " leading", "tab\tinside");
        break;
    }
    text << '\n';
  }
  RC_LOG() << text.str();
  const Result<Log> first = ParseCarmenLog(text.str(), "random.log");
  if (!first.ok()) RC_FAIL(first.error());
  const std::string written = FormatCarmenLog(first.value());
  RC_LOG() << written;
  const Result<Log> second = ParseCarmenLog(written, "written.log");
  if (!second.ok()) RC_FAIL(second.error());
  const ::testing::AssertionResult same = SameLog(second.value(), first.value());
  if (!same) RC_FAIL(same.message());
  RC_ASSERT(FormatCarmenLog(second.value()) == written);
}

}  // namespace
}  // namespace priormap
