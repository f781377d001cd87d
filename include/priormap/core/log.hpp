#pragma once
/// A log: scans, odometry and true poses in the order they were recorded.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <priormap/core/scan.hpp>

namespace priormap {

/// How far the scan poses of a log can be trusted.
enum class PoseSource : std::uint8_t {
  kUnknown = 0,
  kOdometry,     ///< raw odometry: maps drawn from it smear
  kCorrected,    ///< optimised by a SLAM run (e.g. the Radish "corrected" logs)
  kGroundTruth,  ///< exact (simulation)
};

[[nodiscard]] const char* ToString(PoseSource source);
/// Inverse of ToString; nullopt for an unknown name.
[[nodiscard]] std::optional<PoseSource> PoseSourceFromString(std::string_view name);

/// CARMEN fields of ODOM / TRUEPOS records that priormap does not interpret.
struct CarmenRecordFields {
  bool has_timestamps = true;
  std::string host = "nohost";
  double logger_timestamp = 0.0;
};

struct OdometryRecord {
  double timestamp = 0.0;
  Se2 pose;                                ///< odometry pose of the robot
  double tv = 0.0, rv = 0.0, accel = 0.0;  ///< translational / rotational velocity, acceleration
  std::optional<CarmenRecordFields> carmen;
};

struct TruePoseRecord {
  double timestamp = 0.0;
  Se2 true_pose;
  Se2 odom_pose;
  std::optional<CarmenRecordFields> carmen;
};

struct Log {
  enum class RecordKind : std::uint8_t { kScan, kOdometry, kTruePose, kParam };
  struct RecordRef {
    RecordKind kind;
    std::size_t index;  ///< into the vector of that kind
    bool operator==(const RecordRef&) const = default;
  };

  PoseSource pose_source = PoseSource::kUnknown;
  std::vector<Scan> scans;
  std::vector<OdometryRecord> odometry;
  std::vector<TruePoseRecord> true_poses;
  /// (name, value) of CARMEN PARAM lines; the value is the rest of the line.
  std::vector<std::pair<std::string, std::string>> params;
  /// Record order as in the source file. Empty means: scans, then odometry, then true poses,
  /// then params. Writers keep it; code that appends records either appends here too or clears it.
  std::vector<RecordRef> order;

  [[nodiscard]] std::size_t NumRecords() const;
  /// `order`, or the default order when `order` is empty. Contract: `order` refers to every
  /// record exactly once.
  [[nodiscard]] std::vector<RecordRef> RecordOrder() const;
  /// Empty when consistent; otherwise what is wrong (scan problems prefixed by "scan K: ").
  [[nodiscard]] std::vector<std::string> Problems() const;
  /// The first position of the log beyond the world (world_bounds.hpp), named by record and
  /// field ("scan 3: pose x = 1e+300", "odometry record 0: pose y = inf"; scans as in
  /// Scan::FirstBeyondWorld), or nullopt. Writers refuse such a log: the readers would refuse
  /// the file.
  [[nodiscard]] std::optional<std::string> FirstBeyondWorld() const;
};

}  // namespace priormap
