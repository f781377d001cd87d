#pragma once
// What the harnesses check besides "no crash, no sanitizer report": a failed check prints what
// went wrong and aborts, which libFuzzer records as a crash with the input that caused it.

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>
#include <vector>

#include <priormap/core/diagnostic.hpp>

namespace priormap::fuzz {

inline void Check(bool ok, const char* what, std::string_view detail = {}) {
  if (ok) return;
  std::fprintf(stderr, "fuzz check failed: %s\n%.*s\n", what, static_cast<int>(detail.size()),
               detail.data());
  std::abort();
}

/// A rejected input has diagnostics, each of `name` and at a line and column inside `text`.
inline void CheckLocated(const std::vector<priormap::Diagnostic>& diagnostics,
                         std::string_view text, const std::string& name) {
  Check(!diagnostics.empty(), "a failed read has diagnostics");
  for (const priormap::Diagnostic& d : diagnostics) {
    Check(d.file == name && !d.message.empty(), "a diagnostic names the file and the problem",
          d.ToString());
    Check(d.line >= 1 && d.col >= 1, "a diagnostic is located", d.ToString());
    std::size_t start = 0;
    for (int line = 1; line < d.line; ++line) {
      start = text.find('\n', start);
      Check(start != std::string_view::npos, "a diagnostic's line is in the text", d.ToString());
      ++start;
    }
    const std::size_t end = std::min(text.find('\n', start), text.size());
    Check(static_cast<std::size_t>(d.col) <= end - start + 1,
          "a diagnostic's column is in its line", d.ToString());
  }
}

/// Bit-for-bit equality of two doubles (a round trip must not change a single bit).
inline bool SameBits(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}

}  // namespace priormap::fuzz
