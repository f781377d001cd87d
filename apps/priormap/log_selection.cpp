#include "log_selection.hpp"

#include <algorithm>
#include <charconv>
#include <string>

#include <fmt/format.h>

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

std::pair<std::size_t, std::size_t> SelectedScans(const ScanRange& range, std::size_t scans) {
  if (scans == 0) throw UserError("the log has no scans");
  // Scans past the log's end would silently be fewer than asked for.
  if (range.end && *range.end > scans)
    throw UserError(fmt::format("--range {}:{}: the log has only {} (scans 0 to {})", range.first,
                                *range.end, Plural(scans, "scan"), scans - 1));
  const std::size_t end = range.end.value_or(scans);
  if (range.first >= end)
    throw UserError(fmt::format("--range {}:{} selects no scan (the log has {})", range.first,
                                range.end ? std::to_string(*range.end) : "", scans));
  return {range.first, end};
}

}  // namespace priormap::app
