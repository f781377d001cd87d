#pragma once
/// The `laser_data` JSON of Andrea Censi's Canonical Scan Matcher (CSM): a stream of JSON
/// objects, one per scan, concatenated or one per line, as csm's ld_write_as_json writes them
/// (docs/formats.md). Read only; problems are reported at file:line:col of the offending value.

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include <priormap/core/diagnostic.hpp>
#include <priormap/core/log.hpp>

namespace priormap {

struct CsmReadOptions {
  /// Readings below this are invalid. CSM's laser_data carries no range limits.
  double min_range = 0.0;
  /// Readings at or above this are max-range readings; unset: none is (+inf).
  std::optional<double> max_range;
  /// Noise standard deviation of readings without a usable "readings_sigma" entry, m.
  double sigma = 0.01;
};

/// Parses CSM laser_data text; `name` is used in diagnostics. Each object becomes a scan
/// (channel "CSM"). Its pose is "true_pose", else "estimate", else "odometry": the first of these
/// that every scan has, recorded in Log::pose_source (ground_truth, corrected, odometry); when no
/// one of them is in every scan, each scan takes the first it has and pose_source is unknown.
/// "odometry", when known, is also the scan's odom_pose. Readings flagged invalid (valid 0) and
/// null ones are kInvalid; the others get ClassifyReading's status within the options' range.
/// Every reading is kept as read. One diagnostic, at the first problem (columns count characters).
/// A scan whose "timestamp" is before the previous one's is kept in the file's order, with a
/// warning there (Result::warnings).
[[nodiscard]] Result<Log> ParseCsmLog(std::string_view text, const std::string& name,
                                      const CsmReadOptions& options = {});

/// Reads and parses a CSM laser_data file (plain or gzip-compressed).
[[nodiscard]] Result<Log> ReadCsmLog(const std::filesystem::path& path,
                                     const CsmReadOptions& options = {});

/// Whether `text` starts with a CSM laser_data object: a JSON object whose top-level members
/// include "nrays" and "readings" (and not "format", the key of priormap's documents). Only the
/// first object is looked at, and only as far as needed.
[[nodiscard]] bool LooksLikeCsmLog(std::string_view text);

}  // namespace priormap
