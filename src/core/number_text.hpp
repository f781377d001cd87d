#pragma once
// Numbers in text logs, parsed whole: std::from_chars's grammar and values, with a fast path
// for the plain decimals that make up almost every log (a third of a CARMEN log's reading time
// went to from_chars).

#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string_view>

namespace priormap::detail {

/// The double that `text` spells, all of it, or nullopt: from_chars's general format plus an
/// optional '+' sign (but not "+-1"); "nan" and "-nan" give the one quiet NaN.
[[nodiscard]] inline std::optional<double> ParseDouble(std::string_view text) {
  // Clinger's fast path: for -?d+(.d+)? with at most 19 digits, a value below 2^53 and at most
  // 22 decimals, the digits as an integer and 10^decimals are exact doubles, and their
  // correctly rounded quotient is the correctly rounded value of the text, which is what
  // from_chars returns.
  static constexpr std::array<double, 23> kPowersOfTen = {
      1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
      1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
  const char* p = text.data();
  const char* const end = p + text.size();
  const bool negative = p != end && *p == '-';
  p += negative ? 1 : 0;
  std::uint64_t digits = 0;
  const char* const integer = p;
  while (p != end && static_cast<unsigned char>(*p - '0') < 10) digits = 10 * digits + (*p++ - '0');
  const auto integer_digits = p - integer;
  std::ptrdiff_t decimals = 0;
  bool decimals_ok = true;
  if (p != end && *p == '.') {
    const char* const fraction = ++p;
    while (p != end && static_cast<unsigned char>(*p - '0') < 10)
      digits = 10 * digits + (*p++ - '0');
    decimals = p - fraction;
    decimals_ok = decimals > 0 && decimals < static_cast<std::ptrdiff_t>(kPowersOfTen.size());
  }
  if (p == end && integer_digits > 0 && decimals_ok && integer_digits + decimals <= 19 &&
      digits <= (std::uint64_t{1} << 53)) {
    const double value =
        static_cast<double>(digits) / kPowersOfTen[static_cast<std::size_t>(decimals)];
    return negative ? -value : value;
  }
  // Everything else: from_chars, which takes no '+' sign; one is accepted, but not "+-1".
  if (text.size() > 1 && text.front() == '+' && text[1] != '-' && text[1] != '+')
    text.remove_prefix(1);
  double value = 0.0;
  const auto [last, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || last != text.data() + text.size()) return std::nullopt;
  // "-nan" and "nan" mean the same missing value; one NaN keeps a round trip through formats
  // without a sign for NaN (JSON's null) the same.
  if (std::isnan(value)) return std::numeric_limits<double>::quiet_NaN();
  return value;
}

/// The integer that `text` spells, all of it, or nullopt (from_chars's grammar: no '+').
[[nodiscard]] inline std::optional<long long> ParseInteger(std::string_view text) {
  long long value = 0;
  const auto [last, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || last != text.data() + text.size()) return std::nullopt;
  return value;
}

}  // namespace priormap::detail
