// priormap grid: the log-odds occupancy grid of a localized log (the baseline the PRF posterior
// is compared with), as PNG and as a ROS map_server PGM + YAML pair.
#include <chrono>
#include <filesystem>
#include <memory>
#include <string>
#include <system_error>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <priormap/core/file_io.hpp>
#include <priormap/core/log_io.hpp>
#include <priormap/grid/occupancy_grid.hpp>
#include <priormap/render/prf_figures.hpp>

#include "cli_support.hpp"
#include "commands.hpp"
#include "log_selection.hpp"
#include "sensor_choice.hpp"
#include "sonar_grid_command.hpp"

namespace priormap::app {
namespace {

struct GridCliOptions {
  std::string log;
  std::string range = ":";
  std::string out;
  std::string sensor = "auto";  // --sensor: auto, laser or sonar
  grid::GridOptions grid;
  bool max_range_given = false;
};

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void RunGridCommand(const GridCliOptions& o) {
  const auto read_start = std::chrono::steady_clock::now();
  const Log log = ValueOrThrow(ReadLog(o.log));
  const double read_time = SecondsSince(read_start);
  const auto [first, end] = SelectedScans(ParseScanRange(o.range), log.scans.size());
  if (ResolveSensor(o.sensor, log, first, end) == Sensor::kSonar) {
    if (o.grid.beam_step != 1)
      throw UserError(
          fmt::format("--beam-step {} is for laser scans: the sonar grid inserts every "
                      "reading of each ring",
                      o.grid.beam_step));
    grid::SonarGridOptions sonar;
    sonar.resolution = o.grid.resolution;
    sonar.max_cells = o.grid.max_cells;
    if (o.max_range_given) sonar.max_range = o.grid.max_range;
    RunSonarGrid(log, o.log, first, end, sonar, o.out, read_time);
    return;
  }
  const Box2 extent = grid::OccupancyGrid::ExtentOf(log, first, end, o.grid);
  if (extent.isEmpty()) throw UserError("the selected scans have no usable reading");
  grid::OccupancyGrid map(extent, o.grid);  // first: a grid too large leaves no directory behind
  EnsureDirectoryWithoutLastFile(o.out, "summary.json");

  const auto insert_start = std::chrono::steady_clock::now();
  std::size_t beams = 0;
  for (std::size_t k = first; k < end; ++k) beams += map.Insert(log.scans[k]);
  const double insert_time = SecondsSince(insert_start);

  const std::filesystem::path dir(o.out);
  const OccupancyRaster raster = map.Raster();
  WriteMapServerMap(dir / "grid.yaml", raster);
  std::vector<Vec2> sensors;
  for (std::size_t k = first; k < end; ++k) sensors.push_back(log.scans[k].pose.translation());
  render::SaveProbabilityFigure(
      dir / "grid.png", raster,
      fmt::format("occupancy grid, {} m, scans {}:{}", o.grid.resolution, first, end), sensors);
  const nlohmann::json summary = {{"log", o.log},
                                  {"scans", end - first},
                                  {"beams", beams},
                                  {"resolution", o.grid.resolution},
                                  {"width", map.width()},
                                  {"height", map.height()},
                                  {"read_time_s", read_time},
                                  {"insert_time_s", insert_time},
                                  {"beams_per_second", static_cast<double>(beams) / insert_time},
                                  {"grid_bytes", std::filesystem::file_size(dir / "grid.pgm")}};
  WriteTextFileAtomically(dir / "summary.json", summary.dump(2) + "\n");
  fmt::print("wrote {} (grid.png, grid.pgm, grid.yaml, summary.json): {} beams, {}x{} cells\n",
             o.out, beams, map.width(), map.height());
}

}  // namespace

void AddGridCommand(CLI::App& app) {
  auto o = std::make_shared<GridCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "grid",
      "Log-odds occupancy grid of a localized laser or sonar log (PNG, map_server PGM + YAML)");
  cmd->add_option("--log", o->log, "Localized log (CARMEN or priormap JSON, .gz or not)")
      ->required();
  cmd->add_option("--range", o->range, "Scans a:b of the log (b exclusive; a: or :b)")
      ->check(ParsedBy("--range", ParseScanRange))
      ->capture_default_str();
  cmd->add_option("-o,--out", o->out, "Output directory")->required();
  cmd->add_option("--resolution", o->grid.resolution, "Cell size, m")
      ->check(PositiveValue())
      ->capture_default_str();
  cmd->add_option("--sensor", o->sensor,
                  "Laser beams or sonar cones (the arc model); auto: sonar when the scans are "
                  "sonar rings")
      ->check(CLI::IsMember({"auto", "laser", "sonar"}))
      ->capture_default_str();
  cmd->add_option("--beam-step", o->grid.beam_step,
                  "Use every k-th beam of each scan (as prf --beam-step, for equal data)")
      ->check(CLI::Range(std::size_t{1}, std::size_t{100000}))
      ->capture_default_str();
  cmd->add_option("--max-range", o->grid.max_range,
                  "Beams are inserted up to this range; max readings and returns at or beyond "
                  "it (as prf --max-range's R) clear up to it, or up to their sensor's range "
                  "where that is shorter, m (sonar: 5 m unless given)")
      ->check(PositiveValue())
      ->capture_default_str();
  cmd->add_option("--max-cells", o->grid.max_cells,
                  "The most cells the grid may have (about 17 bytes each at the peak)")
      ->check(CLI::Range(1.0, 4e9))
      ->capture_default_str();
  cmd->callback([o, cmd] {
    o->max_range_given = cmd->count("--max-range") > 0;
    RunGridCommand(*o);
  });
}

}  // namespace priormap::app
