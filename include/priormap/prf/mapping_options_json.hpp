#pragma once
/// The posterior's and the burn-in's options as JSON, shared by the records that keep them (the
/// prf command's run.json and summary.json, the sonar study's summary.json), so that an option
/// added to the sampler reaches every record at once.

#include <nlohmann/json.hpp>

#include <priormap/prf/mapping.hpp>

namespace priormap::prf {

/// free_space, orientation_weight, burn_in_temperature, the replica ladder (but which replica
/// is picked), thinned_burn_in, warm_burn_in, delayed_acceptance, edge_shifts, step_scales and
/// vertex_birth_widths.
[[nodiscard]] nlohmann::json SamplingOptionsJson(const MappingOptions& m);

}  // namespace priormap::prf
