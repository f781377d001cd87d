#include "csv_table.hpp"

#include <charconv>
#include <cmath>
#include <optional>
#include <string_view>
#include <unordered_map>

#include <fmt/format.h>

#include <priormap/core/file_io.hpp>
#include <priormap/core/utf8.hpp>

namespace priormap::slam::detail {
namespace {

bool IsBlank(char c) {
  return c == ' ' || c == '\t';
}

std::size_t SkipBlanks(std::string_view line, std::size_t pos) {
  while (pos < line.size() && IsBlank(line[pos])) ++pos;
  return pos;
}

// Splits one line at its commas; throws CsvError on a quoted cell that is not closed or is
// followed by more than blanks.
std::vector<CsvCell> SplitCells(std::string_view line, int line_number, const std::string& name) {
  std::vector<CsvCell> cells;
  ColumnCounter columns(line);
  std::size_t pos = 0;
  for (;;) {
    pos = SkipBlanks(line, pos);
    CsvCell cell;
    cell.col = columns.At(pos);
    if (pos < line.size() && line[pos] == '"') {
      bool closed = false;
      for (++pos; pos < line.size(); ++pos) {
        if (line[pos] != '"') {
          cell.text += line[pos];
        } else if (pos + 1 < line.size() && line[pos + 1] == '"') {
          cell.text += '"';
          ++pos;
        } else {
          closed = true;
          ++pos;
          break;
        }
      }
      if (!closed) {
        throw CsvError{{name, line_number, cell.col,
                        "unterminated quoted cell (the quote opened here is not closed on this "
                        "line; cells cannot span lines)"}};
      }
      pos = SkipBlanks(line, pos);
      if (pos < line.size() && line[pos] != ',') {
        const std::optional<Utf8Char> found = DecodeUtf8(line, pos);  // the whole character
        throw CsvError{{name, line_number, columns.At(pos),
                        fmt::format("expected ',' or the end of the line after a quoted cell, "
                                    "found {}",
                                    QuoteForMessage(line.substr(pos, found ? found->length : 1)))}};
      }
    } else {
      std::size_t end = line.find(',', pos);
      if (end == std::string_view::npos) end = line.size();
      std::size_t last = end;
      while (last > pos && IsBlank(line[last - 1])) --last;
      cell.text = line.substr(pos, last - pos);
      pos = end;
    }
    cells.push_back(std::move(cell));
    if (pos >= line.size()) return cells;
    ++pos;  // the comma
  }
}

bool IsSkipped(std::string_view line) {
  const std::size_t first = SkipBlanks(line, 0);
  return first == line.size() || line[first] == '#';
}

std::string JoinTexts(const std::vector<CsvCell>& cells) {
  std::string out;
  for (const CsvCell& cell : cells) {
    if (!out.empty()) out += ',';
    out += cell.text;
  }
  return out;
}

}  // namespace

CsvTable CsvTable::Parse(std::string_view text, std::string name) {
  if (text.starts_with(kUtf8ByteOrderMark)) text.remove_prefix(kUtf8ByteOrderMark.size());

  std::optional<CsvRow> header;
  std::vector<CsvRow> rows;
  int line_number = 0;
  int last_line_number = 1;
  for (std::size_t start = 0; start <= text.size();) {
    std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(start, end - start);
    if (line.ends_with('\r')) line.remove_suffix(1);
    start = end + 1;
    last_line_number = ++line_number;
    if (IsSkipped(line)) continue;

    CsvRow row{line_number, SplitCells(line, line_number, name)};
    if (!header) {
      // The column of each name so far, by name: a header of many columns is checked in one pass.
      std::unordered_map<std::string_view, int> named;
      for (const CsvCell& cell : row.cells) {
        if (cell.text.empty())
          throw CsvError{{name, line_number, cell.col, "empty column name in the header"}};
        if (const auto [first, added] = named.emplace(cell.text, cell.col); !added) {
          throw CsvError{{name, line_number, cell.col,
                          fmt::format("column {} appears twice in the header (also at column {})",
                                      QuoteForMessage(cell.text), first->second)}};
        }
      }
      header = std::move(row);
      continue;
    }
    const std::size_t expected = header->cells.size();
    if (row.cells.size() != expected) {
      const int col = row.cells.size() > expected ? row.cells[expected].col
                                                  : CharacterColumn(line, line.size());
      throw CsvError{{name, line_number, col,
                      fmt::format("expected {} cells as in the header ({}), found {}", expected,
                                  JoinTexts(header->cells), row.cells.size())}};
    }
    rows.push_back(std::move(row));
  }
  if (!header) {
    throw CsvError{{name, last_line_number, 1,
                    "no header row (the first line that is neither blank nor a '#' comment "
                    "names the columns)"}};
  }
  return CsvTable(std::move(name), std::move(*header), std::move(rows));
}

std::string CsvTable::HeaderText() const {
  return JoinTexts(header_.cells);
}

std::optional<std::size_t> CsvTable::Find(std::string_view column) const {
  for (std::size_t i = 0; i < header_.cells.size(); ++i) {
    if (header_.cells[i].text == column) return i;
  }
  return std::nullopt;
}

void CsvTable::Fail(int line, int col, std::string message) const {
  throw CsvError{{name_, line, col, std::move(message)}};
}

void CsvTable::Fail(const CsvRow& row, std::size_t column, std::string message) const {
  Fail(row.line, row.cells[column].col, std::move(message));
}

std::optional<double> CsvTable::OptionalFiniteNumber(const CsvRow& row, std::size_t column) const {
  const std::string_view cell = row.cells[column].text;
  if (cell.empty()) return std::nullopt;
  // Worded only on failure: a log's every cell passes here.
  const auto fail = [&](std::string_view why) {
    Fail(row, column,
         fmt::format("expected a finite number for column {}, found {}{}",
                     QuoteForMessage(header_.cells[column].text), QuoteForMessage(cell), why));
  };
  std::string_view text = cell;
  // from_chars takes no '+' sign; accept one, but not "+-1".
  if (text.size() > 1 && text[0] == '+' && text[1] != '-' && text[1] != '+') text.remove_prefix(1);
  double value = 0.0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec == std::errc::result_out_of_range && end == text.data() + text.size())
    fail(" (out of the range of double)");
  if (ec != std::errc() || end != text.data() + text.size()) fail("");
  if (std::isnan(value)) fail(" (NaN is not allowed)");
  if (std::isinf(value)) fail(" (infinite values are not allowed)");
  return value;
}

double CsvTable::FiniteNumber(const CsvRow& row, std::size_t column) const {
  if (const std::optional<double> value = OptionalFiniteNumber(row, column)) return *value;
  Fail(row, column,
       fmt::format("expected a finite number for column {}, found an empty cell",
                   QuoteForMessage(header_.cells[column].text)));
}

std::string FormatNumber(double value) {
  return fmt::format("{}", value);
}

}  // namespace priormap::slam::detail
