#pragma once
// --range a:b over a log's scans, shared by `priormap prf` and `priormap grid`.

#include <cstddef>
#include <optional>
#include <string>
#include <utility>

namespace priormap::app {

struct ScanRange {
  std::size_t first = 0;
  std::optional<std::size_t> end;  // one past the last
};

/// "a:b", "a:" or ":b" (scan indices, b exclusive); throws UserError naming --range otherwise.
[[nodiscard]] ScanRange ParseScanRange(const std::string& text);

/// The scans [first, end) that `range` selects in a log of `scans` scans; throws UserError when
/// the log has none, and naming --range when the range selects none or ends past the log.
[[nodiscard]] std::pair<std::size_t, std::size_t> SelectedScans(const ScanRange& range,
                                                                std::size_t scans);

}  // namespace priormap::app
