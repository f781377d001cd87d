#include <fmt/format.h>

#include <priormap/core/check.hpp>
#include <priormap/core/diagnostic.hpp>

namespace priormap {

std::string Diagnostic::Location() const {
  std::string where = file;
  if (line > 0) where += fmt::format(":{}", line);
  if (line > 0 && col > 0) where += fmt::format(":{}", col);
  return where;
}

std::string Diagnostic::ToString() const {
  const std::string where = Location();
  if (where.empty()) return fmt::format("error: {}", message);
  return fmt::format("{}: error: {}", where, message);
}

std::string QuoteForMessage(std::string_view text, std::size_t max_length) {
  std::string out = "'";
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (i == max_length) {
      out += "...";
      break;
    }
    const auto c = static_cast<unsigned char>(text[i]);
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      out += fmt::format("\\x{:02x}", c);
    }
  }
  return out + "'";
}

std::string FormatDiagnostics(const std::vector<Diagnostic>& diagnostics) {
  std::string out;
  for (const Diagnostic& d : diagnostics) {
    if (!out.empty()) out += '\n';
    out += d.ToString();
  }
  return out;
}

namespace detail {
void FailResultAccess(const std::string& error) {
  throw ContractError("value() of a failed Result: " + error);
}
}  // namespace detail

}  // namespace priormap
