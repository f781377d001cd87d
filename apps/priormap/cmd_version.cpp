// priormap version: the version of priormap and of the libraries it was built with.
#include <oneapi/tbb/version.h>

#include <Eigen/Core>
#include <cairo.h>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "commands.hpp"

namespace priormap::app {

void AddVersionCommand(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand("version", "Print the version of priormap and its libraries");
  cmd->callback([] {
    fmt::print("priormap {}\n", PRIORMAP_VERSION);
    fmt::print("  Eigen {}.{}.{}, fmt {}, nlohmann_json {}.{}.{}, CLI11 {}, cairo {}, oneTBB {}\n",
               EIGEN_WORLD_VERSION, EIGEN_MAJOR_VERSION, EIGEN_MINOR_VERSION, FMT_VERSION,
               NLOHMANN_JSON_VERSION_MAJOR, NLOHMANN_JSON_VERSION_MINOR,
               NLOHMANN_JSON_VERSION_PATCH, CLI11_VERSION, cairo_version_string(),
               TBB_VERSION_STRING);
  });
}

}  // namespace priormap::app
