#pragma once
// The comma-separated tables of `priormap slam run` (docs/formats.md): a header row of column
// names, then one row per record. '#' comment lines and blank lines are skipped, cells may be
// surrounded by blanks and may be quoted ("a ""b"""), a UTF-8 byte order mark is ignored.
// Every cell keeps its line and column, so that a reader can report a problem exactly there.

#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <priormap/core/diagnostic.hpp>

namespace priormap::slam::detail {

struct CsvCell {
  std::string text;  ///< without surrounding blanks and quotes
  int col = 1;       ///< 1-based byte column of its first character (of the separator's
                     ///< successor when the cell is empty)
};

struct CsvRow {
  int line = 0;  ///< 1-based
  std::vector<CsvCell> cells;
};

/// The first problem found; thrown by the table's helpers and turned into the reader's
/// Result by CatchCsvError.
struct CsvError {
  Diagnostic diagnostic;
};

class CsvTable {
 public:
  /// Splits `text` into the header and the rows; throws CsvError when there is no header, a
  /// quoted cell is not terminated, a column name is empty or repeated, or a row has another
  /// number of cells than the header.
  static CsvTable Parse(std::string_view text, std::string name);

  [[nodiscard]] const std::string& name() const { return name_; }
  [[nodiscard]] const CsvRow& header() const { return header_; }
  [[nodiscard]] const std::vector<CsvRow>& rows() const { return rows_; }
  /// The header as written by the user, "time,id,range,bearing".
  [[nodiscard]] std::string HeaderText() const;
  /// The index of the column named `column`, if there is one.
  [[nodiscard]] std::optional<std::size_t> Find(std::string_view column) const;

  [[noreturn]] void Fail(int line, int col, std::string message) const;
  [[noreturn]] void Fail(const CsvRow& row, std::size_t column, std::string message) const;

  /// The finite number in cell `column` of `row`. Errors name the column and quote the cell:
  /// `expected a finite number for column 'range', found 'abc'`; NaN, infinities and numbers
  /// beyond the range of double are rejected explicitly.
  [[nodiscard]] double FiniteNumber(const CsvRow& row, std::size_t column) const;
  /// As FiniteNumber, but an empty cell is no value.
  [[nodiscard]] std::optional<double> OptionalFiniteNumber(const CsvRow& row,
                                                           std::size_t column) const;

 private:
  CsvTable(std::string name, CsvRow header, std::vector<CsvRow> rows)
      : name_(std::move(name)), header_(std::move(header)), rows_(std::move(rows)) {}

  std::string name_;
  CsvRow header_;
  std::vector<CsvRow> rows_;
};

/// `read()`, or the diagnostic of the CsvError it throws.
template <typename T, typename Read>
Result<T> CatchCsvError(Read&& read) {
  try {
    return read();
  } catch (const CsvError& error) {
    return error.diagnostic;
  }
}

/// Number formatting that reads back to the same double ("0.1", "1e+300", "-0").
[[nodiscard]] std::string FormatNumber(double value);

}  // namespace priormap::slam::detail
