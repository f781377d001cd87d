#pragma once
// The PRF options beyond the Arak process and a plain burn-in, shared by `prf` and
// `prf sonar-study`: the prior's extensions (free space, orientation) and the burn-in's schedule
// (tempering, thinned stages).

#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <priormap/prf/mapping.hpp>

namespace priormap::app {

/// What the options hold in text or other units before ApplyPosteriorOptions.
struct PosteriorCliOptions {
  double orientation_deg = 0.0;
  std::vector<std::string> thinned_burn_in;  // "STRIDE:STEPS"
  std::string warm_burn_in;                  // "T:STEPS"
  std::string replica_pick = "cold";         // or "best"
};

void AddPosteriorOptions(CLI::App& cmd, prf::MappingOptions& mapping, PosteriorCliOptions& cli);
/// Puts the angle (radians), the thinned stages and the warm stage into `mapping`; UserError on
/// a malformed stage or stages longer than the burn-in.
void ApplyPosteriorOptions(const PosteriorCliOptions& cli, prf::MappingOptions* mapping);
/// UserError when the options do not fit together (stages longer than the burn-in, shares of
/// the vertex births that sum to 1 or more, ...): checked for the command line and run.json.
void RequireConsistentPosteriorOptions(const prf::MappingOptions& mapping);

/// The options as JSON (run.json, summaries), and back (keys absent from older run files keep
/// their defaults).
[[nodiscard]] nlohmann::json PosteriorOptionsJson(const prf::MappingOptions& mapping);
void PosteriorOptionsFromJson(const nlohmann::json& j, prf::MappingOptions* mapping);

}  // namespace priormap::app
