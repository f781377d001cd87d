// JSON documents: scans, logs and scenes are written and read back without changing a bit, in a
// readable form (compact angles, one sigma, statuses only when they cannot be derived).
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/carmen_io.hpp>
#include <priormap/core/file_io.hpp>
#include <priormap/core/json_io.hpp>
#include <priormap/core/log_io.hpp>
#include <priormap/core/simulate.hpp>
#include <priormap/core/world_bounds.hpp>

#include "testing/log_equality.hpp"
#include "testing/temp_dir.hpp"

namespace priormap {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using testing::SameLog;
using testing::SameScan;
using testing::SameScene;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// ---- helpers ----

Log ParseLog(const std::string& text) {
  Result<Log> result = ParseJsonLog(text, "test.json");
  if (!result.ok()) ADD_FAILURE() << result.error() << "\n" << text;
  return result.ok() ? std::move(result).value() : Log{};
}

// A scan that uses every field: ground truth, correlated noise, CARMEN fields, readings that
// are not finite, statuses that the readings do not imply, unevenly spaced angles.
Scan RichScan() {
  Scan scan;
  scan.channel = "ROBOTLASER1";
  scan.timestamp = 1234567.123456789;
  scan.pose = Se2(1.0 / 3, -2.0 / 7, 3.0);
  scan.robot_pose = Se2(0.1, 0.2, -0.3);
  scan.odom_pose = Se2(-1e-300, -kMaxWorldCoordinate, kPi);  // at the world's bound
  scan.angles = {-1.0, -0.3, 0.0, 1e-9, 0.7, 2.5};
  scan.ranges = {1.5, kNaN, kInf, -kInf, 0.0, 7.25};
  scan.sigma = {0.01, 0.02, 0.03, 0.04, 0.05, 1.0 / 3};
  scan.min_range = 0.05;
  scan.max_range = 7.0;
  scan.ClassifyAll();
  scan.status[0] = BeamStatus::kInvalid;  // flagged, not derivable from 1.5 m
  scan.precision = SymmetricBandedMatrix::Ar1Precision(scan.sigma, 0.4);
  ScanTruth& truth = scan.truth.emplace();
  truth.range = {1.4, kNaN, 3, 4, 5, 6};
  truth.alpha = {0.1, kNaN, -0.2, 0.3, -kPi, kPi};
  truth.surface = {0, -1, 1, 1, 2, 3};
  truth.region = {0, -1, 4, 5, 6, 7};
  truth.outlier = {1, 0, 0, 0, 0, 1};
  CarmenLaserFields& c = scan.carmen.emplace();
  c.has_timestamps = false;
  c.host = "a \"quoted\" host\\with\tescapes";
  c.logger_timestamp = 99.5;
  c.laser_type = 4;
  c.start_angle = -1.0;
  c.fov = 3.5;
  c.angular_resolution = 0.25;
  c.accuracy = 0.001;
  c.remission_mode = 2;
  c.remissions = {0.5, kNaN, 1e-310};
  c.tv = -0.5;
  c.rv = 0.25;
  c.forward_safety_dist = 0.3;
  c.side_safety_dist = 0.2;
  c.turn_axis = 1e6;
  EXPECT_TRUE(scan.Problems().empty());
  return scan;
}

Scan FlaserScan(std::size_t n) {
  Scan scan;
  scan.angles = FlaserBeamAngles(n, kPi);
  scan.ranges.resize(n);
  for (std::size_t i = 0; i < n; ++i) scan.ranges[i] = 0.5 + 0.01 * static_cast<double>(i);
  scan.sigma.assign(n, 0.01);
  scan.odom_pose = Se2(1, 2, 3);
  scan.ClassifyAll();
  return scan;
}

// A log with every kind of record, interleaved (as readers build them: records of one kind in
// the order of their indices).
Log RichLog() {
  Log log;
  log.pose_source = PoseSource::kCorrected;
  log.scans = {RichScan(), FlaserScan(180), FlaserScan(0)};
  OdometryRecord odom;
  odom.timestamp = 12.5;
  odom.pose = Se2(1, 2, 0.5);
  odom.tv = 0.1;
  odom.rv = -0.2;
  odom.accel = 0.3;
  odom.carmen = CarmenRecordFields{true, "host", 12.75};
  log.odometry = {odom, OdometryRecord{}};
  TruePoseRecord truth;
  truth.timestamp = 13;
  truth.true_pose = Se2(4, 5, 6);
  truth.odom_pose = Se2(4.1, 5.1, 6.1);
  truth.carmen = CarmenRecordFields{false, "nohost", 0.0};
  log.true_poses = {truth};
  log.params = {{"name", "value with spaces"}, {"quoted", "\"q\" \\ \n"}, {"empty", ""}};
  using K = Log::RecordKind;
  log.order = {{K::kParam, 0},    {K::kScan, 0}, {K::kOdometry, 0},
               {K::kTruePose, 0}, {K::kScan, 1}, {K::kParam, 1},
               {K::kOdometry, 1}, {K::kScan, 2}, {K::kParam, 2}};
  EXPECT_TRUE(log.Problems().empty());
  return log;
}

// ---- scans ----

TEST(JsonIo, RichScanRoundTripsBitExact) {
  const Scan scan = RichScan();
  const std::string text = FormatJsonScan(scan);
  const Log log = ParseLog(text);
  ASSERT_EQ(log.scans.size(), 1U);
  EXPECT_TRUE(SameScan(log.scans[0], scan)) << text;
}

TEST(JsonIo, ScanDocumentReadsAsALogWithOneScan) {
  const Log log = ParseLog(FormatJsonScan(FlaserScan(181)));
  EXPECT_EQ(log.scans.size(), 1U);
  EXPECT_EQ(log.NumRecords(), 1U);
  EXPECT_EQ(log.pose_source, PoseSource::kUnknown);
  EXPECT_EQ(log.RecordOrder(), (std::vector<Log::RecordRef>{{Log::RecordKind::kScan, 0}}));
  EXPECT_TRUE(log.Problems().empty());
}

TEST(JsonIo, ScanDocumentStartsWithFormatAndVersion) {
  const std::string text = FormatJsonScan(FlaserScan(3));
  EXPECT_EQ(text.rfind("{\n  \"format\": \"priormap.scan\",\n  \"version\": 1,\n", 0), 0U) << text;
}

TEST(JsonIo, EvenlySpacedAnglesAreWrittenCompactly) {
  for (const std::size_t n : {180U, 181U, 360U, 361U}) {
    const Scan scan = FlaserScan(n);
    const std::string text = FormatJsonScan(scan);
    EXPECT_THAT(text, HasSubstr("\"angle_min\": -1.5707963267948966,\n")) << n;
    EXPECT_THAT(text, HasSubstr("\"angle_increment\": ")) << n;
    EXPECT_THAT(text, Not(HasSubstr("\"angles\""))) << n;
    EXPECT_EQ(ParseLog(text).scans.at(0).angles, scan.angles) << n;
  }
  // 1 degree steps, as in an LMS200 with 181 beams.
  EXPECT_THAT(FormatJsonScan(FlaserScan(181)),
              HasSubstr("\"angle_increment\": 0.017453292519943295,\n"));
}

TEST(JsonIo, CompactAnglesReproduceSimulatedSensorAngles) {
  // EvenlySpacedAngles' step may be an ulp away from (last - first) / (n - 1) as recomputed.
  for (const int n : {2, 3, 541, 1081, 1440}) {
    Scan scan = FlaserScan(static_cast<std::size_t>(n));
    scan.angles = EvenlySpacedAngles(static_cast<std::size_t>(n), -DegToRad(135), DegToRad(135));
    const std::string text = FormatJsonScan(scan);
    EXPECT_THAT(text, HasSubstr("\"angle_increment\"")) << n;
    EXPECT_EQ(ParseLog(text).scans.at(0).angles, scan.angles) << n;
  }
}

TEST(JsonIo, UnevenAnglesAreWrittenInFull) {
  const std::string text = FormatJsonScan(RichScan());
  EXPECT_THAT(text, HasSubstr("\"angles\": [-1.0,-0.3,0.0,1e-09,0.7,2.5]"));
  EXPECT_THAT(text, Not(HasSubstr("angle_min")));
}

TEST(JsonIo, UniformSigmaIsWrittenOnce) {
  EXPECT_THAT(FormatJsonScan(FlaserScan(180)), HasSubstr("\"sigma\": 0.01\n"));
  EXPECT_THAT(FormatJsonScan(RichScan()), HasSubstr("\"sigma\": [0.01,0.02,"));
}

TEST(JsonIo, StatusesAreWrittenOnlyWhenTheReadingsDoNotImplyThem) {
  EXPECT_THAT(FormatJsonScan(FlaserScan(180)), Not(HasSubstr("\"status\"")));
  EXPECT_THAT(FormatJsonScan(RichScan()),
              HasSubstr("\"status\": [\"invalid\",\"invalid\",\"invalid\",\"invalid\","
                        "\"invalid\",\"max_range\"]"));
}

TEST(JsonIo, NonFiniteNumbersAreNullOrStrings) {
  const std::string text = FormatJsonScan(RichScan());
  EXPECT_THAT(text, HasSubstr("\"ranges\": [1.5,null,\"inf\",\"-inf\",0.0,7.25]"));
  Scan scan = FlaserScan(3);
  scan.max_range = kInf;
  EXPECT_THAT(FormatJsonScan(scan), HasSubstr("\"max_range\": \"inf\""));
}

TEST(JsonIo, EmptyScanRoundTrips) {
  const Scan scan = FlaserScan(0);
  EXPECT_TRUE(SameScan(ParseLog(FormatJsonScan(scan)).scans.at(0), scan));
}

// ---- logs ----

TEST(JsonIo, RichLogRoundTripsBitExactInOrder) {
  const Log log = RichLog();
  const std::string text = FormatJsonLog(log);
  const Log again = ParseLog(text);
  EXPECT_TRUE(SameLog(again, log)) << text;
  EXPECT_EQ(again.order, log.order);
  EXPECT_EQ(FormatJsonLog(again), text);
}

TEST(JsonIo, LogWithoutOrderIsWrittenInTheDefaultOrder) {
  Log log = RichLog();
  log.order.clear();
  const Log again = ParseLog(FormatJsonLog(log));
  EXPECT_EQ(again.order, log.RecordOrder());
  EXPECT_TRUE(SameLog(again, log));
}

TEST(JsonIo, RecordsAreReadBackInTheOrderTheyWereWritten) {
  // An order that lists the scans out of index order: the file holds the records in `order`,
  // and reading gives them indices in that order; the sequence of records is unchanged.
  Log log = RichLog();
  using K = Log::RecordKind;
  log.order = {{K::kScan, 2}, {K::kParam, 1},    {K::kScan, 0},  {K::kOdometry, 1}, {K::kParam, 0},
               {K::kScan, 1}, {K::kTruePose, 0}, {K::kParam, 2}, {K::kOdometry, 0}};
  ASSERT_TRUE(log.Problems().empty());
  const std::string text = FormatJsonLog(log);
  const Log again = ParseLog(text);
  EXPECT_EQ(again.order, (std::vector<Log::RecordRef>{{K::kScan, 0},
                                                      {K::kParam, 0},
                                                      {K::kScan, 1},
                                                      {K::kOdometry, 0},
                                                      {K::kParam, 1},
                                                      {K::kScan, 2},
                                                      {K::kTruePose, 0},
                                                      {K::kParam, 2},
                                                      {K::kOdometry, 1}}));
  EXPECT_TRUE(SameScan(again.scans[0], log.scans[2]));
  EXPECT_TRUE(SameScan(again.scans[2], log.scans[1]));
  EXPECT_EQ(again.params[0], log.params[1]);
  EXPECT_EQ(FormatJsonLog(again), text);
}

TEST(JsonIo, LogIsWrittenOneRecordPerLine) {
  const std::string text = FormatJsonLog(RichLog());
  EXPECT_EQ(text.rfind("{\"format\":\"priormap.log\",\"version\":1,\"pose_source\":\"corrected\","
                       "\"records\":[\n{\"type\":\"param\",\"name\":\"name\",\"value\":"
                       "\"value with spaces\"},\n",
                       0),
            0U)
      << text;
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 11);  // header, 9 records, end
}

TEST(JsonIo, CarmenLogRoundTripsIncludingNonFiniteCarmenFields) {
  // The CARMEN reader accepts any number in the velocity and safety fields.
  const Result<Log> carmen = ParseCarmenLog(
      "ODOM 1 2 0.5 inf -inf nan 1.5 host 2.5\n"
      "ROBOTLASER1 0 -1 2 1 20 inf 0 3 1 2 3 1 -inf 0 0 0 0 0 0 inf -inf nan inf -inf\n"
      "FLASER 3 1 nan 81.83 0 0 0 0 0 0\n"
      "PARAM name value\n",
      "in.log");
  ASSERT_TRUE(carmen.ok()) << carmen.error();
  const std::string text = FormatJsonLog(carmen.value());
  EXPECT_TRUE(SameLog(ParseLog(text), carmen.value())) << text;
}

TEST(JsonIo, TextThatIsNotUtf8IsWrittenWithReplacementCharacters) {
  // Old logs may hold Latin-1 text: "\xd6rebro" is "Oerebro" with a Latin-1 O-umlaut.
  const Result<Log> carmen =
      ParseCarmenLog("PARAM place \xd6rebro\nODOM 0 0 0 0 0 0 1 h\xf6st 2\n", "in.log");
  ASSERT_TRUE(carmen.ok()) << carmen.error();
  const Log log = ParseLog(FormatJsonLog(carmen.value()));
  ASSERT_EQ(log.params.size(), 1U);
  EXPECT_EQ(log.params[0].second, "\xef\xbf\xbdrebro");  // U+FFFD
  EXPECT_EQ(log.odometry.at(0).carmen->host, "h\xef\xbf\xbdst");
  Scan scan = FlaserScan(2);
  scan.channel = "bad\xff";
  EXPECT_EQ(ParseLog(FormatJsonScan(scan)).scans.at(0).channel, "bad\xef\xbf\xbd");
  Scene scene = *BuiltinScene("square");
  scene.name = "\xe9t\xe9";
  const Result<Scene> read = ParseJsonScene(FormatJsonScene(scene), "scene.json");
  ASSERT_TRUE(read.ok()) << read.error();
  EXPECT_EQ(read.value().name, "\xef\xbf\xbdt\xef\xbf\xbd");
}

TEST(JsonIo, SimulatedLogRoundTripsBitExact) {
  const Scene scene = *BuiltinScene("l-room");
  RangeSensor sensor = *RangeSensor::Preset("utm30");
  sensor.correlation = 0.3;
  sensor.outlier_probability = 0.05;
  sensor.dropout_probability = 0.02;
  const std::vector<TimedPose> trajectory = TrajectoryFromWaypoints(scene.waypoints, 0.5, 2.0);
  ASSERT_GE(trajectory.size(), 3U);
  const Log log = SimulateLog(scene, sensor, trajectory, 42);
  ASSERT_FALSE(log.scans.empty());
  ASSERT_TRUE(log.scans[0].truth);
  ASSERT_TRUE(log.scans[0].precision);
  ASSERT_FALSE(log.odometry.empty());
  ASSERT_FALSE(log.true_poses.empty());
  const std::string text = FormatJsonLog(log);
  EXPECT_THAT(text, HasSubstr("\"angle_increment\""));
  EXPECT_TRUE(SameLog(ParseLog(text), log));
}

// Scans with arbitrary values in every field survive a round trip.
RC_GTEST_PROP(JsonIo, RandomScansRoundTrip, ()) {
  const auto number =
      rc::gen::oneOf(rc::gen::element(0.0, -0.0, 1.5, kNaN, kInf, -kInf, 1e-310, 1e300),
                     rc::gen::arbitrary<double>());
  const auto finite = rc::gen::suchThat(number, [](double v) { return std::isfinite(v); });
  const auto positive = rc::gen::suchThat(finite, [](double v) { return v > 0.0; });
  const auto numbers = [&](std::size_t n) {
    return *rc::gen::container<std::vector<double>>(n, number);
  };
  const std::size_t n = *rc::gen::inRange<std::size_t>(0, 12);
  Scan scan;
  scan.channel = *rc::gen::element<std::string>("FLASER", "SIM", "", "\"odd\" \\ name\n");
  scan.timestamp = *number;
  // Positions within the world, as the reader requires: any finite number folded into it.
  const auto coordinate = rc::gen::map(
      finite, [](double v) { return IsWithinWorld(v) ? v : std::fmod(v, kMaxWorldCoordinate); });
  scan.pose = Se2(*coordinate, *coordinate, *finite);
  if (*rc::gen::arbitrary<bool>()) scan.robot_pose = Se2(*coordinate, *coordinate, *finite);
  if (*rc::gen::arbitrary<bool>()) scan.odom_pose = Se2(*coordinate, *coordinate, *finite);
  double angle = *rc::gen::map(rc::gen::inRange(-400, 400), [](int v) { return v / 100.0; });
  const bool even = *rc::gen::arbitrary<bool>();
  const double step = *rc::gen::map(rc::gen::inRange(1, 10000), [](int v) { return v / 1e4; });
  for (std::size_t i = 0; i < n; ++i) {
    scan.angles.push_back(even ? scan.angles.empty() ? angle : scan.angles[0] + i * step : angle);
    angle += *rc::gen::map(rc::gen::inRange(1, 1000), [](int v) { return v / 997.0; });
  }
  scan.ranges = numbers(n);
  scan.sigma = *rc::gen::arbitrary<bool>() ? std::vector<double>(n, *positive)
                                           : *rc::gen::container<std::vector<double>>(n, positive);
  scan.min_range = *rc::gen::element(0.0, 0.1);
  scan.max_range = *rc::gen::element(kInf, 8.0, 81.41);
  scan.ClassifyAll();
  for (BeamStatus& s : scan.status) {
    if (*rc::gen::inRange(0, 4) == 0)
      s = *rc::gen::element(BeamStatus::kValid, BeamStatus::kMaxRange, BeamStatus::kInvalid);
  }
  if (*rc::gen::arbitrary<bool>())
    scan.precision = SymmetricBandedMatrix::Ar1Precision(scan.sigma, 0.5);
  if (*rc::gen::arbitrary<bool>()) {
    ScanTruth& truth = scan.truth.emplace();
    truth.range = numbers(n);
    truth.alpha = numbers(n);
    truth.surface = *rc::gen::container<std::vector<int>>(n, rc::gen::inRange(-1, 100000));
    truth.region = *rc::gen::container<std::vector<int>>(n, rc::gen::inRange(-1, 100000));
    truth.outlier =
        *rc::gen::container<std::vector<std::uint8_t>>(n, rc::gen::element<std::uint8_t>(0, 1));
  }
  if (*rc::gen::arbitrary<bool>()) {
    CarmenLaserFields& c = scan.carmen.emplace();
    c.has_timestamps = *rc::gen::arbitrary<bool>();
    c.host = *rc::gen::element<std::string>("nohost", "h", "");
    c.logger_timestamp = *number;
    c.laser_type = *rc::gen::arbitrary<int>();
    c.start_angle = *number;
    c.fov = *number;
    c.angular_resolution = *number;
    c.accuracy = *number;
    c.remission_mode = *rc::gen::arbitrary<int>();
    c.remissions = numbers(*rc::gen::inRange<std::size_t>(0, 4));
    c.tv = *number;
    c.rv = *number;
    c.forward_safety_dist = *number;
    c.side_safety_dist = *number;
    c.turn_axis = *number;
  }
  // Returns (and true ranges) within the world's bound, as the reader requires: any longer one
  // folded into it. A no-return reading keeps any value.
  const auto fold = [](double& v) {
    if (std::isfinite(v) && !IsReturnWithinWorld(v)) v = std::fmod(v, kMaxWorldCoordinate);
  };
  for (std::size_t i = 0; i < n; ++i)
    if (scan.status[i] == BeamStatus::kValid) fold(scan.ranges[i]);
  if (scan.truth) std::ranges::for_each(scan.truth->range, fold);
  RC_PRE(scan.Problems().empty());
  const std::string text = FormatJsonScan(scan);
  RC_LOG() << text;
  const Result<Log> read = ParseJsonLog(text, "random.json");
  if (!read.ok()) RC_FAIL(read.error());
  RC_ASSERT(read.value().scans.size() == 1U);
  const ::testing::AssertionResult same = SameScan(read.value().scans[0], scan);
  if (!same) RC_FAIL(same.message());
}

// ---- files ----

TEST(JsonIo, WriteThenReadLogFiles) {
  const testing::TempDir dir;
  const Log log = RichLog();
  for (const std::string name : {"log.json", "log.json.gz"}) {
    WriteJsonLog(log, dir / name);
    const Result<Log> read = ReadJsonLog(dir / name);
    ASSERT_TRUE(read.ok()) << read.error();
    EXPECT_TRUE(SameLog(read.value(), log)) << name;
    // ReadLog recognises JSON by its content.
    const Result<Log> sniffed = ReadLog(dir / name);
    ASSERT_TRUE(sniffed.ok()) << sniffed.error();
    EXPECT_TRUE(SameLog(sniffed.value(), log)) << name;
  }
  WriteJsonScan(RichScan(), dir / "scan.json");
  const Result<Log> scan = ReadJsonLog(dir / "scan.json");
  ASSERT_TRUE(scan.ok()) << scan.error();
  EXPECT_TRUE(SameScan(scan.value().scans.at(0), RichScan()));
}

// A program could build a log or a scene with a position of 1e300 and write it, making a file
// that the readers refuse: the writers refuse it, naming the record and field, before writing
// anything, so that an existing file is kept as it was.
TEST(JsonIo, WritersRefuseWhatTheReadersWouldAndKeepTheOldFile) {
  const testing::TempDir dir;
  testing::WriteAll(dir / "log.json", "old");
  const auto expect_refused = [&](const Log& log, const std::string& message_part) {
    try {
      WriteJsonLog(log, dir / "log.json");
      ADD_FAILURE() << "expected IoError containing: " << message_part;
    } catch (const IoError& e) {
      EXPECT_THAT(e.what(), HasSubstr(message_part));
    }
    EXPECT_EQ(testing::ReadAll(dir / "log.json"), "old");
    EXPECT_EQ(testing::FilesIn(dir.path()), std::vector<std::string>{"log.json"});
  };
  Log log = RichLog();
  log.scans[1].pose = Se2(1e300, 0, 0);
  expect_refused(log, "cannot write the log: scan 1: pose x = 1e+300, beyond 1e+09 m in magnitude");
  log = RichLog();
  log.scans[2].robot_pose = Se2(0, -2e9, 0);
  expect_refused(log, "scan 2: robot_pose y = -2000000000");
  log = RichLog();
  log.scans[1].ranges[7] = 1e300;  // a return: the scan has no max range
  log.scans[1].ClassifyAll();
  expect_refused(log, "scan 1: reading 7 = 1e+300 m, a return (below max_range inf m)");
  log = RichLog();
  log.odometry[1].pose = Se2(0, kNaN, 0);
  expect_refused(log, "odometry record 1: pose y = nan");
  log = RichLog();
  log.true_poses[0].odom_pose = Se2(-kInf, 0, 0);
  expect_refused(log, "true pose record 0: odom_pose x = -inf");
  // A no-return reading is written whatever its value, and read back.
  log = RichLog();
  log.scans[1].max_range = 30.0;
  log.scans[1].ranges[7] = 1e300;
  log.scans[1].ClassifyAll();
  WriteJsonLog(log, dir / "log.json");
  const Result<Log> read = ReadJsonLog(dir / "log.json");
  ASSERT_TRUE(read.ok()) << read.error();
  EXPECT_TRUE(SameLog(read.value(), log));

  Scan scan = FlaserScan(3);
  scan.odom_pose = Se2(3e9, 0, 0);
  EXPECT_THROW(WriteJsonScan(scan, dir / "scan.json"), IoError);
  EXPECT_FALSE(std::filesystem::exists(dir / "scan.json"));
}

TEST(JsonIo, SceneWriterRefusesWhatTheReaderWouldAndKeepsTheOldFile) {
  const testing::TempDir dir;
  testing::WriteAll(dir / "scene.json", "old");
  const auto expect_refused = [&](const Scene& scene, const std::string& message_part) {
    try {
      WriteJsonScene(scene, dir / "scene.json");
      ADD_FAILURE() << "expected IoError containing: " << message_part;
    } catch (const IoError& e) {
      EXPECT_THAT(e.what(), HasSubstr(message_part));
    }
    EXPECT_EQ(testing::ReadAll(dir / "scene.json"), "old");
    EXPECT_EQ(testing::FilesIn(dir.path()), std::vector<std::string>{"scene.json"});
  };
  Scene scene = *BuiltinScene("l-room");
  std::get<Polyline>(scene.surfaces[0].shape).points[1].y() = 1e300;
  expect_refused(scene, "cannot write the scene: surface 0: point 1 y = 1e+300");
  scene = *BuiltinScene("two-circles");
  std::get<Circle>(scene.surfaces[1].shape).center = Vec2(-1e9 + 0.25, 0);  // radius 0.35
  expect_refused(
      scene,
      "cannot write the scene: surface 1: expected a radius of at most 0.25 m, which "
      "keeps x and y of every point of the circle about (-999999999.75, 0) within ±1e+09 "
      "m, got 0.35; priormap's readers refuse it");
  scene = *BuiltinScene("square");
  scene.default_pose = Se2(0, 5e9, 0);
  expect_refused(scene, "default_pose y = 5000000000");
  scene = *BuiltinScene("square");
  scene.waypoints = {{0, 0}, {-1e20, 0}};
  expect_refused(scene, "waypoint 1 x = -1e+20");
}

TEST(JsonIo, WriteLogChoosesTheFormat) {
  const testing::TempDir dir;
  Log log = RichLog();
  log.scans.erase(log.scans.begin());      // uneven angles: not for CARMEN
  log.params[1].second = "no line break";  // neither are line breaks
  log.order.clear();
  WriteLog(log, dir / "log.json", LogFormat::kJson);
  EXPECT_EQ(SniffLogFormat(testing::ReadAll(dir / "log.json")), LogFormat::kJson);
  WriteLog(log, dir / "log.carmen", LogFormat::kCarmen);
  EXPECT_EQ(SniffLogFormat(testing::ReadAll(dir / "log.carmen")), LogFormat::kCarmen);
}

// JSON that is not an object goes to the JSON reader, whose error says where and what it expected,
// not to CARMEN's "no records found".
TEST(JsonIo, AJsonArrayIsReadAsJsonAndRefusedAtItsFirstCharacter) {
  EXPECT_EQ(SniffLogFormat(" \n[1, 2]"), LogFormat::kJson);
  const testing::TempDir dir;
  testing::WriteAll(dir / "array.json", "\n  [1, 2]\n");
  const Result<Log> log = ReadLog(dir / "array.json");
  ASSERT_FALSE(log.ok());
  EXPECT_THAT(log.error(), ::testing::HasSubstr("array.json:2:3: error: expected a priormap.log"));
}

// ---- scenes ----

TEST(JsonIo, BuiltinScenesRoundTripBitExact) {
  ASSERT_FALSE(BuiltinSceneNames().empty());
  for (const std::string& name : BuiltinSceneNames()) {
    const Scene scene = *BuiltinScene(name);
    const std::string text = FormatJsonScene(scene);
    const Result<Scene> read = ParseJsonScene(text, name + ".json");
    ASSERT_TRUE(read.ok()) << read.error();
    EXPECT_TRUE(SameScene(read.value(), scene)) << text;
  }
}

TEST(JsonIo, SceneWithEveryFieldRoundTrips) {
  Scene scene;
  scene.name = "every \"field\"";
  scene.surfaces.push_back({Polyline{{{0, 0}, {1.0 / 3, 0}, {1, 1e-300}}, true}, false, "room"});
  scene.surfaces.push_back({Polyline{{{5, 5}, {6, 5}}, false}, true, ""});
  // At the world's bound: the circle's far side at -kMaxWorldCoordinate.
  scene.surfaces.push_back({Circle{{-kMaxWorldCoordinate + 0.5, 2.5}, 0.5}, true, "bin"});
  scene.default_pose = Se2(0.5, -0.5, kPi);
  scene.waypoints = {{0, 0}, {1.0 / 7, 2}};
  ASSERT_TRUE(scene.Problems().empty());
  const testing::TempDir dir;
  WriteJsonScene(scene, dir / "scene.json");
  const Result<Scene> read = ReadJsonScene(dir / "scene.json");
  ASSERT_TRUE(read.ok()) << read.error();
  EXPECT_TRUE(SameScene(read.value(), scene));
}

TEST(JsonIo, SceneWithoutOptionalFieldsReadsWithDefaults) {
  const Result<Scene> read = ParseJsonScene(
      R"({"format": "priormap.scene", "version": 1, "surfaces": [
            {"type": "circle", "center": [1, 2], "radius": 0.5},
            {"type": "polyline", "points": [[0, 0], [1, 0]]}]})",
      "minimal.json");
  ASSERT_TRUE(read.ok()) << read.error();
  const Scene& scene = read.value();
  EXPECT_EQ(scene.name, "");
  EXPECT_FALSE(scene.default_pose);
  EXPECT_TRUE(scene.waypoints.empty());
  ASSERT_EQ(scene.surfaces.size(), 2U);
  EXPECT_FALSE(scene.surfaces[0].clutter);
  EXPECT_EQ(std::get<Circle>(scene.surfaces[0].shape).radius, 0.5);
  EXPECT_FALSE(std::get<Polyline>(scene.surfaces[1].shape).closed);
}

TEST(JsonIo, ScanWithoutOptionalFieldsReadsWithDefaults) {
  const Log log = ParseLog(
      R"({"format": "priormap.scan", "version": 1, "pose": [1, 2, 0.5],
          "angle_min": -1, "angle_increment": 0.5, "ranges": [1, null, "inf", 0.5, 9]})");
  const Scan& scan = log.scans.at(0);
  EXPECT_EQ(scan.channel, "FLASER");
  EXPECT_EQ(scan.timestamp, 0.0);
  EXPECT_EQ(scan.angles, (std::vector<double>{-1, -0.5, 0, 0.5, 1}));
  EXPECT_EQ(scan.sigma, std::vector<double>(5, 0.01));
  EXPECT_EQ(scan.max_range, kInf);
  EXPECT_EQ(scan.status,
            (std::vector<BeamStatus>{BeamStatus::kValid, BeamStatus::kInvalid, BeamStatus::kInvalid,
                                     BeamStatus::kValid, BeamStatus::kValid}));
  EXPECT_FALSE(scan.carmen);
  EXPECT_FALSE(scan.truth);
}

}  // namespace
}  // namespace priormap
