#pragma once
/// Bad user input (logs, scans, scenes, prior files, options) is reported as a list of
/// Diagnostics returned to the caller; the library never prints. See docs/ARCHITECTURE.md.

#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace priormap {

/// One problem found in user input, located as precisely as the input format allows.
struct Diagnostic {
  std::string file;  ///< path as given by the user ("" when the input is not a file)
  int line = 0;      ///< 1-based; 0 when unknown
  int col = 0;       ///< 1-based; 0 when unknown
  std::string message;

  /// `file:line:col` (parts that are unknown are left out; empty when nothing is known).
  [[nodiscard]] std::string Location() const;
  /// `file:line:col: error: message`.
  [[nodiscard]] std::string ToString() const;
};

/// `text` quoted for an error message: at most `max_length` characters (then "..."). UTF-8
/// characters are shown as themselves ("Zürich" stays as the user wrote it); the bytes of control
/// and invisible format characters, and bytes that are not UTF-8, are shown as \xNN, so that a
/// binary or huge token cannot flood a terminal or hide what it holds. So is a combining mark
/// with no character shown before it to draw on (it would mark the opening quote).
[[nodiscard]] std::string QuoteForMessage(std::string_view text, std::size_t max_length = 40);

/// Joins diagnostics one per line, as the CLI prints them.
[[nodiscard]] std::string FormatDiagnostics(const std::vector<Diagnostic>& diagnostics);

/// A value, or the diagnostics explaining why there is none. A value may come with warnings:
/// problems of the input that did not stop the reading but that its user should know of (a
/// log's scans stamped out of time order), located like the diagnostics, for the caller to show
/// (the library never prints).
template <typename T>
class Result {
 public:
  Result(T value) : value_(std::move(value)) {}  // NOLINT(google-explicit-constructor)
  Result(T value, std::vector<Diagnostic> warnings)
      : value_(std::move(value)), warnings_(std::move(warnings)) {}
  Result(std::vector<Diagnostic> diagnostics) : diagnostics_(std::move(diagnostics)) {}  // NOLINT
  Result(Diagnostic diagnostic) : diagnostics_{std::move(diagnostic)} {}                 // NOLINT

  [[nodiscard]] bool ok() const { return value_.has_value(); }
  explicit operator bool() const { return ok(); }

  /// The value; calling this on a failed result is a contract violation.
  [[nodiscard]] T& value() & {
    Checked();
    return *value_;
  }
  [[nodiscard]] const T& value() const& {
    Checked();
    return *value_;
  }
  /// By value from a temporary, so that `const T& v = Read(...).value();` does not dangle.
  [[nodiscard]] T value() && {
    Checked();
    return std::move(*value_);
  }

  [[nodiscard]] const std::vector<Diagnostic>& diagnostics() const { return diagnostics_; }
  /// All diagnostics formatted one per line.
  [[nodiscard]] std::string error() const { return FormatDiagnostics(diagnostics_); }
  /// The warnings of a value (none when there is no value).
  [[nodiscard]] const std::vector<Diagnostic>& warnings() const { return warnings_; }

 private:
  void Checked() const;

  std::optional<T> value_;
  std::vector<Diagnostic> diagnostics_;
  std::vector<Diagnostic> warnings_;
};

namespace detail {
[[noreturn]] void FailResultAccess(const std::string& error);
}  // namespace detail

template <typename T>
void Result<T>::Checked() const {
  if (!value_) detail::FailResultAccess(error());
}

}  // namespace priormap
