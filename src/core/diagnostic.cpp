#include <cstdint>
#include <optional>

#include <fmt/format.h>

#include <priormap/core/check.hpp>
#include <priormap/core/diagnostic.hpp>
#include <priormap/core/utf8.hpp>

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

namespace {

// Whether a character is shown as itself in a message: not a control (C0, DEL, C1), nor one that
// shows as a plain blank or as nothing (a no-break space after a column's name would otherwise
// read as an ASCII space, a zero-width one not at all), nor a line or paragraph separator.
bool ShownAsItself(std::uint32_t code) {
  if (code < 0x20 || (code >= 0x7f && code < 0xa0)) return false;
  return !IsNonAsciiSpace(code) && !IsInvisibleCharacter(code) && code != 0x2028 && code != 0x2029;
}

}  // namespace

std::string QuoteForMessage(std::string_view text, std::size_t max_length) {
  std::string out = "'";
  std::size_t shown = 0;
  // A combining mark draws on the character before it: shown after the opening quote or after
  // an escape, it would read as part of either (an accent on the "'"), so it is escaped there.
  bool previous_as_itself = false;
  for (std::size_t at = 0; at < text.size(); ++shown) {
    if (shown == max_length) {
      out += "...";
      break;
    }
    const std::optional<Utf8Char> c = DecodeUtf8(text, at);
    const std::size_t length = c ? c->length : 1;
    const bool as_itself =
        c && ShownAsItself(c->code) && (previous_as_itself || !IsCombiningMark(c->code));
    previous_as_itself = as_itself;
    if (as_itself) {
      out += text.substr(at, length);
    } else {
      for (std::size_t k = at; k < at + length; ++k)
        out += fmt::format("\\x{:02x}", static_cast<unsigned char>(text[k]));
    }
    at += length;
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
