// Observations CSV (docs/formats.md): `time,id,range,bearing`, one range-bearing measurement per
// row; consecutive rows with the same time form one frame; `time,,,` is a frame without any.
#include <charconv>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <unordered_map>

#include <fmt/format.h>

#include <priormap/core/check.hpp>
#include <priormap/core/file_io.hpp>
#include <priormap/core/world_bounds.hpp>
#include <priormap/slam/slam_io.hpp>

#include "csv_table.hpp"

namespace priormap::slam {
namespace {

using detail::CsvRow;
using detail::CsvTable;

constexpr long long kMaxId = std::numeric_limits<int>::max();
constexpr double kPi = std::numbers::pi;

struct Columns {
  std::size_t time = 0;
  std::optional<std::size_t> id;  // no id column: every id is unknown
  std::size_t range = 0;
  std::size_t bearing = 0;
};

Columns FindColumns(const CsvTable& table) {
  const CsvRow& header = table.header();
  for (const detail::CsvCell& cell : header.cells) {
    if (cell.text != "time" && cell.text != "id" && cell.text != "range" &&
        cell.text != "bearing") {
      table.Fail(header.line, cell.col,
                 fmt::format("unknown column {}; observations have the columns "
                             "time,id,range,bearing (id optional)",
                             QuoteForMessage(cell.text)));
    }
  }
  const auto required = [&](const char* name) {
    if (const std::optional<std::size_t> index = table.Find(name)) return *index;
    table.Fail(header.line, 1,
               fmt::format("missing column '{}' in the header '{}'; observations have the "
                           "columns time,id,range,bearing (id optional)",
                           name, table.HeaderText()));
  };
  return {required("time"), table.Find("id"), required("range"), required("bearing")};
}

// -1 for an unknown landmark (an empty cell or -1), else an id in [0, kMaxId].
int LandmarkId(const CsvTable& table, const CsvRow& row, std::size_t column) {
  std::string_view text = row.cells[column].text;
  if (text.empty()) return -1;
  if (text.size() > 1 && text[0] == '+' && text[1] != '-' && text[1] != '+') text.remove_prefix(1);
  long long id = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), id);
  if (ec == std::errc() && end == text.data() + text.size() &&
      (id == -1 || (0 <= id && id <= kMaxId)))
    return static_cast<int>(id);
  table.Fail(row, column,
             fmt::format("expected a landmark id for column 'id' (an integer in [0, {}], or -1 or "
                         "an empty cell for an unknown landmark), found {}",
                         kMaxId, QuoteForMessage(row.cells[column].text)));
}

// A row with empty range and bearing cells stands for a frame without observations (the vehicle
// saw nothing at that time); it has no landmark id either.
bool IsFrameWithoutObservations(const CsvTable& table, const CsvRow& row, const Columns& columns) {
  if (!row.cells[columns.range].text.empty() || !row.cells[columns.bearing].text.empty())
    return false;
  if (columns.id) {
    const std::string& id = row.cells[*columns.id].text;
    if (!id.empty() && id != "-1") {
      table.Fail(row, *columns.id,
                 fmt::format("a row without range and bearing stands for a frame without "
                             "observations and has no landmark id, found {}",
                             QuoteForMessage(id)));
    }
  }
  return true;
}

// Where the first row of each kind of id (known, unknown) is, to report a file that mixes them.
struct IdKinds {
  int first_known_line = 0;
  int first_unknown_line = 0;
};

void CheckIdKind(const CsvTable& table, const CsvRow& row, std::size_t column, int id,
                 IdKinds& kinds) {
  if (id >= 0) {
    if (kinds.first_unknown_line > 0) {
      table.Fail(row, column,
                 fmt::format("landmark id {} is known, but line {} has an unknown id; the ids of "
                             "a file must be all known or all unknown (-1 or empty)",
                             id, kinds.first_unknown_line));
    }
    if (kinds.first_known_line == 0) kinds.first_known_line = row.line;
  } else {
    if (kinds.first_known_line > 0) {
      table.Fail(row, column,
                 fmt::format("the landmark id is unknown ({}), but line {} has a known id; the "
                             "ids of a file must be all known or all unknown (-1 or empty)",
                             QuoteForMessage(row.cells[column].text), kinds.first_known_line));
    }
    if (kinds.first_unknown_line == 0) kinds.first_unknown_line = row.line;
  }
}

std::vector<ObservationFrame> ReadFrames(const CsvTable& table) {
  const Columns columns = FindColumns(table);
  std::vector<ObservationFrame> frames;
  IdKinds kinds;
  std::unordered_map<int, int> frame_id_lines;  // known id -> its line, in the current frame
  int frame_line = 0;
  for (const CsvRow& row : table.rows()) {
    const double time = table.FiniteNumber(row, columns.time);
    if (!frames.empty() && time < frames.back().time) {
      table.Fail(row, columns.time,
                 fmt::format("time goes backwards: {} is before {} (line {}); rows must be in "
                             "time order",
                             detail::FormatNumber(time), detail::FormatNumber(frames.back().time),
                             frame_line));
    }
    if (frames.empty() || time != frames.back().time) {
      frames.push_back(
          {.time = time, .observations = {}, .line = row.line, .col = row.cells[columns.time].col});
      frame_id_lines.clear();
    }
    frame_line = row.line;
    if (IsFrameWithoutObservations(table, row, columns)) continue;

    RangeBearing observation;
    if (columns.id) {
      observation.id = LandmarkId(table, row, *columns.id);
      CheckIdKind(table, row, *columns.id, observation.id, kinds);
      if (observation.id >= 0) {
        const auto [it, inserted] = frame_id_lines.emplace(observation.id, row.line);
        if (!inserted) {
          table.Fail(row, *columns.id,
                     fmt::format("landmark id {} appears twice in the frame at time {} (lines {} "
                                 "and {})",
                                 observation.id, detail::FormatNumber(frames.back().time),
                                 it->second, row.line));
        }
      }
    }
    observation.range = table.FiniteNumber(row, columns.range);
    if (!(observation.range > 0.0)) {
      table.Fail(row, columns.range,
                 fmt::format("range must be > 0 m, found {}",
                             QuoteForMessage(row.cells[columns.range].text)));
    }
    // As every return priormap reads: a landmark 1e300 m away is an error in the file, and its
    // position (and the map written from it) would lie beyond any world the other readers accept.
    if (!IsReturnWithinWorld(observation.range)) {
      table.Fail(row, columns.range,
                 fmt::format("range must be at most {:.0e} m (the bound of world coordinates), "
                             "found {}",
                             kMaxWorldCoordinate, QuoteForMessage(row.cells[columns.range].text)));
    }
    observation.bearing = table.FiniteNumber(row, columns.bearing);
    if (!(-kPi <= observation.bearing && observation.bearing <= kPi)) {
      table.Fail(row, columns.bearing,
                 fmt::format("bearing must be in [-pi, pi] rad, found {} (degrees?)",
                             QuoteForMessage(row.cells[columns.bearing].text)));
    }
    frames.back().observations.push_back(observation);
  }
  return frames;
}

// What ReadFrames would reject (writing it is a bug of the caller).
void CheckWritable(const std::vector<ObservationFrame>& frames) {
  std::optional<double> previous_time;
  std::optional<bool> known;
  for (const ObservationFrame& frame : frames) {
    PRIORMAP_CHECK(std::isfinite(frame.time), fmt::format("frame time {}", frame.time));
    PRIORMAP_CHECK(!previous_time || frame.time > *previous_time,
                   fmt::format("frame times must increase: {} after {}", frame.time,
                               previous_time.value_or(0.0)));
    previous_time = frame.time;
    std::unordered_map<int, int> seen;
    for (const RangeBearing& o : frame.observations) {
      PRIORMAP_CHECK(o.id >= -1, fmt::format("landmark id {}", o.id));
      PRIORMAP_CHECK(!known || *known == (o.id >= 0), "ids must be all known or all unknown");
      known = o.id >= 0;
      PRIORMAP_CHECK(o.id < 0 || ++seen[o.id] == 1,
                     fmt::format("landmark id {} twice at time {}", o.id, frame.time));
      PRIORMAP_CHECK(o.range > 0.0 && IsReturnWithinWorld(o.range),
                     fmt::format("range {}", o.range));
      PRIORMAP_CHECK(-kPi <= o.bearing && o.bearing <= kPi, fmt::format("bearing {}", o.bearing));
    }
  }
}

}  // namespace

Result<std::vector<ObservationFrame>> ParseObservationsCsv(std::string_view text,
                                                           const std::string& name) {
  return detail::CatchCsvError<std::vector<ObservationFrame>>(
      [&] { return ReadFrames(CsvTable::Parse(text, name)); });
}

std::string FormatObservationsCsv(const std::vector<ObservationFrame>& frames) {
  CheckWritable(frames);
  std::string out = "time,id,range,bearing\n";
  for (const ObservationFrame& frame : frames) {
    const std::string time = detail::FormatNumber(frame.time);
    if (frame.observations.empty()) out += time + ",,,\n";
    for (const RangeBearing& o : frame.observations) {
      out += fmt::format("{},{},{},{}\n", time, o.id, detail::FormatNumber(o.range),
                         detail::FormatNumber(o.bearing));
    }
  }
  return out;
}

Result<std::vector<ObservationFrame>> ReadObservationsCsv(const std::filesystem::path& path) {
  Result<std::string> text = ReadFileText(path);
  if (!text) return text.diagnostics();
  return ParseObservationsCsv(text.value(), path.string());
}

void WriteObservationsCsv(const std::vector<ObservationFrame>& frames,
                          const std::filesystem::path& path) {
  WriteTextFileAtomically(path, FormatObservationsCsv(frames));
}

}  // namespace priormap::slam
