#pragma once
// `priormap grid --sensor sonar`: the sonar occupancy grid of a log's rings, with the outputs of
// the laser grid (grid.png, grid.pgm + grid.yaml, summary.json).

#include <cstddef>
#include <string>

#include <priormap/core/log.hpp>
#include <priormap/grid/sonar_grid.hpp>

namespace priormap::app {

void RunSonarGrid(const Log& log, const std::string& log_path, std::size_t first, std::size_t end,
                  const grid::SonarGridOptions& options, const std::string& out,
                  double read_time_s);

}  // namespace priormap::app
