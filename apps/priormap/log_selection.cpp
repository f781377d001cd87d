#include "log_selection.hpp"

#include <charconv>

#include <fmt/format.h>

#include <priormap/core/log_io.hpp>

#include "cli_support.hpp"

namespace priormap::app {
namespace {

std::optional<std::size_t> ParseIndex(std::string_view text, const std::string& whole) {
  if (text.empty()) return std::nullopt;
  std::size_t value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size())
    throw UserError(fmt::format("--range: '{}' is not a:b with scan indices a < b", whole));
  return value;
}

}  // namespace

ScanRange ParseScanRange(const std::string& text) {
  const auto colon = text.find(':');
  if (colon == std::string::npos)
    throw UserError(fmt::format("--range: '{}' is not a:b with scan indices a < b", text));
  const std::string_view view(text);
  ScanRange range;
  range.first = ParseIndex(view.substr(0, colon), text).value_or(0);
  range.end = ParseIndex(view.substr(colon + 1), text);
  if (range.end && *range.end <= range.first)
    throw UserError(fmt::format("--range: '{}' is empty (a must be below b)", text));
  return range;
}

Log ReadLogOrThrow(const std::string& path) {
  return ValueOrThrow(ReadLog(path));
}

}  // namespace priormap::app
