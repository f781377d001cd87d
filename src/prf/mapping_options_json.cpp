#include <priormap/prf/mapping_options_json.hpp>

namespace priormap::prf {

nlohmann::json SamplingOptionsJson(const MappingOptions& m) {
  nlohmann::json thinned = nlohmann::json::array();
  for (const ThinnedBurnIn& stage : m.thinned_burn_in)
    thinned.push_back({{"stride", stage.stride}, {"steps", stage.steps}});
  return {
      {"free_space", m.sampler.free_space},
      {"orientation_weight", m.sampler.orientation.weight},
      {"burn_in_temperature", m.burn_in_temperature},
      {"burn_in_replicas", m.burn_in_replicas},
      {"replica_temperature", m.replica_temperature},
      {"replica_steps", m.replica_steps},
      {"replica_pick", m.replica_pick_best ? "best" : "cold"},
      {"thinned_burn_in", thinned},
      {"thinned_rotation", m.thinned_rotation},
      {"thinned_weighed", m.thinned_weighed},
      {"warm_burn_in",
       {{"temperature", m.warm_burn_in.temperature}, {"steps", m.warm_burn_in.steps}}},
      {"delayed_acceptance", m.sampler.screen_stride},
      {"edge_shifts", m.sampler.weights[MoveKind::kEdgeShift]},
      {"step_scales", m.sampler.step_scales},
      {"vertex_birth_widths", m.sampler.vertex_birth_widths},
      {"corner_completion",
       {{"probability", m.sampler.corner_completion},
        {"jitter", m.sampler.corner_completion_jitter}}},
      {"neighbour_birth",
       {{"probability", m.sampler.neighbour_birth}, {"jitter", m.sampler.neighbour_birth_jitter}}},
      {"vertex_jump",
       {{"weight", m.sampler.weights[MoveKind::kVertexJump]},
        {"reach", m.sampler.vertex_jump_reach},
        {"jitter", m.sampler.vertex_jump_jitter}}},
      {"vertex_pairs", m.sampler.weights[MoveKind::kVertexPair]}};
}

}  // namespace priormap::prf
