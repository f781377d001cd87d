#include "testing/diagnostic_matchers.hpp"

#include <cstddef>

namespace priormap {

void PrintTo(const Diagnostic& d, std::ostream* os) {
  *os << d.ToString();
}

namespace testing {

::testing::Matcher<const Diagnostic&> DiagnosticAt(const std::string& file, int line, int col,
                                                   const std::string& message_part) {
  using ::testing::AllOf;
  using ::testing::Field;
  using ::testing::HasSubstr;
  return AllOf(Field("file", &Diagnostic::file, file), Field("line", &Diagnostic::line, line),
               Field("col", &Diagnostic::col, col),
               Field("message", &Diagnostic::message, HasSubstr(message_part)));
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::size_t start = 0;
  while (start <= text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    lines.push_back(text.substr(start, end - start));
    start = end + 1;
  }
  return lines;
}

}  // namespace testing
}  // namespace priormap
