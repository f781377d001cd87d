// Odometry CSV (docs/formats.md): bicycle controls `time,speed,steer`, each held until the next
// row's time, or SE(2) increments `time,dx,dy,dtheta[,sx,sy,stheta]` since the previous row.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>

#include <fmt/format.h>

#include <priormap/core/check.hpp>
#include <priormap/core/file_io.hpp>
#include <priormap/core/world_bounds.hpp>
#include <priormap/slam/slam_io.hpp>
#include <priormap/slam/vehicle_model.hpp>

#include "csv_table.hpp"

namespace priormap::slam {
namespace {

using detail::CsvRow;
using detail::CsvTable;

constexpr double kPi = std::numbers::pi;
constexpr const char* kExpectedColumns =
    "time,speed,steer (bicycle controls) or time,dx,dy,dtheta[,sx,sy,stheta] (increments)";
constexpr std::array<const char*, 2> kBicycleColumns = {"speed", "steer"};
constexpr std::array<const char*, 6> kIncrementColumns = {"dx", "dy", "dtheta",
                                                          "sx", "sy", "stheta"};

bool IsOneOf(const std::string& name, const auto& names) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

// Column indices; which of speed/dx exist says the kind.
struct Columns {
  std::size_t time = 0;
  bool bicycle = false;
  std::array<std::size_t, 3> control{};               // speed, steer / dx, dy, dtheta
  std::array<std::optional<std::size_t>, 3> sigma{};  // sx, sy, stheta (increments only)
};

Columns FindColumns(const CsvTable& table) {
  const CsvRow& header = table.header();
  std::optional<std::size_t> first_bicycle;
  std::optional<std::size_t> first_increment;
  for (std::size_t i = 0; i < header.cells.size(); ++i) {
    const std::string& name = header.cells[i].text;
    const bool bicycle = IsOneOf(name, kBicycleColumns);
    const bool increment = IsOneOf(name, kIncrementColumns);
    if (!bicycle && !increment && name != "time") {
      table.Fail(header.line, header.cells[i].col,
                 fmt::format("unknown column {}; odometry has the columns {}",
                             QuoteForMessage(name), kExpectedColumns));
    }
    if (bicycle && !first_bicycle) first_bicycle = i;
    if (increment && !first_increment) first_increment = i;
    if ((bicycle && first_increment) || (increment && first_bicycle)) {
      table.Fail(header.line, header.cells[i].col,
                 fmt::format("column {} cannot be mixed with {}: odometry has the columns {}",
                             QuoteForMessage(name),
                             QuoteForMessage(
                                 header.cells[bicycle ? *first_increment : *first_bicycle].text),
                             kExpectedColumns));
    }
  }
  if (!first_bicycle && !first_increment) {
    table.Fail(header.line, 1,
               fmt::format("the header '{}' names neither bicycle controls nor increments; "
                           "odometry has the columns {}",
                           table.HeaderText(), kExpectedColumns));
  }
  Columns columns;
  columns.bicycle = first_bicycle.has_value();
  const auto required = [&](const char* name) {
    if (const std::optional<std::size_t> index = table.Find(name)) return *index;
    table.Fail(header.line, 1,
               fmt::format("missing column '{}' in the header '{}'; {} need the columns {}", name,
                           table.HeaderText(), columns.bicycle ? "bicycle controls" : "increments",
                           columns.bicycle ? "time,speed,steer" : "time,dx,dy,dtheta"));
  };
  columns.time = required("time");
  if (columns.bicycle) {
    columns.control = {required("speed"), required("steer"), 0};
  } else {
    columns.control = {required("dx"), required("dy"), required("dtheta")};
    columns.sigma = {table.Find("sx"), table.Find("sy"), table.Find("stheta")};
  }
  return columns;
}

// The time of `row`, after the previous row's (`previous`, on `previous_line`).
double RowTime(const CsvTable& table, const CsvRow& row, std::size_t column,
               std::optional<double> previous, int previous_line) {
  const double time = table.FiniteNumber(row, column);
  if (previous && !(time > *previous)) {
    table.Fail(
        row, column,
        fmt::format("time must increase strictly: {} is not after {} (line {})",
                    detail::FormatNumber(time), detail::FormatNumber(*previous), previous_line));
  }
  if (previous && !std::isfinite(time - *previous)) {
    table.Fail(
        row, column,
        fmt::format("the step from time {} (line {}) to {} is too long to represent",
                    detail::FormatNumber(*previous), previous_line, detail::FormatNumber(time)));
  }
  return time;
}

Se2 Increment(const CsvTable& table, const CsvRow& row, const Columns& columns, bool first) {
  const double dx = table.FiniteNumber(row, columns.control[0]);
  const double dy = table.FiniteNumber(row, columns.control[1]);
  const double dtheta = table.FiniteNumber(row, columns.control[2]);
  if (first) {
    for (int i = 0; i < 3; ++i) {
      if (std::array{dx, dy, dtheta}[i] != 0.0) {
        table.Fail(row, columns.control[i],
                   fmt::format("the first row marks the start and its increment must be 0, "
                               "found {}",
                               QuoteForMessage(row.cells[columns.control[i]].text)));
      }
    }
  }
  // A step longer than the world is wide is an error in the file; the poses after it would lie
  // beyond any world the other readers accept.
  for (int i = 0; i < 2; ++i) {
    if (!IsWithinWorld(std::array{dx, dy}[i])) {
      table.Fail(row, columns.control[i],
                 fmt::format("{} must be at most {:.0e} m in magnitude (the bound of world "
                             "coordinates), found {}",
                             i == 0 ? "dx" : "dy", kMaxWorldCoordinate,
                             QuoteForMessage(row.cells[columns.control[i]].text)));
    }
  }
  if (!(-kPi <= dtheta && dtheta <= kPi)) {
    table.Fail(row, columns.control[2],
               fmt::format("dtheta must be in [-pi, pi] rad, found {} (degrees?)",
                           QuoteForMessage(row.cells[columns.control[2]].text)));
  }
  return {dx, dy, dtheta};
}

// A row's bicycle controls. As every value read, each is bounded: a speed above the world's
// bound per second (1e9 m/s, three times the speed of light) and a steering angle outside
// [-pi, pi] are errors in the file, most likely of units, as is a dtheta outside [-pi, pi].
BicycleControl Control(const CsvTable& table, const CsvRow& row, const Columns& columns) {
  const double speed = table.FiniteNumber(row, columns.control[0]);
  const double steer = table.FiniteNumber(row, columns.control[1]);
  if (!IsWithinWorld(speed)) {
    table.Fail(
        row, columns.control[0],
        fmt::format("speed must be at most {:.0e} m/s in magnitude (the bound of world "
                    "coordinates, per second), found {}",
                    kMaxWorldCoordinate, QuoteForMessage(row.cells[columns.control[0]].text)));
  }
  if (!(-kPi <= steer && steer <= kPi)) {
    table.Fail(row, columns.control[1],
               fmt::format("steer must be in [-pi, pi] rad, found {} (degrees?)",
                           QuoteForMessage(row.cells[columns.control[1]].text)));
  }
  return {speed, steer};
}

// The distance a speed held over dt covers, |speed| dt, within the world's bound as an
// increment's dx and dy are: a longer step would put the poses after it beyond any world the
// other readers accept (and 1e9 m/s held for 1e300 s is not even finite).
bool IsStepWithinWorld(double speed, double dt) {
  return std::abs(speed) * dt <= kMaxWorldCoordinate;
}

// The increment's 1-sigma errors; NaN where the column or the cell is empty.
Vec3 IncrementStd(const CsvTable& table, const CsvRow& row, const Columns& columns) {
  Vec3 sigma = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
  for (int i = 0; i < 3; ++i) {
    if (!columns.sigma[i]) continue;
    if (const std::optional<double> value = table.OptionalFiniteNumber(row, *columns.sigma[i])) {
      if (!(*value >= 0.0)) {
        table.Fail(row, *columns.sigma[i],
                   fmt::format("a standard deviation must be >= 0, found {}",
                               QuoteForMessage(row.cells[*columns.sigma[i]].text)));
      }
      sigma[i] = *value;
    }
  }
  return sigma;
}

Odometry ReadOdometry(const CsvTable& table) {
  const Columns columns = FindColumns(table);
  const std::vector<CsvRow>& rows = table.rows();
  Odometry odometry;
  std::optional<double> previous;
  int previous_line = 0;
  std::optional<BicycleControl> held;  // the previous row's controls
  int held_col = 0;                    // and the column of its speed
  for (const CsvRow& row : rows) {
    const double time = RowTime(table, row, columns.time, previous, previous_line);
    if (columns.bicycle) {
      const BicycleControl control = Control(table, row, columns);
      if (held) {
        const double dt = time - *previous;
        if (!IsStepWithinWorld(held->speed, dt)) {
          table.Fail(previous_line, held_col,
                     fmt::format("speed {} m/s held from t = {} to t = {} (line {}) covers {} m "
                                 "in one step, more than {:.0e} m (the bound of world "
                                 "coordinates)",
                                 detail::FormatNumber(held->speed), detail::FormatNumber(*previous),
                                 detail::FormatNumber(time), row.line, std::abs(held->speed) * dt,
                                 kMaxWorldCoordinate));
        }
        MotionStep& step = odometry.steps.emplace_back(MotionStep{time, dt, *held});
        step.line = previous_line;
        step.col = held_col;
      }
      held = control;
      held_col = row.cells[columns.control[0]].col;
    } else {
      const Se2 increment = Increment(table, row, columns, !previous.has_value());
      const Vec3 sigma = IncrementStd(table, row, columns);
      if (previous) {
        MotionStep& step =
            odometry.steps.emplace_back(MotionStep{time, time - *previous, increment, sigma});
        step.line = row.line;
        step.col = row.cells[columns.control[0]].col;
      }
    }
    if (!previous) odometry.start_time = time;
    previous = time;
    previous_line = row.line;
  }
  if (rows.size() < 2) {
    table.Fail(rows.empty() ? table.header().line : rows.back().line, 1,
               fmt::format("odometry needs at least two rows (the start and the end of a step), "
                           "found {}",
                           rows.size()));
  }
  return odometry;
}

// What ReadOdometry would reject, or could not give back (a bug of the caller).
void CheckWritable(const Odometry& odometry) {
  PRIORMAP_CHECK(!odometry.steps.empty(), "odometry without steps cannot be written");
  PRIORMAP_CHECK(std::isfinite(odometry.start_time), "start time must be finite");
  const std::size_t kind = odometry.steps.front().motion.index();
  double previous = odometry.start_time;
  for (const MotionStep& step : odometry.steps) {
    PRIORMAP_CHECK(step.motion.index() == kind, "bicycle steps and increments cannot be mixed");
    PRIORMAP_CHECK(std::isfinite(step.time) && step.time > previous,
                   fmt::format("step times must increase: {} after {}", step.time, previous));
    // Only times are written: dt must be what reading gives back.
    PRIORMAP_CHECK(std::abs(step.time - previous - step.dt) <=
                       1e-9 * std::max({1.0, std::abs(step.time), std::abs(previous)}),
                   fmt::format("steps must be contiguous: the step ending at {} has dt {}, but "
                               "the previous one ended at {}",
                               step.time, step.dt, previous));
    if (const auto* control = std::get_if<BicycleControl>(&step.motion)) {
      // As the reader, with the dt it reads back (the difference of the written times).
      PRIORMAP_CHECK(IsWithinWorld(control->speed) && -kPi <= control->steer &&
                         control->steer <= kPi &&
                         IsStepWithinWorld(control->speed, step.time - previous),
                     fmt::format("bicycle controls must be finite, |speed| at most {:.0e} m/s "
                                 "and {:.0e} m per step, steer in [-pi, pi]: speed {}, steer {}, "
                                 "dt {}",
                                 kMaxWorldCoordinate, kMaxWorldCoordinate, control->speed,
                                 control->steer, step.time - previous));
    } else {
      const Se2& increment = std::get<Se2>(step.motion);
      PRIORMAP_CHECK(IsWithinWorld(increment.x()) && IsWithinWorld(increment.y()) &&
                         std::isfinite(increment.theta()),
                     "increments must be finite and within the world's bound");
      for (int i = 0; i < 3; ++i) {
        PRIORMAP_CHECK(std::isnan(step.increment_std[i]) ||
                           (std::isfinite(step.increment_std[i]) && step.increment_std[i] >= 0.0),
                       fmt::format("increment standard deviation {}", step.increment_std[i]));
      }
    }
    previous = step.time;
  }
}

std::string OptionalNumber(double value) {
  return std::isnan(value) ? std::string() : detail::FormatNumber(value);
}

}  // namespace

Result<Odometry> ParseOdometryCsv(std::string_view text, const std::string& name) {
  return detail::CatchCsvError<Odometry>([&] { return ReadOdometry(CsvTable::Parse(text, name)); });
}

std::string FormatOdometryCsv(const Odometry& odometry) {
  CheckWritable(odometry);
  const std::vector<MotionStep>& steps = odometry.steps;
  const std::string start = detail::FormatNumber(odometry.start_time);
  std::string out;
  if (std::holds_alternative<BicycleControl>(steps.front().motion)) {
    // Row k holds the controls of step k from its start; the last row only ends the last step
    // (its controls, the last step's repeated, are not used).
    const auto row = [&](const std::string& time, const MotionStep& step) {
      const auto& control = std::get<BicycleControl>(step.motion);
      out += fmt::format("{},{},{}\n", time, detail::FormatNumber(control.speed),
                         detail::FormatNumber(control.steer));
    };
    out += "time,speed,steer\n";
    row(start, steps.front());
    for (std::size_t k = 0; k < steps.size(); ++k)
      row(detail::FormatNumber(steps[k].time), steps[std::min(k + 1, steps.size() - 1)]);
    return out;
  }
  const bool with_std = std::any_of(steps.begin(), steps.end(), [](const MotionStep& step) {
    return !step.increment_std.array().isNaN().all();
  });
  out += with_std ? "time,dx,dy,dtheta,sx,sy,stheta\n" : "time,dx,dy,dtheta\n";
  out += start + (with_std ? ",0,0,0,,,\n" : ",0,0,0\n");
  for (const MotionStep& step : steps) {
    const Se2& increment = std::get<Se2>(step.motion);
    out += fmt::format("{},{},{},{}", detail::FormatNumber(step.time),
                       detail::FormatNumber(increment.x()), detail::FormatNumber(increment.y()),
                       detail::FormatNumber(increment.theta()));
    if (with_std) {
      out += fmt::format(",{},{},{}", OptionalNumber(step.increment_std.x()),
                         OptionalNumber(step.increment_std.y()),
                         OptionalNumber(step.increment_std.z()));
    }
    out += '\n';
  }
  return out;
}

std::optional<Diagnostic> FirstPoseBeyondWorld(const Se2& initial_pose, const Odometry& odometry,
                                               double wheelbase, const std::string& name) {
  Se2 pose = initial_pose;
  for (const MotionStep& step : odometry.steps) {
    const Se2 start = pose;
    if (const auto* control = std::get_if<BicycleControl>(&step.motion)) {
      pose = BicycleMotion(pose, *control, step.dt, wheelbase);
    } else {
      pose = IncrementMotion(pose, std::get<Se2>(step.motion));
    }
    if (!pose.vector().allFinite()) return std::nullopt;  // the filter says so, and why
    if (IsWithinWorld(pose.x()) && IsWithinWorld(pose.y())) continue;
    return Diagnostic{
        .file = name,
        .line = step.line,
        .col = step.col,
        .message = fmt::format(
            "this row's motion takes the pose from ({}, {}) to ({}, {}) m at t = {} s, beyond "
            "{:.0e} m in x or y (the bound of world coordinates): the odometry dead-reckoned "
            "from the initial pose ({}, {}) leaves the world",
            start.x(), start.y(), pose.x(), pose.y(), detail::FormatNumber(step.time),
            kMaxWorldCoordinate, initial_pose.x(), initial_pose.y())};
  }
  return std::nullopt;
}

Result<Odometry> ReadOdometryCsv(const std::filesystem::path& path) {
  Result<std::string> text = ReadFileText(path);
  if (!text) return text.diagnostics();
  return ParseOdometryCsv(text.value(), path.string());
}

void WriteOdometryCsv(const Odometry& odometry, const std::filesystem::path& path) {
  WriteTextFileAtomically(path, FormatOdometryCsv(odometry));
}

}  // namespace priormap::slam
