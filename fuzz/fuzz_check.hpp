#pragma once
// What the harnesses check besides "no crash, no sanitizer report": a failed check prints what
// went wrong and aborts, which libFuzzer records as a crash with the input that caused it.

#include <cstdio>
#include <cstdlib>
#include <string_view>

namespace priormap::fuzz {

inline void Check(bool ok, const char* what, std::string_view detail = {}) {
  if (ok) return;
  std::fprintf(stderr, "fuzz check failed: %s\n%.*s\n", what, static_cast<int>(detail.size()),
               detail.data());
  std::abort();
}

}  // namespace priormap::fuzz
