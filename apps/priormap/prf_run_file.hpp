#pragma once
// A `priormap prf` run's options and its run.json, which `--resume` reads to repeat the run and
// `prf rhat` to tell which runs sample the same posterior.

#include <cstdint>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include <priormap/prf/laser_data.hpp>
#include <priormap/prf/mapping.hpp>

#include "prf_posterior_options.hpp"

namespace priormap::app {

struct MappingCliOptions {
  std::string log;
  std::string range = ":";
  std::string out;
  prf::LaserSelection selection;
  prf::MappingOptions mapping;
  bool anneal = false;
  std::string sensor = "auto";  // --sensor: auto, laser or sonar
  std::string sonar_model;      // --sonar-model FILE; empty: the defaults
  PosteriorCliOptions posterior;
  // How this session runs (not part of the run: not saved in run.json).
  std::string resume;
  double checkpoint_every_s = 5.0;
  std::uint64_t stop_after_steps = 0;
  bool sigma_given = false;  // --sigma on the command line, even at its default value
};

/// The options that define a run, saved as DIR/run.json so that --resume DIR repeats them.
[[nodiscard]] nlohmann::json RunJson(const MappingCliOptions& o);

/// The run saved in the run.json at `path`, over `base` (which keeps what run.json does not hold:
/// a session's settings, or the defaults); keys absent from older run files take the values
/// those runs used. UserError for a malformed file or another version.
[[nodiscard]] MappingCliOptions ReadRunFile(const std::filesystem::path& path,
                                            MappingCliOptions base);

}  // namespace priormap::app
