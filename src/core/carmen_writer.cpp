#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <span>
#include <string_view>

#include <fmt/format.h>

#include <priormap/core/carmen_io.hpp>
#include <priormap/core/check.hpp>
#include <priormap/core/file_io.hpp>
#include <priormap/core/world_bounds.hpp>

#include "angle_step.hpp"

namespace priormap {
namespace {

// Which record a value belongs to, for error messages ("scan 3", "param 0").
struct RecordName {
  const char* kind;
  std::size_t index;
};

// Values that a CARMEN line cannot hold are refused rather than written into a file that the
// reader would reject or, worse, misread (a blank in a PARAM name, a line break in its value).
void RequireFinite(double value, const char* field, RecordName record) {
  if (!std::isfinite(value)) {
    throw IoError(fmt::format("{} {} has {} {}, which a CARMEN log cannot hold (it must be finite)",
                              record.kind, record.index, field, value));
  }
}

void RequireFinite(const Se2& pose, const char* field, RecordName record) {
  if (!pose.IsFinite()) {
    throw IoError(fmt::format("{} {} has a non-finite {} ({}), which a CARMEN log cannot hold",
                              record.kind, record.index, field, pose.ToString()));
  }
}

void RequireWord(const std::string& value, const char* field, RecordName record) {
  if (value.empty() || value.find_first_of(" \t\r\n") != std::string::npos) {
    throw IoError(
        fmt::format("{} {} has {} '{}', which a CARMEN log cannot hold (it must be one "
                    "word)",
                    record.kind, record.index, field, value));
  }
}

void RequireTimestamps(double timestamp, bool has_timestamps, const std::string& host,
                       double logger_timestamp, RecordName record) {
  if (!has_timestamps) return;
  RequireFinite(timestamp, "timestamp", record);
  RequireWord(host, "host", record);
  RequireFinite(logger_timestamp, "logger_timestamp", record);
}

void RequireRecordTimestamps(double timestamp, const std::optional<CarmenRecordFields>& carmen,
                             RecordName record) {
  if (carmen) {
    RequireTimestamps(timestamp, carmen->has_timestamps, carmen->host, carmen->logger_timestamp,
                      record);
  } else {
    RequireFinite(timestamp, "timestamp", record);
  }
}

// FLASER lines carry no angles: only scans with the reader's default angles can be one (an
// empty scan included: "FLASER 0 ..." is read back as it was written).
bool HasFlaserAngles(const Scan& scan) {
  return FlaserBeamAngles(scan.size(), CarmenReadOptions{}.fov) == scan.angles;
}

// start_angle and angular_resolution that reproduce the scan's angles as start + i * resolution.
std::pair<double, double> RobotLaserAngles(const Scan& scan, std::size_t scan_index) {
  const std::size_t n = scan.size();
  if (scan.carmen && scan.carmen->angular_resolution != 0.0) {
    const CarmenLaserFields& c = *scan.carmen;
    bool same = true;
    for (std::size_t i = 0; i < n && same; ++i) {
      same = c.start_angle + static_cast<double>(i) * c.angular_resolution == scan.angles[i];
    }
    if (same && std::isfinite(c.start_angle) && std::isfinite(c.angular_resolution)) {
      return {c.start_angle, c.angular_resolution};
    }
  }
  if (n < 2) return {n == 1 ? scan.angles[0] : 0.0, 0.0};
  // A step that gives the angles back bit for bit, when there is one; the reader's angles are
  // start + i * resolution, and the estimate below may be an ulp off it.
  if (const auto step = detail::ExactAngleStep(scan.angles); step && *step > 0.0)
    return {scan.angles[0], *step};
  const double resolution = (scan.angles[n - 1] - scan.angles[0]) / static_cast<double>(n - 1);
  if (!(resolution > 0.0)) {
    throw IoError(
        fmt::format("scan {} has beam angles that do not increase, which a CARMEN log "
                    "cannot represent",
                    scan_index));
  }
  for (std::size_t i = 0; i < n; ++i) {
    const double expected = scan.angles[0] + static_cast<double>(i) * resolution;
    if (!(std::abs(expected - scan.angles[i]) <= 1e-9)) {  // NaN angles are not evenly spaced
      throw IoError(fmt::format(
          "scan {} has unevenly spaced beam angles, which a CARMEN log cannot represent; "
          "write JSON instead",
          scan_index));
    }
  }
  return {scan.angles[0], resolution};
}

void AppendNumbers(std::string& out, const std::vector<double>& values) {
  for (double v : values) fmt::format_to(std::back_inserter(out), " {}", v);
}

void AppendPose(std::string& out, const Se2& pose) {
  fmt::format_to(std::back_inserter(out), " {} {} {}", pose.x(), pose.y(), pose.theta());
}

void AppendTimestamps(std::string& out, double timestamp, bool has_timestamps,
                      const std::string& host, double logger_timestamp) {
  if (has_timestamps)
    fmt::format_to(std::back_inserter(out), " {} {} {}", timestamp, host, logger_timestamp);
}

void AppendRecordTimestamps(std::string& out, double timestamp,
                            const std::optional<CarmenRecordFields>& carmen) {
  if (carmen) {
    AppendTimestamps(out, timestamp, carmen->has_timestamps, carmen->host,
                     carmen->logger_timestamp);
  } else {
    AppendTimestamps(out, timestamp, true, "priormap", timestamp);
  }
}

// Whether `scan` is written as a FLASER/RLASER line (else as ROBOTLASER1).
bool WrittenAsFlaser(const Scan& scan) {
  return (scan.channel == "FLASER" || scan.channel == "RLASER") && scan.odom_pose.has_value() &&
         HasFlaserAngles(scan);
}

// A ROBOTLASER1 record's own field of view is written back as read (0 included).
bool HasOwnFieldOfView(const Scan& scan) {
  return scan.carmen && (scan.channel == "ROBOTLASER1" || scan.carmen->fov != 0.0);
}

// The max range a ROBOTLASER1 line gets: the record's own maximum_range as read (writing the
// detected one in its place would make its readings leave the detection when read again).
double WrittenMaxRange(const Scan& scan) {
  return HasOwnFieldOfView(scan) && scan.carmen->maximum_range ? *scan.carmen->maximum_range
                                                               : scan.max_range;
}

void AppendScan(std::string& out, const Scan& scan, std::size_t index) {
  const RecordName record{"scan", index};
  // Before the angles are read one per reading (the other checks of an inconsistent log come
  // after the records, whose checks say more precisely what a CARMEN line cannot hold).
  if (scan.angles.size() != scan.size())
    throw IoError(
        fmt::format("cannot write an inconsistent log: scan {}: angles has {} entries "
                    "for {} readings",
                    index, scan.angles.size(), scan.size()));
  const CarmenLaserFields carmen = scan.carmen.value_or(CarmenLaserFields{});
  const bool old_style = WrittenAsFlaser(scan);
  RequireFinite(scan.pose, "pose", record);
  if (old_style) RequireFinite(*scan.odom_pose, "odometry pose", record);
  if (!old_style) RequireFinite(scan.robot_pose.value_or(scan.pose), "robot pose", record);
  if (scan.carmen) {
    RequireTimestamps(scan.timestamp, carmen.has_timestamps, carmen.host, carmen.logger_timestamp,
                      record);
  } else {
    RequireFinite(scan.timestamp, "timestamp", record);
  }
  if (old_style) {
    fmt::format_to(std::back_inserter(out), "{} {}", scan.channel, scan.size());
    AppendNumbers(out, scan.ranges);
    AppendPose(out, scan.pose);
    AppendPose(out, *scan.odom_pose);
  } else {
    const auto [start, resolution] = RobotLaserAngles(scan, index);
    // Other scans than ROBOTLASER1 records get the span of their angles.
    const double fov = HasOwnFieldOfView(scan) ? carmen.fov
                       : scan.size() > 1       ? resolution * static_cast<double>(scan.size() - 1)
                                               : 0.0;
    RequireFinite(fov, "field of view", record);
    const double max_range = WrittenMaxRange(scan);
    fmt::format_to(std::back_inserter(out), "ROBOTLASER1 {} {} {} {} {} {} {} {}",
                   carmen.laser_type, start, fov, resolution, max_range, carmen.accuracy,
                   carmen.remission_mode, scan.size());
    AppendNumbers(out, scan.ranges);
    fmt::format_to(std::back_inserter(out), " {}", carmen.remissions.size());
    AppendNumbers(out, carmen.remissions);
    AppendPose(out, scan.pose);
    AppendPose(out, scan.robot_pose.value_or(scan.pose));
    fmt::format_to(std::back_inserter(out), " {} {} {} {} {}", carmen.tv, carmen.rv,
                   carmen.forward_safety_dist, carmen.side_safety_dist, carmen.turn_axis);
  }
  if (scan.carmen) {
    AppendTimestamps(out, scan.timestamp, carmen.has_timestamps, carmen.host,
                     carmen.logger_timestamp);
  } else {
    AppendTimestamps(out, scan.timestamp, true, "priormap", scan.timestamp);
  }
  out += '\n';
}

std::string Counted(std::size_t n, std::string_view what, std::string_view unit,
                    std::string_view note = "") {
  return fmt::format("{} of {} {}{}{}", what, n, unit, n == 1 ? "" : "s", note);
}

}  // namespace

namespace {

// The max range each scan reads back with, as the reader finds it: a ROBOTLASER1 line's own
// (when positive), else the one detected from the lines without one (`detected`, +inf for none).
struct ReadBackMaxRanges {
  std::vector<bool> as_flaser;
  std::vector<std::optional<double>> own;
  double detected = std::numeric_limits<double>::infinity();

  explicit ReadBackMaxRanges(const Log& log) {
    std::vector<std::span<const double>> without_own;
    for (const Scan& scan : log.scans) {
      as_flaser.push_back(WrittenAsFlaser(scan));
      const double written = WrittenMaxRange(scan);
      own.push_back(!as_flaser.back() && written > 0.0 ? std::optional<double>(written)
                                                       : std::nullopt);
      if (!own.back()) without_own.emplace_back(scan.ranges);
    }
    detected = DetectMaxRangeSentinel(without_own).value_or(detected);
  }

  [[nodiscard]] double of(std::size_t k) const { return own[k].value_or(detected); }
};

// A no-return reading longer than any return may be (world_bounds.hpp) is kept by the reader
// only if it reads back as a no-return: a FLASER line has no field for its max range, and the
// one detected may be longer or none, making it a return that the reader refuses.
void RequireNoOverlongReturnReadBack(const Log& log) {
  bool any = false;
  for (const Scan& scan : log.scans)
    any = any || std::ranges::any_of(scan.ranges, [](double r) {
            return std::isfinite(r) && !IsReturnWithinWorld(r);
          });
  if (!any) return;
  const ReadBackMaxRanges max_ranges(log);
  const CarmenReadOptions read_back;
  for (std::size_t k = 0; k < log.scans.size(); ++k) {
    const std::vector<double>& ranges = log.scans[k].ranges;
    for (std::size_t i = 0; i < ranges.size(); ++i) {
      if (IsReturnWithinWorld(ranges[i]) ||
          ClassifyReading(ranges[i], read_back.min_range, max_ranges.of(k)) != BeamStatus::kValid)
        continue;
      throw IoError(fmt::format(
          "cannot write the log as CARMEN: scan {}: reading {} = {} m would read back as a return "
          "(below the max range {} m that the reader would find), beyond {:.0e} m, which the "
          "reader refuses; write priormap JSON, which keeps the max range",
          k, i, ranges[i], max_ranges.of(k), kMaxWorldCoordinate));
    }
  }
}

}  // namespace

std::vector<std::string> CarmenLosses(const Log& log) {
  const CarmenReadOptions read_back;
  const ReadBackMaxRanges max_ranges(log);
  const std::vector<bool>& as_flaser = max_ranges.as_flaser;
  const double detected = max_ranges.detected;
  std::size_t other_sigma = 0, precision = 0, truth = 0, odometry = 0, min_range = 0, max_range = 0,
              status = 0, robot_pose = 0, timestamps = 0;
  // A line whose CARMEN fields say it has no timestamps is read back at time +0.
  const auto drops_timestamp = [](double timestamp, const auto& carmen) {
    return carmen && !carmen->has_timestamps && !(timestamp == 0.0 && !std::signbit(timestamp));
  };
  for (const OdometryRecord& r : log.odometry) timestamps += drops_timestamp(r.timestamp, r.carmen);
  for (const TruePoseRecord& r : log.true_poses)
    timestamps += drops_timestamp(r.timestamp, r.carmen);
  for (std::size_t k = 0; k < log.scans.size(); ++k) {
    const Scan& scan = log.scans[k];
    timestamps += drops_timestamp(scan.timestamp, scan.carmen);
    if (scan.robot_pose && as_flaser[k]) ++robot_pose;
    if (std::ranges::any_of(scan.sigma, [&](double s) { return s != read_back.sigma; }))
      ++other_sigma;
    if (scan.precision) ++precision;
    if (scan.truth) ++truth;
    // ODOM records, where the log has them, carry the odometry that ROBOTLASER1 lines cannot.
    if (scan.odom_pose && !as_flaser[k] && log.odometry.empty()) ++odometry;
    if (scan.min_range != read_back.min_range) ++min_range;
    const double read_max_range = max_ranges.of(k);
    if (read_max_range != scan.max_range) ++max_range;
    for (std::size_t i = 0; i < scan.size(); ++i)
      if (scan.status[i] != ClassifyReading(scan.ranges[i], read_back.min_range, read_max_range))
        ++status;
  }
  std::vector<std::string> losses;
  if (other_sigma > 0)
    losses.push_back(Counted(other_sigma, "the range noise", "scan",
                             fmt::format(" (read back as sigma {} m)", read_back.sigma)));
  if (precision > 0) losses.push_back(Counted(precision, "the correlated noise", "scan"));
  if (truth > 0) losses.push_back(Counted(truth, "the ground truth", "scan"));
  if (odometry > 0)
    losses.push_back(
        Counted(odometry, "the odometry pose", "scan", " (ROBOTLASER1 has no field for it)"));
  if (robot_pose > 0)
    losses.push_back(
        Counted(robot_pose, "the robot pose", "scan", " (FLASER has no field for it)"));
  if (timestamps > 0)
    losses.push_back(Counted(timestamps, "the timestamp", "record",
                             " (its CARMEN fields say that its line has none: read back as 0)"));
  if (min_range > 0) losses.push_back(Counted(min_range, "the minimum range", "scan"));
  if (max_range > 0)
    losses.push_back(Counted(max_range, "the max range", "scan",
                             std::isinf(detected)
                                 ? std::string(" (FLASER has no field for it)")
                                 : fmt::format(" (read back as the {} m detected from the "
                                               "no-return readings)",
                                               detected)));
  if (status > 0)
    losses.push_back(Counted(status, "the status", "reading", " (read back from its value)"));
  if (log.pose_source != read_back.pose_source)
    losses.push_back(fmt::format("the pose source \"{}\" (read back as \"{}\")",
                                 ToString(log.pose_source), ToString(read_back.pose_source)));
  return losses;
}

std::string FormatCarmenLog(const Log& log) {
  // The reader refuses a file without records, as it is likely not a CARMEN log at all.
  if (log.NumRecords() == 0)
    throw IoError(
        "cannot write the log as CARMEN: it has no records, and the reader refuses a CARMEN file "
        "without any; write priormap JSON, which holds an empty log");
  std::string out = "# written by priormap; record formats as in docs/formats.md\n";
  for (const Log::RecordRef& ref : log.RecordOrder()) {
    switch (ref.kind) {
      case Log::RecordKind::kScan:
        AppendScan(out, log.scans[ref.index], ref.index);
        break;
      case Log::RecordKind::kOdometry: {
        const OdometryRecord& r = log.odometry[ref.index];
        RequireFinite(r.pose, "pose", {"odometry record", ref.index});
        RequireRecordTimestamps(r.timestamp, r.carmen, {"odometry record", ref.index});
        out += "ODOM";
        AppendPose(out, r.pose);
        fmt::format_to(std::back_inserter(out), " {} {} {}", r.tv, r.rv, r.accel);
        AppendRecordTimestamps(out, r.timestamp, r.carmen);
        out += '\n';
        break;
      }
      case Log::RecordKind::kTruePose: {
        const TruePoseRecord& r = log.true_poses[ref.index];
        RequireFinite(r.true_pose, "true pose", {"true pose record", ref.index});
        RequireFinite(r.odom_pose, "odometry pose", {"true pose record", ref.index});
        RequireRecordTimestamps(r.timestamp, r.carmen, {"true pose record", ref.index});
        out += "TRUEPOS";
        AppendPose(out, r.true_pose);
        AppendPose(out, r.odom_pose);
        AppendRecordTimestamps(out, r.timestamp, r.carmen);
        out += '\n';
        break;
      }
      case Log::RecordKind::kParam: {
        const auto& [name, value] = log.params[ref.index];
        RequireWord(name, "name", {"param", ref.index});
        if (value.find('\n') != std::string::npos) {
          throw IoError(
              fmt::format("param {} ({}) has a line break in its value, which a CARMEN "
                          "log cannot hold",
                          ref.index, name));
        }
        // The reader takes the value from its first field to the end of the line, less the
        // blanks that end it: blanks at either end would not read back.
        if (!value.empty() &&
            (value.find_first_of(" \t\r") == 0 || value.find_last_of(" \r") == value.size() - 1)) {
          throw IoError(
              fmt::format("param {} ({}) has the value '{}', which a CARMEN log cannot hold (it "
                          "must not start with a blank nor end with a space)",
                          ref.index, name, value));
        }
        fmt::format_to(std::back_inserter(out), "PARAM {}{}{}\n", name, value.empty() ? "" : " ",
                       value);
        break;
      }
    }
  }
  // After the records, whose checks say what a CARMEN line cannot hold (a non-finite pose).
  if (const auto beyond = log.FirstBeyondWorld())
    throw IoError(CannotWriteBeyondWorld("the log", *beyond));
  if (const std::vector<std::string> problems = log.Problems(); !problems.empty())
    throw IoError(fmt::format("cannot write an inconsistent log: {}", problems.front()));
  for (std::size_t k = 0; k < log.scans.size(); ++k)
    if (log.scans[k].sonar)
      throw IoError(fmt::format(
          "scan {} is a sonar ring, whose cones a CARMEN log cannot hold (it would read back as a "
          "laser scan); write priormap JSON",
          k));
  RequireNoOverlongReturnReadBack(log);
  return out;
}

void WriteCarmenLog(const Log& log, const std::filesystem::path& path) {
  WriteTextFileAtomically(path, FormatCarmenLog(log));
}

}  // namespace priormap
