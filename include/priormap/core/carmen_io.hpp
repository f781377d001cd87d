#pragma once
/// CARMEN logs (Radish / Freiburg datasets): FLASER, RLASER, ROBOTLASER1, ODOM, TRUEPOS and PARAM
/// records, plain or gzip-compressed. Other record types are skipped and counted. The format and
/// the choices made where it is ambiguous are in docs/formats.md.

#include <filesystem>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <priormap/core/diagnostic.hpp>
#include <priormap/core/log.hpp>

namespace priormap {

struct CarmenReadOptions {
  /// Readings at or above this are max-range readings: it shortens the sensor's max range
  /// (ROBOTLASER1's own field, else the one detected from the log by DetectMaxRangeSentinel)
  /// and is used where the sensor has none; it never lengthens it.
  std::optional<double> max_range;
  /// Readings below this are invalid.
  double min_range = 0.0;
  /// Field of view of FLASER/RLASER lines, which carry no angles: beam i of n is at
  /// -fov/2 + i * fov / n for n = 180 or 360, and -fov/2 + i * fov / (n - 1) otherwise
  /// (the SICK conventions of the Radish logs).
  double fov = 3.141592653589793;
  /// Noise standard deviation given to every reading, m.
  double sigma = 0.01;
  PoseSource pose_source = PoseSource::kUnknown;
  /// Reading stops after this many diagnostics.
  int max_diagnostics = 20;
  /// How diagnostics name min_range and max_range: a command names the options they came from
  /// ("--min-range"), so that its user knows which value to change.
  std::string min_range_name = "the minimum range";
  std::string max_range_name = "the given max range";
};

struct CarmenReadStats {
  std::map<std::string, int> records;        ///< per record type, including skipped ones
  std::optional<double> detected_max_range;  ///< from DetectMaxRangeSentinel
  int comment_lines = 0;
  /// The first text kept from the log (a PARAM's name or value, a host name) that is not UTF-8,
  /// located at its first byte that is not ("expected UTF-8 text in ..."): CARMEN keeps the
  /// bytes as read, but JSON holds only UTF-8, so a JSON writer would have to replace them.
  std::optional<Diagnostic> not_utf8;
};

/// Reads a CARMEN log file. `stats` (optional) receives what was found.
[[nodiscard]] Result<Log> ReadCarmenLog(const std::filesystem::path& path,
                                        const CarmenReadOptions& options = {},
                                        CarmenReadStats* stats = nullptr);

/// Parses CARMEN text; `name` is used in diagnostics, whose columns count characters (UTF-8 code
/// points, as an editor does), not bytes. A scan stamped (ipc_timestamp) before the previous
/// stamped scan of its record type is kept in the file's order, with a warning at that field
/// (Result::warnings); equal timestamps are normal.
[[nodiscard]] Result<Log> ParseCarmenLog(std::string_view text, const std::string& name,
                                         const CarmenReadOptions& options = {},
                                         CarmenReadStats* stats = nullptr);

/// Writes `log` as CARMEN text. Scans whose angles follow the FLASER convention above are
/// written as their channel (FLASER/RLASER); any other scan as ROBOTLASER1. Non-finite
/// readings are written as "nan". Throws IoError, writing nothing, for what a CARMEN line cannot
/// hold or the reader would refuse, such as a position beyond the world (Log::FirstBeyondWorld),
/// a heading that is not finite, a PARAM value with blanks at its ends, an empty log, a sonar ring
/// or an inconsistent log (Log::Problems).
[[nodiscard]] std::string FormatCarmenLog(const Log& log);

/// FormatCarmenLog, written atomically (gzip-compressed when `path` ends in .gz).
void WriteCarmenLog(const Log& log, const std::filesystem::path& path);

/// What FormatCarmenLog cannot carry of `log`, one phrase per kind with its count ("the ground
/// truth of 12 scans", ...): the noise model (sigma other than the reader's default, a precision
/// matrix), ground truth, odometry poses of scans written as ROBOTLASER1 (in a log without ODOM
/// records), robot poses of scans written as FLASER/RLASER, timestamps of records whose CARMEN
/// fields say their line has none (has_timestamps false, read back as 0), a minimum range, a max
/// range that reading back would not find (FLASER lines have none: it is detected again from their
/// readings), readings whose status would read back otherwise, and the pose source. Empty when
/// reading the text back gives the same log, so that a command can warn before the user relies on a
/// log that reads back different.
[[nodiscard]] std::vector<std::string> CarmenLosses(const Log& log);

/// The beam angles of a FLASER/RLASER line of n readings (see CarmenReadOptions::fov).
[[nodiscard]] std::vector<double> FlaserBeamAngles(std::size_t n, double fov);

/// The "no return" threshold of a log, if its readings show one: the largest value (to the cm)
/// read at least 10 times is the sentinel s when the readings within 0.5 m below s
/// outnumber those in [s - 2.5, s - 0.5) m at least ten to one; the threshold is then s - 0.5 m.
/// Covers the SICK codes (81.83, 81.91), ACES (50.0), Oerebro (32.77) and the ~51 m clusters.
[[nodiscard]] std::optional<double> DetectMaxRangeSentinel(const std::vector<double>& readings);
/// The same over several groups of readings (a log's scans, read in place).
[[nodiscard]] std::optional<double> DetectMaxRangeSentinel(
    std::span<const std::span<const double>> groups);

}  // namespace priormap
