// Whatever a writer writes, its reader reads back. For every writer of the core, on values that
// include the adversarial ones (NaN, infinities, subnormals, 1e300, -0.0, positions just inside
// and just beyond the world's bound, radii <= 0, headings that are not finite, returns beyond the
// bound, empty and Unicode names), either the writer refuses, naming the field and leaving the
// target as it was, or its own reader reads the file back as it was written.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <tuple>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <priormap/core/carmen_io.hpp>
#include <priormap/core/file_io.hpp>
#include <priormap/core/json_io.hpp>
#include <priormap/core/log_io.hpp>
#include <priormap/core/scene.hpp>
#include <priormap/core/world_bounds.hpp>

#include "testing/log_equality.hpp"
#include "testing/temp_dir.hpp"

namespace priormap {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kSubnormal = std::numeric_limits<double>::denorm_min();
const double kJustInside = std::nextafter(kMaxWorldCoordinate, 0.0);
const double kJustBeyond = std::nextafter(kMaxWorldCoordinate, kInf);

std::string Exact(double v) {
  std::ostringstream out;
  out.precision(17);
  out << v;
  return out.str();
}

bool SameDouble(double a, double b) {
  return (std::isnan(a) && std::isnan(b)) ||
         std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}

// Draws the values of one test case. In an ordinary case every value is one that the writers
// must accept (a writer that refused everything would otherwise pass); in an adversarial case a
// quarter of the draws come from the values that writers and readers have got wrong.
class Draw {
 public:
  Draw() : adversarial_(!OneIn(3)) {}

  // Whether this case may hold a value that a writer refuses.
  [[nodiscard]] bool adversarial() const { return adversarial_; }

  // Any finite number: a timestamp, a velocity, a remission.
  double Number() {
    if (Odd())
      return *rc::gen::element(kNaN, kInf, -kInf, kSubnormal, -kSubnormal, 1e300, -1e300, -0.0,
                               std::numeric_limits<double>::max(), kJustBeyond);
    return *rc::gen::oneOf(
        rc::gen::map(rc::gen::inRange(-1000000, 1000000), [](int v) { return v / 1000.0; }),
        rc::gen::suchThat(rc::gen::arbitrary<double>(), [](double v) { return std::isfinite(v); }));
  }
  // x or y of a position.
  double Coordinate() {
    if (Odd())
      return *rc::gen::element(kNaN, kInf, -kInf, 1e300, -1e300, kJustBeyond, -kJustBeyond,
                               kMaxWorldCoordinate, -kMaxWorldCoordinate, kJustInside, -0.0,
                               kSubnormal);
    const double drawn = *rc::gen::oneOf(
        rc::gen::map(rc::gen::inRange(-1000000, 1000000), [](int v) { return v / 1000.0; }),
        rc::gen::suchThat(rc::gen::arbitrary<double>(), [](double v) { return std::isfinite(v); }));
    return IsWithinWorld(drawn) ? drawn : std::fmod(drawn, kMaxWorldCoordinate);
  }
  double Heading() {
    if (Odd()) return *rc::gen::element(kNaN, kInf, -kInf, 1e300, -0.0, kSubnormal, 4.0);
    return *rc::gen::map(rc::gen::inRange(-40000, 40000), [](int v) { return v / 10000.0; });
  }
  Se2 Pose() {
    const double x = Coordinate(), y = Coordinate();
    return {x, y, Heading()};
  }
  // A reading: returns within the bound, no-returns and invalid readings of any value.
  double Reading() {
    if (Odd())
      return *rc::gen::element(1e300, -1e300, kJustBeyond, kJustInside, kSubnormal, -0.0,
                               std::numeric_limits<double>::max(), 81.83);
    return *rc::gen::oneOf(
        rc::gen::map(rc::gen::inRange(-1000, 100000), [](int v) { return v / 1000.0; }),
        rc::gen::element(kNaN, kInf, -kInf, 0.0, 30.0, 81.91));
  }
  // A name, a label, a host: one word unless odd. Strings are valid UTF-8: the JSON writers
  // replace invalid bytes by U+FFFD by design (json_document.hpp).
  std::string Word() {
    if (Odd()) return *rc::gen::element<std::string>("", "two words", " lead", "trail ", "tab\t");
    return *rc::gen::element<std::string>("nohost", "h", "Καλημέρα", "🚪", "a\"b\\c", "#x");
  }
  // Free text: a PARAM value, a scene's name, a label, a channel.
  std::string Text() {
    if (Odd())
      return *rc::gen::element<std::string>(" leading", "trailing ", "  ", "\ttab", "a\rb",
                                            "line\nbreak");
    return *rc::gen::element<std::string>("", "1", "two words", "Καλημέρα 🚪",
                                          std::string("nul\0inside", 10), "tab\tinside");
  }
  // Whether to draw an adversarial value now.
  bool Odd() { return adversarial_ && OneIn(6); }

  // True with probability 1 / n whatever the size (rc::gen::inRange favours small values early).
  static bool OneIn(int n) {
    std::vector<int> one_of(static_cast<std::size_t>(n), 0);
    one_of[0] = 1;
    return *rc::gen::elementOf(one_of) == 1;
  }

 private:
  bool adversarial_;
};

std::vector<double> EvenAngles(std::size_t n, double first, double step) {
  std::vector<double> angles(n);
  for (std::size_t i = 0; i < n; ++i) angles[i] = first + static_cast<double>(i) * step;
  return angles;
}

Scan DrawScan(Draw& draw) {
  Scan scan;
  const std::size_t n = *rc::gen::element<std::size_t>(0, 1, 2, 3, 5, 180);
  scan.channel = *rc::gen::element<std::string>("FLASER", "RLASER", "ROBOTLASER1", "SIM");
  if (draw.Odd()) scan.channel = draw.Text();
  scan.timestamp = draw.Number();
  scan.pose = draw.Pose();
  if (*rc::gen::arbitrary<bool>()) scan.robot_pose = draw.Pose();
  if (*rc::gen::inRange(0, 4) != 0) scan.odom_pose = draw.Pose();
  switch (*rc::gen::inRange(0, 4)) {
    case 0:
      scan.angles = FlaserBeamAngles(n, std::numbers::pi);
      break;
    case 1:
      scan.angles = EvenlySpacedAngles(
          n, *rc::gen::map(rc::gen::inRange(-400, 0), [](int v) { return v / 100.0; }),
          *rc::gen::map(rc::gen::inRange(1, 400), [](int v) { return v / 100.0; }));
      break;
    default:
      scan.angles =
          EvenAngles(n, *rc::gen::map(rc::gen::inRange(-400, 400), [](int v) { return v / 100.0; }),
                     *rc::gen::map(rc::gen::inRange(1, 10000), [](int v) { return v / 1e4; }));
  }
  if (draw.Odd() && n > 0) {  // uneven, decreasing, not finite, or one missing
    switch (*rc::gen::inRange(0, 4)) {
      case 0:
        scan.angles.back() += 1e-3;
        break;
      case 1:
        std::ranges::reverse(scan.angles);
        break;
      case 2:
        scan.angles.front() = *rc::gen::element(kNaN, kInf, -kInf, 1e300);
        break;
      default:
        scan.angles.pop_back();
    }
  }
  for (std::size_t i = 0; i < n; ++i) scan.ranges.push_back(draw.Reading());
  scan.sigma.assign(n, 0.01);
  if (*rc::gen::arbitrary<bool>())
    for (double& s : scan.sigma)
      s = draw.Odd() ? *rc::gen::element(0.0, -1.0, kNaN, kInf, kSubnormal) : 0.02;
  const auto limits = *rc::gen::element(std::pair{0.0, kInf}, std::pair{0.1, 8.0},
                                        std::pair{0.0, 81.41}, std::pair{0.0, 30.0});
  scan.min_range = limits.first;
  scan.max_range = limits.second;
  if (draw.Odd())
    std::tie(scan.min_range, scan.max_range) =
        *rc::gen::element(std::pair{kNaN, kInf}, std::pair{0.0, kNaN}, std::pair{5.0, 5.0},
                          std::pair{-1.0, 3.0}, std::pair{0.1, 1e300}, std::pair{0.0, -kInf});
  scan.ClassifyAll();
  for (BeamStatus& s : scan.status) {
    if (*rc::gen::inRange(0, 6) == 0)
      s = *rc::gen::element(BeamStatus::kMaxRange, BeamStatus::kInvalid);
    if (draw.Odd()) s = BeamStatus::kValid;
  }
  if (n > 0 && *rc::gen::inRange(0, 4) == 0 &&
      std::ranges::all_of(scan.sigma, [](double s) { return s > 0.0 && std::isfinite(s); }))
    scan.precision = SymmetricBandedMatrix::Ar1Precision(scan.sigma, 0.5);
  if (*rc::gen::inRange(0, 3) == 0) {
    ScanTruth& truth = scan.truth.emplace();
    for (std::size_t i = 0; i < n; ++i) {
      truth.range.push_back(*rc::gen::arbitrary<bool>() ? draw.Reading() : kNaN);
      truth.alpha.push_back(draw.Number());
      truth.surface.push_back(draw.Odd() ? *rc::gen::element(-2, std::numeric_limits<int>::min())
                                         : *rc::gen::inRange(-1, 100));
      truth.region.push_back(draw.Odd() ? -7 : *rc::gen::inRange(-1, 100));
      truth.outlier.push_back(draw.Odd() ? std::uint8_t{2} : *rc::gen::element<std::uint8_t>(0, 1));
    }
  }
  if (*rc::gen::arbitrary<bool>()) {
    CarmenLaserFields& c = scan.carmen.emplace();
    c.has_timestamps = *rc::gen::inRange(0, 4) != 0;
    c.host = draw.Word();
    c.logger_timestamp = draw.Number();
    c.laser_type = *rc::gen::arbitrary<int>();
    if (scan.channel == "ROBOTLASER1" && n > 1) {
      c.start_angle = scan.angles.front();
      c.angular_resolution =
          (scan.angles.back() - scan.angles.front()) / static_cast<double>(n - 1);
      c.fov = c.angular_resolution * static_cast<double>(n - 1);
    }
    if (*rc::gen::arbitrary<bool>()) c.maximum_range = scan.max_range;
    c.accuracy = draw.Number();
    c.remission_mode = *rc::gen::inRange(0, 3);
    for (int i = *rc::gen::inRange(0, 3); i > 0; --i) c.remissions.push_back(draw.Number());
    c.tv = draw.Number();
    c.rv = draw.Number();
    c.forward_safety_dist = draw.Number();
    c.side_safety_dist = draw.Number();
    c.turn_axis = draw.Number();
  }
  if (*rc::gen::inRange(0, 5) == 0) {
    SonarFields& sonar = scan.sonar.emplace();
    sonar.spread = draw.Odd() ? *rc::gen::element(0.0, kNaN, 4.0) : 0.3490658503988659;
    if (*rc::gen::arbitrary<bool>())
      for (std::size_t i = 0; i < n; ++i) sonar.origins.emplace_back(draw.Coordinate(), 0.1);
    if (*rc::gen::arbitrary<bool>()) {
      sonar.true_echo.assign(n, SonarEcho::kSurface);
      for (std::size_t i = 0; i < n; ++i)
        sonar.true_feature.push_back(draw.Odd() ? -3 : *rc::gen::inRange(-1, 50));
    }
  }
  return scan;
}

Log DrawLog(Draw& draw) {
  Log log;
  log.pose_source = *rc::gen::element(PoseSource::kUnknown, PoseSource::kOdometry,
                                      PoseSource::kCorrected, PoseSource::kGroundTruth);
  const auto stamps = [&]() -> std::optional<CarmenRecordFields> {
    if (*rc::gen::arbitrary<bool>()) return std::nullopt;
    return CarmenRecordFields{*rc::gen::inRange(0, 4) != 0, draw.Word(), draw.Number()};
  };
  for (int k = *rc::gen::inRange(0, 4); k > 0; --k) log.scans.push_back(DrawScan(draw));
  for (int k = *rc::gen::inRange(0, 3); k > 0; --k)
    log.odometry.push_back(
        {draw.Number(), draw.Pose(), draw.Number(), draw.Number(), draw.Number(), stamps()});
  for (int k = *rc::gen::inRange(0, 3); k > 0; --k)
    log.true_poses.push_back({draw.Number(), draw.Pose(), draw.Pose(), stamps()});
  for (int k = *rc::gen::inRange(0, 3); k > 0; --k)
    log.params.emplace_back(draw.Word(), draw.Text());
  // The records in the file's order, interleaved as a reader makes them: each kind's records in
  // the order of their indices.
  if (*rc::gen::arbitrary<bool>()) {
    std::vector<Log::RecordRef> refs = log.RecordOrder();
    for (std::size_t i = refs.size(); i > 1; --i)
      std::swap(refs[i - 1], refs[*rc::gen::inRange<std::size_t>(0, i)]);
    std::map<Log::RecordKind, std::size_t> next;
    for (Log::RecordRef& ref : refs) ref.index = next[ref.kind]++;
    log.order = std::move(refs);
  }
  return log;
}

Scene DrawScene(Draw& draw) {
  Scene scene;
  scene.name = *rc::gen::arbitrary<bool>() ? draw.Text() : "room";
  for (int s = *rc::gen::inRange(0, 4); s > 0; --s) {
    SceneSurface surface;
    if (*rc::gen::arbitrary<bool>()) {
      Polyline polyline;
      const int points = draw.Odd() ? *rc::gen::inRange(0, 2) : *rc::gen::inRange(2, 5);
      for (int i = 0; i < points; ++i) {
        // Distinct points on a grid, so that no segment has zero length unless odd.
        polyline.points.emplace_back(i * 1.5 + *rc::gen::inRange(0, 1000) * 1e-3,
                                     draw.Coordinate());
        if (i > 0 && draw.Odd()) polyline.points.back() = polyline.points[i - 1];
      }
      polyline.closed = points > 2 && *rc::gen::arbitrary<bool>();
      surface.shape = std::move(polyline);
    } else {
      Circle circle;
      // Ordinary centres leave room for any ordinary radius.
      circle.center = draw.Odd() ? Vec2(draw.Coordinate(), draw.Coordinate())
                                 : Vec2(*rc::gen::inRange(-1000000, 1000000) / 1000.0,
                                        *rc::gen::inRange(-1000000, 1000000) / 1000.0);
      circle.radius = *rc::gen::map(rc::gen::inRange(1, 100000), [](int v) { return v / 1000.0; });
      if (draw.Odd()) {
        switch (*rc::gen::inRange(0, 3)) {
          case 0:  // on the bound, or just within it by less than the radius
            circle.center = {*rc::gen::element(kMaxWorldCoordinate, -kMaxWorldCoordinate,
                                               -kMaxWorldCoordinate + 0.25),
                             0.0};
            break;
          case 1:
            circle.radius =
                *rc::gen::element(0.0, -0.0, -1.0, kNaN, kInf, -kInf, kSubnormal, 1e300, -1e300);
            break;
          default:
            circle.radius = LargestRadiusWithinWorld(circle.center.x(), circle.center.y());
            if (*rc::gen::arbitrary<bool>()) circle.radius = std::nextafter(circle.radius, kInf);
        }
      }
      surface.shape = circle;
    }
    surface.clutter = *rc::gen::arbitrary<bool>();
    surface.label = *rc::gen::arbitrary<bool>() ? draw.Text() : "";
    scene.surfaces.push_back(std::move(surface));
  }
  if (*rc::gen::arbitrary<bool>()) scene.default_pose = draw.Pose();
  for (int i = *rc::gen::inRange(0, 3); i > 0; --i)
    scene.waypoints.emplace_back(draw.Coordinate(), draw.Coordinate());
  return scene;
}

// The words that name a field in the writers' refusals: a message must name one.
constexpr std::string_view kFields[] = {
    "pose",  "theta",     "reading", "true_range", "true_surface", "true_region",   "true_outlier",
    "sigma", "angles",    "angle",   "min_range",  "max_range",    "status",        "precision",
    "host",  "timestamp", "name",    "value",      "sonar",        "true_feature",  "spread",
    "point", "segment",   "radius",  "circle",     "waypoint",     "field of view", "records"};

// Writes with `write` to a fresh directory, in which the target exists beforehand or not. A
// refusal must name a field, and leave the directory as it was; otherwise `check_read_back`
// reads the file and says how it differs from what was written.
template <typename Write, typename CheckReadBack>
void WriteThenReadBack(const Draw& draw, const std::string& name, Write write,
                       CheckReadBack check_read_back) {
  const testing::TempDir dir;
  const bool existing = *rc::gen::arbitrary<bool>();
  if (existing) testing::WriteAll(dir / name, "old");
  try {
    write(dir / name);
  } catch (const IoError& e) {
    const std::string message = e.what();
    RC_TAG("refused");
    RC_LOG() << "refused: " << message << "\n";
    RC_ASSERT(draw.adversarial());
    RC_ASSERT(std::ranges::any_of(
        kFields, [&](std::string_view field) { return message.find(field) != std::string::npos; }));
    RC_ASSERT(testing::FilesIn(dir.path()) ==
              (existing ? std::vector<std::string>{name} : std::vector<std::string>{}));
    if (existing) RC_ASSERT(testing::ReadAll(dir / name) == "old");
    return;
  }
  RC_TAG(draw.adversarial() ? "written, adversarial" : "written, ordinary");
  const ::testing::AssertionResult same = check_read_back(dir / name);
  if (!same) RC_FAIL(same.message());
}

std::string DrawJsonName() {
  return *rc::gen::element<std::string>("out.json", "out.json.gz", "Ωut.JSON");
}

RC_GTEST_PROP(WriterRoundTrip, JsonScan, ()) {
  Draw draw;
  const Scan scan = DrawScan(draw);
  WriteThenReadBack(
      draw, DrawJsonName(), [&](const auto& path) { WriteJsonScan(scan, path); },
      [&](const auto& path) -> ::testing::AssertionResult {
        const Result<Log> read = ReadJsonLog(path);
        if (!read.ok()) return ::testing::AssertionFailure() << read.error();
        if (read.value().scans.size() != 1U) return ::testing::AssertionFailure() << "not 1 scan";
        return testing::SameScan(read.value().scans[0], scan);
      });
}

RC_GTEST_PROP(WriterRoundTrip, JsonLog, ()) {
  Draw draw;
  const Log log = DrawLog(draw);
  WriteThenReadBack(
      draw, DrawJsonName(), [&](const auto& path) { WriteJsonLog(log, path); },
      [&](const auto& path) -> ::testing::AssertionResult {
        const Result<Log> read = ReadJsonLog(path);
        if (!read.ok()) return ::testing::AssertionFailure() << read.error();
        return testing::SameLog(read.value(), log);
      });
}

// What a CARMEN line carries of a record reads back as written; what it does not carry is either
// derived as the reader derives it or named by CarmenLosses.
::testing::AssertionResult SameAsCarmenCarriesIt(const Log& read, const Log& log,
                                                 bool angles_to_1e9) {
  ::testing::AssertionResult differs = ::testing::AssertionFailure();
  bool same = true;
  const auto check = [&](bool ok, const std::string& what) {
    if (!ok) {
      differs << "\n  " << what;
      same = false;
    }
  };
  const auto same_pose = [](const Se2& a, const Se2& b) {
    return SameDouble(a.x(), b.x()) && SameDouble(a.y(), b.y()) && SameDouble(a.theta(), b.theta());
  };
  const std::vector<std::string> losses = CarmenLosses(log);
  const auto lost = [&](std::string_view what) {
    return std::ranges::any_of(
        losses, [&](const std::string& l) { return l.find(what) != std::string::npos; });
  };
  const auto same_stamps = [&](const std::string& at, double read_timestamp,
                               const CarmenRecordFields& r, double timestamp,
                               const std::optional<CarmenRecordFields>& c) {
    const bool has = c ? c->has_timestamps : true;
    check(r.has_timestamps == has, at + "has_timestamps");
    if (has) {
      check(SameDouble(read_timestamp, timestamp), at + "timestamp");
      check(r.host == (c ? c->host : "priormap"), at + "host");
      check(SameDouble(r.logger_timestamp, c ? c->logger_timestamp : timestamp),
            at + "logger_timestamp");
    } else {
      check(SameDouble(read_timestamp, timestamp) || (read_timestamp == 0.0 && lost("timestamp")),
            at + "timestamp, lost without a word");
    }
  };
  check(read.RecordOrder() == log.RecordOrder(), "record order");
  check(read.params == log.params, "params");
  if (!same) return differs;
  for (std::size_t k = 0; k < log.scans.size(); ++k) {
    const Scan& a = read.scans[k];
    const Scan& b = log.scans[k];
    const std::string at = "scan " + std::to_string(k) + ": ";
    const bool flaser = (b.channel == "FLASER" || b.channel == "RLASER") && b.odom_pose &&
                        b.angles == FlaserBeamAngles(b.size(), std::numbers::pi);
    check(!b.sonar, at + "a sonar ring, read back as a laser scan");
    check(a.channel == (flaser ? b.channel : "ROBOTLASER1"), at + "channel");
    check(same_pose(a.pose, b.pose), at + "pose");
    if (flaser) {
      check(a.odom_pose && same_pose(*a.odom_pose, *b.odom_pose), at + "odom_pose");
      check(!a.robot_pose && (!b.robot_pose || lost("robot pose")),
            at + "robot_pose, lost without a word");
    } else {
      check(a.robot_pose && same_pose(*a.robot_pose, b.robot_pose.value_or(b.pose)),
            at + "robot_pose");
      check(!a.odom_pose && (!b.odom_pose || !log.odometry.empty() || lost("odometry pose")),
            at + "odom_pose, lost without a word");
    }
    check(a.ranges.size() == b.ranges.size() && std::ranges::equal(a.ranges, b.ranges, SameDouble),
          at + "ranges");
    // A ROBOTLASER1 line holds (start, resolution): angles that no resolution gives back bit for
    // bit, but evenly spaced to 1e-9 rad, come back to that precision. Ordinary angles are
    // start + i * step exactly, and come back so.
    const auto same_angle = [&](double x, double y) {
      return SameDouble(x, y) || (angles_to_1e9 && std::abs(x - y) <= 1e-9);
    };
    check(a.angles.size() == b.angles.size() && std::ranges::equal(a.angles, b.angles, same_angle),
          at + "angles" +
              (a.angles.size() == b.angles.size() && !a.angles.empty()
                   ? " (last " + Exact(a.angles.back()) + " vs " + Exact(b.angles.back()) + ")"
                   : std::string()));
    if (!a.carmen) {
      check(false, at + "no CARMEN fields");
      continue;
    }
    const CarmenLaserFields& c = *a.carmen;
    const std::optional<CarmenRecordFields> stamps =
        b.carmen ? std::optional<CarmenRecordFields>(CarmenRecordFields{
                       b.carmen->has_timestamps, b.carmen->host, b.carmen->logger_timestamp})
                 : std::nullopt;
    same_stamps(at, a.timestamp, {c.has_timestamps, c.host, c.logger_timestamp}, b.timestamp,
                stamps);
    if (!flaser && b.carmen) {
      check(c.laser_type == b.carmen->laser_type && SameDouble(c.accuracy, b.carmen->accuracy) &&
                c.remission_mode == b.carmen->remission_mode &&
                std::ranges::equal(c.remissions, b.carmen->remissions, SameDouble) &&
                SameDouble(c.tv, b.carmen->tv) && SameDouble(c.rv, b.carmen->rv) &&
                SameDouble(c.forward_safety_dist, b.carmen->forward_safety_dist) &&
                SameDouble(c.side_safety_dist, b.carmen->side_safety_dist) &&
                SameDouble(c.turn_axis, b.carmen->turn_axis),
            at + "ROBOTLASER1 fields");
    }
    // What a line does not carry: the status and max range as the reader derives them.
    if (!lost("max range")) check(SameDouble(a.max_range, b.max_range), at + "max_range");
    if (!lost("status")) check(a.status == b.status, at + "status");
    if (!lost("minimum range")) check(SameDouble(a.min_range, b.min_range), at + "min_range");
    if (!lost("range noise")) check(a.sigma == b.sigma, at + "sigma");
  }
  for (std::size_t k = 0; k < log.odometry.size(); ++k) {
    const OdometryRecord& a = read.odometry[k];
    const OdometryRecord& b = log.odometry[k];
    const std::string at = "odometry record " + std::to_string(k) + ": ";
    check(same_pose(a.pose, b.pose) && SameDouble(a.tv, b.tv) && SameDouble(a.rv, b.rv) &&
              SameDouble(a.accel, b.accel),
          at + "pose or velocities");
    same_stamps(at, a.timestamp, a.carmen.value_or(CarmenRecordFields{}), b.timestamp, b.carmen);
  }
  for (std::size_t k = 0; k < log.true_poses.size(); ++k) {
    const TruePoseRecord& a = read.true_poses[k];
    const TruePoseRecord& b = log.true_poses[k];
    const std::string at = "true pose record " + std::to_string(k) + ": ";
    check(same_pose(a.true_pose, b.true_pose) && same_pose(a.odom_pose, b.odom_pose), at + "poses");
    same_stamps(at, a.timestamp, a.carmen.value_or(CarmenRecordFields{}), b.timestamp, b.carmen);
  }
  return same ? ::testing::AssertionSuccess() : differs;
}

RC_GTEST_PROP(WriterRoundTrip, CarmenLog, ()) {
  Draw draw;
  Log log = DrawLog(draw);
  // A sonar ring is refused (CARMEN cannot carry its cones), and so is an empty log (the reader
  // takes a file without records for something else): both only in an adversarial case.
  if (!draw.adversarial()) {
    for (Scan& scan : log.scans) scan.sonar.reset();
    if (log.NumRecords() == 0) log.params.emplace_back("robot_use_laser", "on");
  }
  const std::string name = *rc::gen::element<std::string>("out.log", "out.log.gz", "Ωut.clf");
  WriteThenReadBack(
      draw, name, [&](const auto& path) { WriteCarmenLog(log, path); },
      [&](const auto& path) -> ::testing::AssertionResult {
        const Result<Log> read = ReadCarmenLog(path);
        if (!read.ok()) return ::testing::AssertionFailure() << read.error();
        return SameAsCarmenCarriesIt(read.value(), log, draw.adversarial());
      });
}

RC_GTEST_PROP(WriterRoundTrip, JsonScene, ()) {
  Draw draw;
  const Scene scene = DrawScene(draw);
  WriteThenReadBack(
      draw, DrawJsonName(), [&](const auto& path) { WriteJsonScene(scene, path); },
      [&](const auto& path) -> ::testing::AssertionResult {
        const Result<Scene> read = ReadJsonScene(path);
        if (!read.ok()) return ::testing::AssertionFailure() << read.error();
        return testing::SameScene(read.value(), scene);
      });
}

// The reader's words for a document's first problem: its diagnostic without the place.
std::string ReaderMessage(const std::string& document) {
  const Result<Scene> read = ParseJsonScene(document, "scene.json");
  if (read.ok()) return "(read)";
  const std::string error = read.error();
  const std::size_t from = error.find("error: ") + 7;
  return error.substr(from, error.rfind(" (at ") - from);
}

// A circle about a centre on the world's bound fits with no radius: the writer says, as the
// reader does, to move the centre inwards, not to take a radius of at most 0.
TEST(WriterRoundTrip, SceneWriterRefusesACircleBeyondTheWorldInTheReadersWords) {
  for (const double x : {-kMaxWorldCoordinate + 0.25, kMaxWorldCoordinate}) {
    Scene scene;
    scene.surfaces.push_back({Circle{Vec2(x, 0.0), 0.35}, false, ""});
    std::string written;
    try {
      written = FormatJsonScene(scene);
      ADD_FAILURE() << "expected IoError for x = " << x;
    } catch (const IoError& e) {
      written = e.what();
    }
    const std::string read = ReaderMessage(fmt::format(
        R"({{"format": "priormap.scene", "version": 1, "surfaces": [{{"type": "circle", )"
        R"("center": [{}, 0], "radius": 0.35}}]}})",
        x));
    EXPECT_THAT(written, HasSubstr("cannot write the scene: surface 0: " + read));
  }
  Scene scene;
  scene.surfaces.push_back({Circle{Vec2(0.0, kMaxWorldCoordinate), 0.35}, false, ""});
  try {
    (void)FormatJsonScene(scene);
    ADD_FAILURE() << "expected IoError";
  } catch (const IoError& e) {
    EXPECT_THAT(e.what(), HasSubstr("move the centre inwards by at least the radius 0.35"));
    EXPECT_THAT(e.what(), Not(HasSubstr("at most 0")));
  }
}

// Values the readers refuse that the writers used to write: a heading that is not finite (a NaN,
// or an infinity, which Se2 wraps to NaN), a radius <= 0 or NaN, a polyline of one point.
TEST(WriterRoundTrip, WritersRefuseAHeadingOrARadiusTheReadersWouldAndKeepTheOldFile) {
  const testing::TempDir dir;
  testing::WriteAll(dir / "out.json", "old");
  const auto expect_refused = [&](const auto& write, const std::string& message_part) {
    try {
      write(dir / "out.json");
      ADD_FAILURE() << "expected IoError containing: " << message_part;
    } catch (const IoError& e) {
      EXPECT_THAT(e.what(), HasSubstr(message_part));
    }
    EXPECT_EQ(testing::ReadAll(dir / "out.json"), "old");
    EXPECT_EQ(testing::FilesIn(dir.path()), std::vector<std::string>{"out.json"});
  };
  Scan scan;
  scan.pose = Se2(1.0, 2.0, kNaN);
  expect_refused([&](const auto& path) { WriteJsonScan(scan, path); },
                 "cannot write the scan: pose theta = nan, not a finite angle; priormap's "
                 "readers refuse it");
  scan.pose = Se2();
  scan.odom_pose = Se2(0.0, 0.0, kInf);
  expect_refused([&](const auto& path) { WriteJsonScan(scan, path); }, "odom_pose theta = nan");
  Log log;
  log.odometry.push_back({0.0, Se2(0.0, 0.0, -kInf), 0.0, 0.0, 0.0, std::nullopt});
  expect_refused([&](const auto& path) { WriteJsonLog(log, path); },
                 "cannot write the log: odometry record 0: pose theta = nan");
  log.odometry.clear();
  log.true_poses.push_back({0.0, Se2(), Se2(1.0, 1.0, kNaN), std::nullopt});
  expect_refused([&](const auto& path) { WriteJsonLog(log, path); },
                 "true pose record 0: odom_pose theta = nan");
  for (const double radius : {0.0, -0.0, -1.0, kNaN}) {
    Scene scene;
    scene.surfaces.push_back({Circle{Vec2(1.0, 1.0), radius}, false, "bin"});
    expect_refused([&](const auto& path) { WriteJsonScene(scene, path); },
                   "cannot write the scene: surface 0: circle radius must be positive and finite");
  }
  Scene scene;
  scene.default_pose = Se2(0.0, 0.0, kNaN);
  expect_refused([&](const auto& path) { WriteJsonScene(scene, path); },
                 "default_pose theta = nan");
  scene.default_pose.reset();
  scene.surfaces.push_back({Polyline{{Vec2(0.0, 0.0)}, false}, false, ""});
  expect_refused([&](const auto& path) { WriteJsonScene(scene, path); },
                 "surface 0: a polyline needs at least 2 points");
}

// Angles start + i * step with a step much finer than the angles: the estimate of the step from
// the first and last angles is many ulps from any step that gives them back, which must still
// be found, as a ROBOTLASER1 line holds only (start, resolution).
TEST(WriterRoundTrip, CarmenKeepsEvenlySpacedAnglesOfAFineStepBitForBit) {
  for (const double first : {-3.99, -1.0, 2.5}) {
    for (const double step : {1e-4, 3e-4, 7e-5}) {
      for (const std::size_t n : {5U, 181U, 1081U}) {
        Log log;
        Scan& scan = log.scans.emplace_back();
        scan.channel = "SIM";
        scan.angles = EvenAngles(n, first, step);
        scan.ranges.assign(n, 1.0);
        scan.sigma.assign(n, 0.01);
        scan.ClassifyAll();
        const Result<Log> read = ParseCarmenLog(FormatCarmenLog(log), "fine.log");
        ASSERT_TRUE(read.ok()) << read.error();
        EXPECT_EQ(read.value().scans.at(0).angles, scan.angles)
            << "first " << first << ", step " << step << ", n " << n;
      }
    }
  }
}

}  // namespace
}  // namespace priormap
