#pragma once
// --log LOG and --range a:b, shared by `priormap prf` and `priormap grid`.

#include <cstddef>
#include <optional>
#include <string>

#include <priormap/core/log.hpp>

namespace priormap::app {

struct ScanRange {
  std::size_t first = 0;
  std::optional<std::size_t> end;  // one past the last
};

/// "a:b", "a:" or ":b" (scan indices, b exclusive); throws UserError naming --range otherwise.
[[nodiscard]] ScanRange ParseScanRange(const std::string& text);

/// The log at `path` (CARMEN or priormap JSON, gzip or not); diagnostics as a UserError.
[[nodiscard]] Log ReadLogOrThrow(const std::string& path);

}  // namespace priormap::app
