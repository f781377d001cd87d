#pragma once
// gMock vocabulary for Diagnostics: readable failure messages, a matcher for where a diagnostic
// points and what it says, and the lines of a text its positions count in.

#include <ostream>
#include <string>
#include <vector>

#include <gmock/gmock.h>

#include <priormap/core/diagnostic.hpp>

namespace priormap {

/// Diagnostics print as `file:line:col: error: message` in failure messages (found by ADL).
void PrintTo(const Diagnostic& d, std::ostream* os);

namespace testing {

/// A diagnostic of `file` at `line` and `col` whose message contains `message_part`.
::testing::Matcher<const Diagnostic&> DiagnosticAt(const std::string& file, int line, int col,
                                                   const std::string& message_part);

/// `text` split at each '\n' (the newline not included): line n of a diagnostic is element n - 1.
/// A text ending in '\n' gives a last, empty line; an empty text gives one empty line.
std::vector<std::string> Lines(const std::string& text);

}  // namespace testing
}  // namespace priormap
