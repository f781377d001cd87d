#include <priormap/core/carmen_io.hpp>
#include <priormap/core/check.hpp>
#include <priormap/core/file_io.hpp>

#include <cmath>

#include <fmt/format.h>

namespace priormap {
namespace {


// FLASER lines carry no angles: only scans with the reader's default angles can be one.
bool HasFlaserAngles(const Scan& scan) {
  return scan.size() > 0 && FlaserBeamAngles(scan.size(), CarmenReadOptions{}.fov) == scan.angles;
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
    if (same) return {c.start_angle, c.angular_resolution};
  }
  if (n < 2) return {n == 1 ? scan.angles[0] : 0.0, 0.0};
  const double resolution = (scan.angles[n - 1] - scan.angles[0]) / static_cast<double>(n - 1);
  for (std::size_t i = 0; i < n; ++i) {
    const double expected = scan.angles[0] + static_cast<double>(i) * resolution;
    if (std::abs(expected - scan.angles[i]) > 1e-9) {
      throw IoError(fmt::format(
          "scan {} has unevenly spaced beam angles, which a CARMEN log cannot represent; "
          "write JSON instead", scan_index));
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
  if (has_timestamps) fmt::format_to(std::back_inserter(out), " {} {} {}", timestamp, host, logger_timestamp);
}

void AppendRecordTimestamps(std::string& out, double timestamp,
                            const std::optional<CarmenRecordFields>& carmen) {
  if (carmen) {
    AppendTimestamps(out, timestamp, carmen->has_timestamps, carmen->host, carmen->logger_timestamp);
  } else {
    AppendTimestamps(out, timestamp, true, "priormap", timestamp);
  }
}

void AppendScan(std::string& out, const Scan& scan, std::size_t index) {
  const CarmenLaserFields carmen = scan.carmen.value_or(CarmenLaserFields{});
  const bool old_style = (scan.channel == "FLASER" || scan.channel == "RLASER") &&
                         scan.odom_pose.has_value() && HasFlaserAngles(scan);
  if (old_style) {
    fmt::format_to(std::back_inserter(out), "{} {}", scan.channel, scan.size());
    AppendNumbers(out, scan.ranges);
    AppendPose(out, scan.pose);
    AppendPose(out, *scan.odom_pose);
  } else {
    const auto [start, resolution] = RobotLaserAngles(scan, index);
    const double fov = carmen.fov != 0.0 ? carmen.fov : resolution * static_cast<double>(scan.size() - 1);
    fmt::format_to(std::back_inserter(out), "ROBOTLASER1 {} {} {} {} {} {} {} {}", carmen.laser_type,
                   start, fov, resolution, scan.max_range, carmen.accuracy, carmen.remission_mode,
                   scan.size());
    AppendNumbers(out, scan.ranges);
    fmt::format_to(std::back_inserter(out), " {}", carmen.remissions.size());
    AppendNumbers(out, carmen.remissions);
    AppendPose(out, scan.pose);
    AppendPose(out, scan.robot_pose.value_or(scan.pose));
    fmt::format_to(std::back_inserter(out), " {} {} {} {} {}", carmen.tv, carmen.rv,
                   carmen.forward_safety_dist, carmen.side_safety_dist, carmen.turn_axis);
  }
  if (scan.carmen) {
    AppendTimestamps(out, scan.timestamp, carmen.has_timestamps, carmen.host, carmen.logger_timestamp);
  } else {
    AppendTimestamps(out, scan.timestamp, true, "priormap", scan.timestamp);
  }
  out += '\n';
}

}  // namespace

std::string FormatCarmenLog(const Log& log) {
  std::string out = "# written by priormap; record formats as in docs/formats.md\n";
  for (const Log::RecordRef& ref : log.RecordOrder()) {
    switch (ref.kind) {
      case Log::RecordKind::kScan:
        AppendScan(out, log.scans[ref.index], ref.index);
        break;
      case Log::RecordKind::kOdometry: {
        const OdometryRecord& r = log.odometry[ref.index];
        out += "ODOM";
        AppendPose(out, r.pose);
        fmt::format_to(std::back_inserter(out), " {} {} {}", r.tv, r.rv, r.accel);
        AppendRecordTimestamps(out, r.timestamp, r.carmen);
        out += '\n';
        break;
      }
      case Log::RecordKind::kTruePose: {
        const TruePoseRecord& r = log.true_poses[ref.index];
        out += "TRUEPOS";
        AppendPose(out, r.true_pose);
        AppendPose(out, r.odom_pose);
        AppendRecordTimestamps(out, r.timestamp, r.carmen);
        out += '\n';
        break;
      }
      case Log::RecordKind::kParam: {
        const auto& [name, value] = log.params[ref.index];
        fmt::format_to(std::back_inserter(out), "PARAM {}{}{}\n", name, value.empty() ? "" : " ", value);
        break;
      }
    }
  }
  return out;
}

void WriteCarmenLog(const Log& log, const std::filesystem::path& path) {
  WriteTextFileAtomically(path, FormatCarmenLog(log));
}

}  // namespace priormap
