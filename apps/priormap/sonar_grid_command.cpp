#include "sonar_grid_command.hpp"

#include <chrono>
#include <filesystem>
#include <system_error>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <priormap/core/file_io.hpp>
#include <priormap/render/prf_figures.hpp>

#include "cli_support.hpp"

namespace priormap::app {

void RunSonarGrid(const Log& log, const std::string& log_path, std::size_t first, std::size_t end,
                  const grid::SonarGridOptions& options, const std::string& out,
                  double read_time_s) {
  const Box2 extent = grid::SonarGrid::ExtentOf(log, first, end, options);
  if (extent.isEmpty()) throw UserError("the selected rings have no usable reading");
  grid::SonarGrid map(extent, options);  // first: a grid too large leaves no directory behind
  EnsureDirectoryWithoutLastFile(out, "summary.json");
  const auto start = std::chrono::steady_clock::now();
  std::size_t readings = 0;
  std::vector<Vec2> sensors;
  for (std::size_t k = first; k < end; ++k) {
    readings += map.Insert(log.scans[k]);
    if (log.scans[k].sonar) sensors.push_back(log.scans[k].pose.translation());
  }
  const double insert_time =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  const std::filesystem::path dir(out);
  const OccupancyRaster raster = map.Raster();
  WriteMapServerMap(dir / "grid.yaml", raster);
  render::SaveProbabilityFigure(
      dir / "grid.png", raster,
      fmt::format("sonar occupancy grid, {} m, scans {}:{}", options.resolution, first, end),
      sensors);
  const nlohmann::json summary = {
      {"log", log_path},
      {"sensor", "sonar"},
      {"scans", end - first},
      {"readings", readings},
      {"resolution", options.resolution},
      {"max_range", options.max_range},
      {"width", map.width()},
      {"height", map.height()},
      {"read_time_s", read_time_s},
      {"insert_time_s", insert_time},
      {"readings_per_second", static_cast<double>(readings) / insert_time},
      {"grid_bytes", std::filesystem::file_size(dir / "grid.pgm")}};
  WriteTextFileAtomically(dir / "summary.json", summary.dump(2) + "\n");
  fmt::print(
      "wrote {} (grid.png, grid.pgm, grid.yaml, summary.json): {} sonar readings, {}x{} "
      "cells\n",
      out, readings, map.width(), map.height());
}

}  // namespace priormap::app
