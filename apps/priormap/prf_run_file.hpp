#pragma once
// A `priormap prf` run's options and its run.json, which `--resume` reads to repeat the run and
// `prf rhat` to tell which runs sample the same posterior.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include <priormap/prf/laser_data.hpp>
#include <priormap/prf/mapping.hpp>

#include "prf_posterior_options.hpp"

namespace priormap::app {

/// What run.json records of a run as it started, in the hashes its checkpoints are checked by, so
/// that a resume refused by them can say why: its data changed, or this priormap makes another
/// run of the same options (another version).
struct RunFingerprints {
  std::uint64_t data = 0;  ///< MappingData::data_fingerprint: the readings selected, the data model
  std::uint64_t run = 0;   ///< MappingData::fingerprint: those and the options
};

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
  // The run's as it started, which run.json records (absent from run files written before
  // 2026-12-01): not an option.
  std::optional<RunFingerprints> started_with;
};

/// The options that define a run, saved as DIR/run.json so that --resume DIR repeats them, with
/// the run's fingerprints as it started (o.started_with) when they are known.
[[nodiscard]] nlohmann::json RunJson(const MappingCliOptions& o);

/// The run saved in the run.json at `path`, over `base` (which keeps what run.json does not hold:
/// a session's settings, or the defaults); keys absent from older run files take the values
/// those runs used. UserError for a malformed file or another version of the format.
[[nodiscard]] MappingCliOptions ReadRunFile(const std::filesystem::path& path,
                                            MappingCliOptions base);

}  // namespace priormap::app
