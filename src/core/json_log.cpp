// priormap.scan / priormap.log JSON documents (docs/formats.md).
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <utility>

#include <climits>
#include <fmt/format.h>

#include <priormap/core/file_io.hpp>
#include <priormap/core/json_io.hpp>
#include <priormap/core/world_bounds.hpp>

#include "angle_step.hpp"
#include "json_document.hpp"
#include "scan_time_order.hpp"

namespace priormap {
namespace {

using detail::JsonNode;
using detail::OrderedJson;

constexpr int kVersion = 1;
constexpr double kDefaultSigma = 0.01;

// Scalars go through NumberToJson like the arrays: nlohmann would write an infinity as null,
// which reads back as NaN (the CARMEN reader accepts any number in the velocity, accuracy and
// safety fields).
OrderedJson CarmenLaserToJson(const CarmenLaserFields& c) {
  OrderedJson j;
  j["has_timestamps"] = c.has_timestamps;
  j["host"] = c.host;
  j["logger_timestamp"] = detail::NumberToJson(c.logger_timestamp);
  j["laser_type"] = c.laser_type;
  j["start_angle"] = detail::NumberToJson(c.start_angle);
  j["fov"] = detail::NumberToJson(c.fov);
  j["angular_resolution"] = detail::NumberToJson(c.angular_resolution);
  if (c.maximum_range) j["maximum_range"] = detail::NumberToJson(*c.maximum_range);
  j["accuracy"] = detail::NumberToJson(c.accuracy);
  j["remission_mode"] = c.remission_mode;
  j["remissions"] = detail::NumbersToJson(c.remissions);
  j["tv"] = detail::NumberToJson(c.tv);
  j["rv"] = detail::NumberToJson(c.rv);
  j["forward_safety_dist"] = detail::NumberToJson(c.forward_safety_dist);
  j["side_safety_dist"] = detail::NumberToJson(c.side_safety_dist);
  j["turn_axis"] = detail::NumberToJson(c.turn_axis);
  return j;
}

OrderedJson CarmenRecordToJson(const CarmenRecordFields& c) {
  return {{"has_timestamps", c.has_timestamps},
          {"host", c.host},
          {"logger_timestamp", detail::NumberToJson(c.logger_timestamp)}};
}

OrderedJson SonarToJson(const SonarFields& sonar) {
  OrderedJson j;
  j["spread"] = detail::NumberToJson(sonar.spread);
  if (!sonar.origins.empty()) {
    OrderedJson origins = OrderedJson::array();
    for (const Vec2& o : sonar.origins)
      origins.push_back({detail::NumberToJson(o.x()), detail::NumberToJson(o.y())});
    j["origins"] = std::move(origins);
  }
  if (!sonar.true_echo.empty() || !sonar.true_feature.empty()) {
    OrderedJson echo = OrderedJson::array();
    for (SonarEcho e : sonar.true_echo) echo.push_back(ToString(e));
    j["true_echo"] = std::move(echo);
    j["true_feature"] = sonar.true_feature;
  }
  return j;
}

bool StatusesAreDerivable(const Scan& scan) {
  for (std::size_t i = 0; i < scan.size(); ++i) {
    if (scan.status[i] != ClassifyReading(scan.ranges[i], scan.min_range, scan.max_range))
      return false;
  }
  return true;
}

OrderedJson ScanToJson(const Scan& scan, OrderedJson j) {
  j["channel"] = scan.channel;
  j["timestamp"] = detail::NumberToJson(scan.timestamp);
  j["pose"] = detail::PoseToJson(scan.pose);
  if (scan.robot_pose) j["robot_pose"] = detail::PoseToJson(*scan.robot_pose);
  if (scan.odom_pose) j["odom_pose"] = detail::PoseToJson(*scan.odom_pose);
  j["min_range"] = detail::NumberToJson(scan.min_range);
  j["max_range"] = detail::NumberToJson(scan.max_range);
  if (const auto step = detail::ExactAngleStep(scan.angles)) {
    j["angle_min"] = scan.angles.front();
    j["angle_increment"] = *step;
  } else {
    j["angles"] = detail::NumbersToJson(scan.angles);
  }
  j["ranges"] = detail::NumbersToJson(scan.ranges);
  const bool uniform_sigma =
      !scan.sigma.empty() && std::all_of(scan.sigma.begin(), scan.sigma.end(),
                                         [&](double s) { return s == scan.sigma[0]; });
  j["sigma"] = uniform_sigma ? OrderedJson(scan.sigma[0]) : detail::NumbersToJson(scan.sigma);
  if (!StatusesAreDerivable(scan)) {
    OrderedJson status = OrderedJson::array();
    for (BeamStatus s : scan.status) status.push_back(ToString(s));
    j["status"] = std::move(status);
  }
  if (scan.precision) {
    OrderedJson bands = OrderedJson::array();
    const Eigen::MatrixXd& band = scan.precision->band();
    for (Eigen::Index k = 0; k < band.rows(); ++k) {
      bands.push_back(
          detail::NumbersToJson(std::vector<double>(band.row(k).begin(), band.row(k).end())));
    }
    j["precision"] = {{"bandwidth", scan.precision->bandwidth()}, {"bands", std::move(bands)}};
  }
  if (scan.truth) {
    j["true_range"] = detail::NumbersToJson(scan.truth->range);
    j["true_alpha"] = detail::NumbersToJson(scan.truth->alpha);
    j["true_surface"] = scan.truth->surface;
    j["true_region"] = scan.truth->region;
    j["true_outlier"] = scan.truth->outlier;
  }
  if (scan.carmen) j["carmen"] = CarmenLaserToJson(*scan.carmen);
  if (scan.sonar) j["sonar"] = SonarToJson(*scan.sonar);
  return j;
}

// ---- reading ----

std::optional<double> OptionalNumber(const JsonNode& object, const char* key,
                                     std::string_view what) {
  if (const auto node = detail::OptionalMember(object, key)) return detail::Number(*node, what);
  return std::nullopt;
}

std::optional<Se2> OptionalPose(const JsonNode& object, const char* key) {
  if (const auto node = detail::OptionalMember(object, key)) return detail::Pose(*node, key);
  return std::nullopt;
}

std::vector<double> SizedNumbers(const JsonNode& object, const char* key, std::size_t n) {
  const JsonNode node = detail::Member(object, key);
  std::vector<double> values = detail::Numbers(node, fmt::format("\"{}\"", key));
  if (values.size() != n)
    detail::Fail(node, fmt::format("expected {} values in \"{}\", got {}", n, key, values.size()));
  return values;
}

std::vector<int> SizedInts(const JsonNode& object, const char* key, std::size_t n, long long lo,
                           long long hi) {
  const JsonNode node = detail::Member(object, key);
  const std::vector<long long> values = detail::Integers(node, fmt::format("\"{}\"", key));
  if (values.size() != n)
    detail::Fail(node, fmt::format("expected {} values in \"{}\", got {}", n, key, values.size()));
  for (std::size_t i = 0; i < n; ++i) {
    if (values[i] < lo || values[i] > hi) {
      detail::Fail(
          detail::Element(node, i),
          fmt::format("expected values of \"{}\" in [{}, {}], got {}", key, lo, hi, values[i]));
    }
  }
  return {values.begin(), values.end()};
}

// Every key a reader takes, by object: any other is refused rather than ignored.
constexpr std::string_view kScanKeys[] = {
    "format",          "version",      "type",        "channel",      "timestamp", "pose",
    "robot_pose",      "odom_pose",    "min_range",   "max_range",    "angles",    "angle_min",
    "angle_increment", "ranges",       "sigma",       "status",       "precision", "true_range",
    "true_alpha",      "true_surface", "true_region", "true_outlier", "carmen",    "sonar"};
constexpr std::string_view kCarmenLaserKeys[] = {"has_timestamps",
                                                 "host",
                                                 "logger_timestamp",
                                                 "laser_type",
                                                 "start_angle",
                                                 "fov",
                                                 "angular_resolution",
                                                 "maximum_range",
                                                 "accuracy",
                                                 "remission_mode",
                                                 "remissions",
                                                 "tv",
                                                 "rv",
                                                 "forward_safety_dist",
                                                 "side_safety_dist",
                                                 "turn_axis"};
constexpr std::string_view kCarmenRecordKeys[] = {"has_timestamps", "host", "logger_timestamp"};
constexpr std::string_view kSonarKeys[] = {"spread", "origins", "true_echo", "true_feature"};
constexpr std::string_view kPrecisionKeys[] = {"bandwidth", "bands"};
constexpr std::string_view kOdometryKeys[] = {"type", "timestamp", "pose",  "tv",
                                              "rv",   "accel",     "carmen"};
constexpr std::string_view kTruePoseKeys[] = {"type", "timestamp", "true_pose", "odom_pose",
                                              "carmen"};
constexpr std::string_view kParamKeys[] = {"type", "name", "value"};
constexpr std::string_view kLogKeys[] = {"format", "version", "pose_source", "records"};

std::vector<double> ReadAngles(const JsonNode& object, std::size_t n) {
  if (detail::OptionalMember(object, "angles")) return SizedNumbers(object, "angles", n);
  const auto min = detail::OptionalMember(object, "angle_min");
  const auto step = detail::OptionalMember(object, "angle_increment");
  if (!min || !step)
    detail::Fail(object, "expected \"angles\", or \"angle_min\" and \"angle_increment\"");
  const double first = detail::FiniteNumber(*min, "angle_min");
  const double increment = detail::FiniteNumber(*step, "angle_increment");
  std::vector<double> angles(n);
  for (std::size_t i = 0; i < n; ++i) angles[i] = first + static_cast<double>(i) * increment;
  return angles;
}

std::vector<BeamStatus> ReadStatus(const JsonNode& node, const std::vector<double>& ranges,
                                   double min_range, double max_range) {
  const std::size_t n = ranges.size();
  if (detail::ArraySize(node, "\"status\"") != n)
    detail::Fail(node, fmt::format("expected {} entries in \"status\"", n));
  std::vector<BeamStatus> status(n);
  for (std::size_t i = 0; i < n; ++i) {
    const JsonNode e = detail::Element(node, i);
    const std::string s = detail::String(e, "a beam status");
    if (s == "valid") {
      // A flag can make a reading unusable, not a NaN, an infinity, a range <= 0 or one outside
      // [min_range, max_range) usable.
      if (!(std::isfinite(ranges[i]) && ranges[i] > 0.0))
        detail::Fail(
            e, fmt::format("reading {} is {}: \"valid\" needs a finite range > 0", i, ranges[i]));
      if (ClassifyReading(ranges[i], min_range, max_range) != BeamStatus::kValid)
        detail::Fail(e, fmt::format("reading {} is {} m: \"valid\" needs a range in [min_range, "
                                    "max_range) = [{}, {}) m",
                                    i, ranges[i], min_range, max_range));
      status[i] = BeamStatus::kValid;
    } else if (s == "max_range")
      status[i] = BeamStatus::kMaxRange;
    else if (s == "invalid")
      status[i] = BeamStatus::kInvalid;
    else
      detail::Fail(
          e,
          fmt::format(
              "expected a beam status (\"valid\", \"max_range\" or \"invalid\"), got \"{}\"", s));
  }
  return status;
}

SymmetricBandedMatrix ReadPrecision(const JsonNode& node, std::size_t n) {
  detail::RequireObject(node, "the precision");
  detail::RefuseUnknownMembers(node, kPrecisionKeys, "the precision");
  const long long bandwidth =
      detail::Integer(detail::Member(node, "bandwidth"), "the precision bandwidth");
  if (bandwidth < 0 || static_cast<std::size_t>(bandwidth) >= std::max<std::size_t>(n, 1)) {
    detail::Fail(node, fmt::format("precision bandwidth must be in [0, {}), got {}", n, bandwidth));
  }
  const JsonNode bands = detail::Member(node, "bands");
  if (detail::ArraySize(bands, "precision bands") != static_cast<std::size_t>(bandwidth) + 1) {
    detail::Fail(bands, fmt::format("expected bandwidth + 1 = {} bands", bandwidth + 1));
  }
  // Every band is read and checked before the (bandwidth + 1) x n matrix is allocated, so that
  // its size is bounded by the document's: a short document with a large bandwidth must not
  // make the reader allocate gigabytes.
  std::vector<std::vector<double>> values(static_cast<std::size_t>(bandwidth) + 1);
  for (std::size_t k = 0; k < values.size(); ++k) {
    const JsonNode row = detail::Element(bands, k);
    values[k] = detail::Numbers(row, "a precision band");
    if (values[k].size() != n)
      detail::Fail(row, fmt::format("expected {} values in each precision band", n));
    // Band k's last k entries lie outside the matrix and are not read.
    for (std::size_t j = 0; j + k < n; ++j)
      if (!std::isfinite(values[k][j]))
        detail::Fail(
            detail::Element(row, j),
            fmt::format("expected a finite number in precision band {}, got {}", k, values[k][j]));
  }
  SymmetricBandedMatrix w(n, static_cast<std::size_t>(bandwidth));
  for (std::size_t k = 0; k < values.size(); ++k) {
    for (std::size_t j = 0; j + k < n; ++j) w.Set(j + k, j, values[k][j]);
  }
  return w;
}

CarmenLaserFields ReadCarmenLaser(const JsonNode& node) {
  detail::RequireObject(node, "\"carmen\" fields");
  detail::RefuseUnknownMembers(node, kCarmenLaserKeys, "a scan's \"carmen\" fields");
  CarmenLaserFields c;
  const auto number = [&](const char* key, double fallback) {
    return OptionalNumber(node, key, key).value_or(fallback);
  };
  if (const auto n = detail::OptionalMember(node, "has_timestamps"))
    c.has_timestamps = detail::Boolean(*n, "has_timestamps");
  if (const auto n = detail::OptionalMember(node, "host")) c.host = detail::String(*n, "host");
  c.logger_timestamp = number("logger_timestamp", 0.0);
  if (const auto n = detail::OptionalMember(node, "laser_type"))
    c.laser_type = static_cast<int>(detail::IntegerInRange(*n, "laser_type", INT_MIN, INT_MAX));
  c.start_angle = number("start_angle", 0.0);
  c.fov = number("fov", 0.0);
  c.angular_resolution = number("angular_resolution", 0.0);
  c.maximum_range = OptionalNumber(node, "maximum_range", "maximum_range");
  c.accuracy = number("accuracy", 0.0);
  if (const auto n = detail::OptionalMember(node, "remission_mode"))
    c.remission_mode =
        static_cast<int>(detail::IntegerInRange(*n, "remission_mode", INT_MIN, INT_MAX));
  if (const auto n = detail::OptionalMember(node, "remissions"))
    c.remissions = detail::Numbers(*n, "remissions");
  c.tv = number("tv", 0.0);
  c.rv = number("rv", 0.0);
  c.forward_safety_dist = number("forward_safety_dist", 0.0);
  c.side_safety_dist = number("side_safety_dist", 0.0);
  c.turn_axis = number("turn_axis", 0.0);
  return c;
}

// The "sonar" member of a ring's scan record (docs/formats.md): n readings.
SonarFields ReadSonar(const JsonNode& node, std::size_t n) {
  detail::RequireObject(node, "\"sonar\" fields");
  detail::RefuseUnknownMembers(node, kSonarKeys, "a scan's \"sonar\" fields");
  SonarFields sonar;
  const JsonNode spread = detail::Member(node, "spread");
  sonar.spread = detail::FiniteNumber(spread, "the sonar cone's spread");
  if (!(sonar.spread > 0.0 && sonar.spread < std::numbers::pi))
    detail::Fail(spread, fmt::format("expected the sonar cone's full angle in (0, pi) rad, got {}",
                                     sonar.spread));
  if (const auto origins = detail::OptionalMember(node, "origins")) {
    if (detail::ArraySize(*origins, "\"origins\"") != n)
      detail::Fail(*origins,
                   fmt::format("expected {} transducer origins [x, y], one per reading", n));
    for (std::size_t i = 0; i < n; ++i)
      sonar.origins.push_back(detail::Point(detail::Element(*origins, i), "a transducer origin"));
  }
  const auto echo = detail::OptionalMember(node, "true_echo");
  const auto feature = detail::OptionalMember(node, "true_feature");
  if (echo.has_value() != feature.has_value())
    detail::Fail(node, "expected both \"true_echo\" and \"true_feature\", or neither");
  if (echo) {
    if (detail::ArraySize(*echo, "\"true_echo\"") != n)
      detail::Fail(*echo, fmt::format("expected {} entries in \"true_echo\"", n));
    for (std::size_t i = 0; i < n; ++i) {
      const JsonNode e = detail::Element(*echo, i);
      const std::string name = detail::String(e, "a sonar echo kind");
      const auto kind = SonarEchoFromString(name);
      if (!kind)
        detail::Fail(e, fmt::format("expected a sonar echo kind (\"none\", \"surface\", "
                                    "\"corner\", \"multipath\" or \"spurious\"), got \"{}\"",
                                    name));
      sonar.true_echo.push_back(*kind);
    }
    sonar.true_feature = SizedInts(node, "true_feature", n, -1, std::numeric_limits<int>::max());
  }
  return sonar;
}

std::optional<CarmenRecordFields> ReadCarmenRecord(const JsonNode& record) {
  const auto node = detail::OptionalMember(record, "carmen");
  if (!node) return std::nullopt;
  detail::RequireObject(*node, "\"carmen\" fields");
  detail::RefuseUnknownMembers(*node, kCarmenRecordKeys, "a record's \"carmen\" fields");
  CarmenRecordFields c;
  if (const auto n = detail::OptionalMember(*node, "has_timestamps"))
    c.has_timestamps = detail::Boolean(*n, "has_timestamps");
  if (const auto n = detail::OptionalMember(*node, "host")) c.host = detail::String(*n, "host");
  c.logger_timestamp = OptionalNumber(*node, "logger_timestamp", "logger_timestamp").value_or(0.0);
  return c;
}

// At the reading, like a position beyond the world at its coordinate; only once the statuses
// are known, as a no-return reading is kept whatever its value. A true range is the distance
// to a surface of the simulated scene, whatever the reading's status.
void RefuseReturnsBeyondWorld(const Scan& scan, const JsonNode& node, const JsonNode& ranges) {
  detail::RefuseReturnBeyondWorld(scan, ranges, "an element of \"ranges\"");
  if (const std::optional<std::size_t> i = scan.FirstTrueRangeBeyondWorld())
    detail::Fail(detail::Element(detail::Member(node, "true_range"), *i),
                 fmt::format("expected an element of \"true_range\" in metres, at most {:.0e}, "
                             "or null where nothing was hit, got {}",
                             kMaxWorldCoordinate, scan.truth->range[*i]));
}

Scan ReadScan(const JsonNode& node) {
  detail::RequireObject(node, "a scan");
  detail::RefuseUnknownMembers(node, kScanKeys, "a scan");
  Scan scan;
  if (const auto n = detail::OptionalMember(node, "channel"))
    scan.channel = detail::String(*n, "the channel");
  scan.timestamp = OptionalNumber(node, "timestamp", "the timestamp").value_or(0.0);
  scan.pose = detail::Pose(detail::Member(node, "pose"), "the sensor pose");
  scan.robot_pose = OptionalPose(node, "robot_pose");
  scan.odom_pose = OptionalPose(node, "odom_pose");
  scan.min_range = OptionalNumber(node, "min_range", "min_range").value_or(0.0);
  scan.max_range = OptionalNumber(node, "max_range", "max_range")
                       .value_or(std::numeric_limits<double>::infinity());
  if (std::isnan(scan.max_range)) scan.max_range = std::numeric_limits<double>::infinity();
  const JsonNode ranges = detail::Member(node, "ranges");
  scan.ranges = detail::Numbers(ranges, "\"ranges\"");
  const std::size_t n = scan.ranges.size();
  scan.angles = ReadAngles(node, n);
  if (const auto sigma = detail::OptionalMember(node, "sigma")) {
    if (sigma->value.is_array()) {
      scan.sigma = SizedNumbers(node, "sigma", n);
    } else {
      scan.sigma.assign(n, detail::Number(*sigma, "sigma"));
    }
  } else {
    scan.sigma.assign(n, kDefaultSigma);
  }
  if (const auto status = detail::OptionalMember(node, "status")) {
    scan.status = ReadStatus(*status, scan.ranges, scan.min_range, scan.max_range);
  } else {
    scan.ClassifyAll();
  }
  if (const auto precision = detail::OptionalMember(node, "precision"))
    scan.precision = ReadPrecision(*precision, n);
  if (detail::OptionalMember(node, "true_range")) {
    ScanTruth& truth = scan.truth.emplace();
    truth.range = SizedNumbers(node, "true_range", n);
    truth.alpha = SizedNumbers(node, "true_alpha", n);
    constexpr long long kMaxId = std::numeric_limits<int>::max();
    truth.surface = SizedInts(node, "true_surface", n, -1, kMaxId);
    truth.region = SizedInts(node, "true_region", n, -1, kMaxId);
    if (detail::OptionalMember(node, "true_outlier")) {
      const std::vector<int> outlier = SizedInts(node, "true_outlier", n, 0, 1);
      truth.outlier.assign(outlier.begin(), outlier.end());
    } else {
      truth.outlier.assign(n, 0);
    }
  } else {
    // The truth is read as a whole: without its ranges, the other members would be dropped
    // unread, and a file that meant to carry them would lose them without a word.
    for (const char* key : {"true_alpha", "true_surface", "true_region", "true_outlier"})
      if (const auto member = detail::OptionalMember(node, key))
        detail::Fail(*member, fmt::format("\"{}\" needs \"true_range\": a scan's ground truth is "
                                          "read only with its true ranges",
                                          key));
  }
  if (const auto carmen = detail::OptionalMember(node, "carmen"))
    scan.carmen = ReadCarmenLaser(*carmen);
  if (const auto sonar = detail::OptionalMember(node, "sonar")) scan.sonar = ReadSonar(*sonar, n);
  if (const std::vector<std::string> problems = scan.Problems(); !problems.empty()) {
    // At the member the problem is about, where the scan has it; at the scan otherwise.
    const std::string& problem = problems.front();
    const auto keys = [&]() -> std::vector<const char*> {
      if (problem.starts_with("sigma")) return {"sigma"};
      if (problem.starts_with("angles")) return {"angles", "angle_increment", "angle_min"};
      if (problem.starts_with("need 0 <= min_range")) return {"max_range", "min_range"};
      if (problem.starts_with("pose")) return {"pose"};
      if (problem.starts_with("precision")) return {"precision"};
      if (problem.starts_with("status")) return {"status"};
      return {};
    }();
    for (const char* key : keys)
      if (const auto member = detail::OptionalMember(node, key))
        detail::Fail(*member, "inconsistent scan: " + problem);
    detail::Fail(node, "inconsistent scan: " + problem);
  }
  RefuseReturnsBeyondWorld(scan, node, ranges);
  return scan;
}

void ReadRecord(const JsonNode& record, Log& log) {
  detail::RequireObject(record, "a log record");
  const JsonNode type_node = detail::Member(record, "type");
  const std::string type = detail::String(type_node, "the record type");
  if (type != "scan") {
    const std::span<const std::string_view> known =
        type == "odometry"    ? std::span<const std::string_view>(kOdometryKeys)
        : type == "true_pose" ? std::span<const std::string_view>(kTruePoseKeys)
                              : std::span<const std::string_view>(kParamKeys);
    if (type == "odometry" || type == "true_pose" || type == "param")
      detail::RefuseUnknownMembers(record, known, fmt::format("a \"{}\" record", type));
  }
  if (type == "scan") {
    log.order.push_back({Log::RecordKind::kScan, log.scans.size()});
    log.scans.push_back(ReadScan(record));
  } else if (type == "odometry") {
    OdometryRecord r;
    r.timestamp = OptionalNumber(record, "timestamp", "the timestamp").value_or(0.0);
    r.pose = detail::Pose(detail::Member(record, "pose"), "the odometry pose");
    r.tv = OptionalNumber(record, "tv", "tv").value_or(0.0);
    r.rv = OptionalNumber(record, "rv", "rv").value_or(0.0);
    r.accel = OptionalNumber(record, "accel", "accel").value_or(0.0);
    r.carmen = ReadCarmenRecord(record);
    log.order.push_back({Log::RecordKind::kOdometry, log.odometry.size()});
    log.odometry.push_back(std::move(r));
  } else if (type == "true_pose") {
    TruePoseRecord r;
    r.timestamp = OptionalNumber(record, "timestamp", "the timestamp").value_or(0.0);
    r.true_pose = detail::Pose(detail::Member(record, "true_pose"), "the true pose");
    r.odom_pose = detail::Pose(detail::Member(record, "odom_pose"), "the odometry pose");
    r.carmen = ReadCarmenRecord(record);
    log.order.push_back({Log::RecordKind::kTruePose, log.true_poses.size()});
    log.true_poses.push_back(std::move(r));
  } else if (type == "param") {
    log.order.push_back({Log::RecordKind::kParam, log.params.size()});
    log.params.emplace_back(detail::String(detail::Member(record, "name"), "the parameter name"),
                            detail::String(detail::Member(record, "value"), "the parameter value"));
  } else {
    detail::Fail(type_node, fmt::format("expected a record type (\"scan\", \"odometry\", "
                                        "\"true_pose\" or \"param\"), got \"{}\"",
                                        type));
  }
}

Log ReadLogDocument(const JsonNode& root) {
  detail::RequireObject(root, "a priormap.log or priormap.scan document");
  const JsonNode format_node = detail::Member(root, "format");
  const std::string format = detail::String(format_node, "the document format");
  Log log;
  if (format == "priormap.scan") {
    detail::RequireFormat(root, "priormap.scan", kVersion);
    log.scans.push_back(ReadScan(root));
    return log;
  }
  if (format != "priormap.log") {
    detail::Fail(
        format_node,
        fmt::format("expected format \"priormap.log\" or \"priormap.scan\", got \"{}\"", format));
  }
  detail::RequireFormat(root, "priormap.log", kVersion);
  detail::RefuseUnknownMembers(root, kLogKeys, "a priormap.log document");
  if (const auto source = detail::OptionalMember(root, "pose_source")) {
    const std::string name = detail::String(*source, "the pose source");
    const auto parsed = PoseSourceFromString(name);
    if (!parsed)
      detail::Fail(
          *source,
          fmt::format(
              "expected a pose source (unknown, odometry, corrected, ground_truth), got \"{}\"",
              name));
    log.pose_source = *parsed;
  }
  const JsonNode records = detail::Member(root, "records");
  const std::size_t n = detail::ArraySize(records, "\"records\"");
  for (std::size_t i = 0; i < n; ++i) ReadRecord(detail::Element(records, i), log);
  return log;
}

// The warnings of a log's scans stamped before the previous scan of their channel
// (scan_time_order.hpp), at their "timestamp". A scan is stamped when its record has a finite
// "timestamp" and is not a CARMEN line without one (has_timestamps false, written as 0).
std::vector<Diagnostic> TimeOrderWarnings(const detail::JsonDocument& document, const Log& log) {
  if (log.order.empty()) return {};  // a priormap.scan document: one scan
  const JsonNode records = detail::Member(document.root(), "records");
  std::vector<std::size_t> record_of_scan(log.scans.size());
  std::vector<detail::StampedScan> stamped;
  for (std::size_t i = 0; i < log.order.size(); ++i) {
    if (log.order[i].kind != Log::RecordKind::kScan) continue;
    const std::size_t k = log.order[i].index;
    record_of_scan[k] = i;
    const Scan& scan = log.scans[k];
    if (std::isfinite(scan.timestamp) && !(scan.carmen && !scan.carmen->has_timestamps) &&
        detail::Element(records, i).value.contains("timestamp"))
      stamped.push_back({k, scan.channel, scan.timestamp});
  }
  return detail::TimeOrderWarnings(stamped, [&](std::span<const std::size_t> scans) {
    std::vector<std::size_t> indices;  // of records, increasing as the scans' are
    for (const std::size_t k : scans) indices.push_back(record_of_scan[k]);
    const std::vector<std::optional<TextPosition>> positions =
        document.LocateMembersOfElements(records.pointer, indices, "timestamp");
    std::vector<Diagnostic> located;
    for (std::size_t j = 0; j < indices.size(); ++j) {
      const TextPosition at = positions[j].value_or(TextPosition{0, 0});
      located.push_back(
          {document.name(), at.line, at.col,
           fmt::format(" (at {})", (records.pointer / indices[j] / "timestamp").to_string())});
    }
    return located;
  });
}

// What ReadScan refuses besides positions and returns beyond the world (Scan::FirstBeyondWorld):
// a heading that is not finite (written as null), an inconsistent scan (Scan::Problems), and ids
// of the ground truth that it reads as out of range.
std::optional<std::string> ScanRefusal(const Scan& scan) {
  if (auto refused = HeadingNotFinite("pose", scan.pose.theta())) return refused;
  if (scan.robot_pose)
    if (auto refused = HeadingNotFinite("robot_pose", scan.robot_pose->theta())) return refused;
  if (scan.odom_pose)
    if (auto refused = HeadingNotFinite("odom_pose", scan.odom_pose->theta())) return refused;
  if (const std::vector<std::string> problems = scan.Problems(); !problems.empty())
    return "inconsistent scan: " + problems.front();
  // The sizes agree, as Problems() checked them.
  const auto id_refusal = [](const char* field,
                             const std::vector<int>& ids) -> std::optional<std::string> {
    const auto it = std::ranges::find_if(ids, [](int id) { return id < -1; });
    if (it == ids.end()) return std::nullopt;
    return fmt::format("{} {} = {}, below -1 (nothing)", field, it - ids.begin(), *it);
  };
  if (scan.truth) {
    if (auto refused = id_refusal("true_surface", scan.truth->surface)) return refused;
    if (auto refused = id_refusal("true_region", scan.truth->region)) return refused;
    for (std::size_t i = 0; i < scan.truth->outlier.size(); ++i)
      if (scan.truth->outlier[i] > 1)
        return fmt::format("true_outlier {} = {}, neither 0 nor 1", i, scan.truth->outlier[i]);
  }
  if (scan.sonar) return id_refusal("true_feature", scan.sonar->true_feature);
  return std::nullopt;
}

// The same for a log: its scans, the headings of its other records, and the order of its
// records (Log::Problems).
std::optional<std::string> LogRefusal(const Log& log) {
  for (std::size_t k = 0; k < log.scans.size(); ++k)
    if (const auto refused = ScanRefusal(log.scans[k]))
      return fmt::format("scan {}: {}", k, *refused);
  for (std::size_t k = 0; k < log.odometry.size(); ++k)
    if (const auto refused = HeadingNotFinite("pose", log.odometry[k].pose.theta()))
      return fmt::format("odometry record {}: {}", k, *refused);
  for (std::size_t k = 0; k < log.true_poses.size(); ++k)
    for (const auto& [field, pose] :
         {std::pair<const char*, const Se2&>{"true_pose", log.true_poses[k].true_pose},
          {"odom_pose", log.true_poses[k].odom_pose}})
      if (const auto refused = HeadingNotFinite(field, pose.theta()))
        return fmt::format("true pose record {}: {}", k, *refused);
  if (const std::vector<std::string> problems = log.Problems(); !problems.empty())
    return problems.front();
  return std::nullopt;
}

OrderedJson DocumentHeader(const char* format) {
  OrderedJson j;
  j["format"] = format;
  j["version"] = kVersion;
  return j;
}

}  // namespace

std::string FormatJsonScan(const Scan& scan) {
  if (const auto beyond = scan.FirstBeyondWorld())
    throw IoError(CannotWriteBeyondWorld("the scan", *beyond));
  if (const auto refused = ScanRefusal(scan))
    throw IoError(CannotWriteRefused("the scan", *refused));
  return detail::DumpOneMemberPerLine(ScanToJson(scan, DocumentHeader("priormap.scan")));
}

std::string FormatJsonLog(const Log& log) {
  if (const auto beyond = log.FirstBeyondWorld())
    throw IoError(CannotWriteBeyondWorld("the log", *beyond));
  if (const auto refused = LogRefusal(log)) throw IoError(CannotWriteRefused("the log", *refused));
  OrderedJson header = DocumentHeader("priormap.log");
  header["pose_source"] = ToString(log.pose_source);
  std::string out = detail::Dump(header);
  out.pop_back();  // reopen the object to stream the records one per line
  out += ",\"records\":[";
  bool first = true;
  for (const Log::RecordRef& ref : log.RecordOrder()) {
    OrderedJson record;
    switch (ref.kind) {
      case Log::RecordKind::kScan:
        record = ScanToJson(log.scans[ref.index], OrderedJson{{"type", "scan"}});
        break;
      case Log::RecordKind::kOdometry: {
        const OdometryRecord& r = log.odometry[ref.index];
        record = {{"type", "odometry"},
                  {"timestamp", detail::NumberToJson(r.timestamp)},
                  {"pose", detail::PoseToJson(r.pose)},
                  {"tv", detail::NumberToJson(r.tv)},
                  {"rv", detail::NumberToJson(r.rv)},
                  {"accel", detail::NumberToJson(r.accel)}};
        if (r.carmen) record["carmen"] = CarmenRecordToJson(*r.carmen);
        break;
      }
      case Log::RecordKind::kTruePose: {
        const TruePoseRecord& r = log.true_poses[ref.index];
        record = {{"type", "true_pose"},
                  {"timestamp", detail::NumberToJson(r.timestamp)},
                  {"true_pose", detail::PoseToJson(r.true_pose)},
                  {"odom_pose", detail::PoseToJson(r.odom_pose)}};
        if (r.carmen) record["carmen"] = CarmenRecordToJson(*r.carmen);
        break;
      }
      case Log::RecordKind::kParam:
        record = {{"type", "param"},
                  {"name", log.params[ref.index].first},
                  {"value", log.params[ref.index].second}};
        break;
    }
    out += first ? "\n" : ",\n";
    out += detail::Dump(record);
    first = false;
  }
  out += "\n]}\n";
  return out;
}

Result<Log> ParseJsonLog(std::string_view text, const std::string& name) {
  Result<detail::JsonDocument> document = detail::JsonDocument::Parse(text, name);
  if (!document) return document.diagnostics();
  try {
    Log log = ReadLogDocument(document.value().root());
    std::vector<Diagnostic> warnings = TimeOrderWarnings(document.value(), log);
    return Result<Log>(std::move(log), std::move(warnings));
  } catch (const detail::JsonSchemaError& error) {
    return document.value().Diagnose(error);
  }
}

Result<Log> ReadJsonLog(const std::filesystem::path& path) {
  Result<std::string> text = ReadFileText(path);
  if (!text) return text.diagnostics();
  return ParseJsonLog(text.value(), path.string());
}

void WriteJsonScan(const Scan& scan, const std::filesystem::path& path) {
  WriteTextFileAtomically(path, FormatJsonScan(scan));
}

void WriteJsonLog(const Log& log, const std::filesystem::path& path) {
  WriteTextFileAtomically(path, FormatJsonLog(log));
}

}  // namespace priormap
