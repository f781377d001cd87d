#pragma once
// The readers' warning for scans stamped earlier than the scan before them. Such a scan is kept
// where the file has it: every command takes the scans in the file's order (scan K, --range,
// scan --all's records) and none uses the timestamps, and real logs hold a few (intel-corrected:
// 4 scans up to 0.86 s early; infinite-corridor-corrected: 3 whose clock runs backwards before
// it wraps), so refusing or sorting them would lose data or renumber the scans. But whoever
// exports the log to a tool that interpolates in time must know.

#include <algorithm>
#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <priormap/core/diagnostic.hpp>

namespace priormap::detail {

/// Follows the timestamps of a log's scans in file order, per channel (a front and a rear laser
/// interleave their own clocks), and words a warning for each scan stamped strictly before the
/// previous stamped scan of its channel. Equal timestamps are normal (several logs stamp runs of
/// scans alike) and pass. The first kListed are warned of one by one, the rest in one summary at
/// the first of them.
class ScanTimeOrder {
 public:
  static constexpr std::size_t kListed = 5;

  struct Previous {
    std::size_t scan = 0;
    double timestamp = 0.0;
    int line = 0;  ///< 0 when the reader locates it only if needed
  };

  /// Notes scan `scan` of `channel`, stamped `timestamp` (finite), at `line` (0: unknown); returns
  /// the previous stamped scan of that channel when this one is stamped before it. Scans without a
  /// timestamp are not noted.
  std::optional<Previous> Note(std::string_view channel, std::size_t scan, double timestamp,
                               int line);

  /// Whether the next warning is given a location: each listed one, and the first beyond them,
  /// where the summary points. A reader whose locations cost a search (JSON) asks first.
  [[nodiscard]] bool WantsLocation() const { return count_ <= kListed; }

  /// The warning of scan `scan` of `channel`, stamped `timestamp` before `previous` (whose line
  /// the caller has filled in where it can), at `where` (file, line and column; a message there,
  /// such as JSON's " (at /records/7/timestamp)", is kept after the warning's).
  void Warn(Diagnostic where, std::string_view channel, std::size_t scan, double timestamp,
            const Previous& previous);

  /// The warnings, with the summary of those not listed.
  [[nodiscard]] std::vector<Diagnostic> Warnings() &&;

 private:
  std::vector<std::pair<std::string, Previous>> last_;  // per channel, in order of appearance
  std::size_t count_ = 0;
  std::vector<Diagnostic> warnings_;
  Diagnostic first_unlisted_;
  std::size_t first_unlisted_scan_ = 0;
};

/// A scan with a timestamp, in file order.
struct StampedScan {
  std::size_t scan = 0;
  std::string_view channel;
  double timestamp = 0.0;
};

/// ScanTimeOrder's warnings for `stamped`, for a reader whose positions cost a search (JSON):
/// the scans out of order are found first, then `locate(scans)` is asked once for where the
/// timestamps of the few scans the warnings name are (increasing scan indices, a dozen at
/// most): a Diagnostic each with file, line and column, and a message to follow the warning's
/// (or none).
template <typename Locate>
std::vector<Diagnostic> TimeOrderWarnings(std::span<const StampedScan> stamped,
                                          const Locate& locate) {
  struct OutOfOrder {
    const StampedScan* scan;
    ScanTimeOrder::Previous previous;
  };
  ScanTimeOrder order;
  std::vector<OutOfOrder> found;
  for (const StampedScan& s : stamped)
    if (const auto previous = order.Note(s.channel, s.scan, s.timestamp, 0))
      found.push_back({&s, *previous});
  if (found.empty()) return {};
  // The scans warned of one by one and the first of the rest (WantsLocation), and the scans
  // before them.
  std::vector<std::size_t> scans;
  for (std::size_t w = 0; w < found.size() && w <= ScanTimeOrder::kListed; ++w) {
    scans.push_back(found[w].scan->scan);
    scans.push_back(found[w].previous.scan);
  }
  std::ranges::sort(scans);
  scans.erase(std::unique(scans.begin(), scans.end()), scans.end());
  const std::vector<Diagnostic> located = locate(std::span<const std::size_t>(scans));
  const auto where = [&](std::size_t scan) {
    const auto it = std::ranges::lower_bound(scans, scan);
    return located[static_cast<std::size_t>(it - scans.begin())];
  };
  for (const OutOfOrder& o : found) {
    ScanTimeOrder::Previous previous = o.previous;
    Diagnostic at;
    if (order.WantsLocation()) {
      previous.line = where(previous.scan).line;
      at = where(o.scan->scan);
    }
    order.Warn(std::move(at), o.scan->channel, o.scan->scan, o.scan->timestamp, previous);
  }
  return std::move(order).Warnings();
}

}  // namespace priormap::detail
