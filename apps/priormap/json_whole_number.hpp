#pragma once
// Whole numbers read from JSON files a user can edit (run.json, summary.json), checked:
// nlohmann's get<int>() of 1e300 is undefined behaviour, and of -1.5 a silent truncation.
#include <cstdint>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

namespace priormap::app {

/// What a JSON value that should be a whole number is not; the reader adds the file.
class JsonNumberError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The value as an Int, if it is a whole number (in JSON's integer form) that Int holds.
template <class Int>
[[nodiscard]] std::optional<Int> WholeNumberOf(const nlohmann::json& value) {
  if (value.is_number_unsigned()) {
    if (const auto u = value.get<std::uint64_t>(); std::in_range<Int>(u))
      return static_cast<Int>(u);
  } else if (value.is_number_integer()) {
    if (const auto i = value.get<std::int64_t>(); std::in_range<Int>(i)) return static_cast<Int>(i);
  }
  return std::nullopt;
}

/// object[key] as an Int, or `fallback` when the key is absent (an error when there is none).
template <class Int>
[[nodiscard]] Int WholeNumberMember(const nlohmann::json& object, const std::string& key,
                                    std::optional<Int> fallback = std::nullopt) {
  if (!object.contains(key)) {
    if (fallback) return *fallback;
    throw JsonNumberError(fmt::format("expected the member \"{}\"", key));
  }
  const nlohmann::json& value = object.at(key);
  if (const std::optional<Int> number = WholeNumberOf<Int>(value)) return *number;
  throw JsonNumberError(fmt::format("\"{}\" must be a whole number from {} to {}, got {}", key,
                                    std::numeric_limits<Int>::min(),
                                    std::numeric_limits<Int>::max(), value.dump()));
}

}  // namespace priormap::app
