#include <cmath>

#include <nlohmann/json.hpp>

#include <priormap/priorlets/map_scan_json.hpp>

#include "../core/json_document.hpp"

namespace priormap::priorlets {
namespace {

// As everywhere in our JSON (docs/formats.md): null for NaN ("not available"), the strings
// "inf" / "-inf" for infinities (an out-of-model beam keeps its infinite reading).
nlohmann::json Number(double v) {
  return nlohmann::json(detail::NumberToJson(v));
}

nlohmann::json Numbers(const std::vector<double>& values) {
  nlohmann::json array = nlohmann::json::array();
  for (double v : values) array.push_back(Number(v));
  return array;
}

nlohmann::json Ranges(const std::vector<BeamRange>& ranges) {
  nlohmann::json array = nlohmann::json::array();
  for (const BeamRange& r : ranges) array.push_back({r.first, r.last});
  return array;
}

nlohmann::json EigenvariationsJson(const std::vector<Eigenvariation>& eigenvariations) {
  nlohmann::json array = nlohmann::json::array();
  for (const Eigenvariation& ev : eigenvariations) {
    array.push_back({{"sigma", ev.sigma},
                     {"intrinsic_fraction", ev.intrinsic_fraction},
                     {"rho", Numbers(ev.rho)},
                     {"alpha", Numbers(ev.alpha)}});
  }
  return array;
}

void AddPosterior(const Posterior& p, nlohmann::json& j) {
  j["dof"] = {{"free", p.dof.free},
              {"extrinsic", p.dof.extrinsic},
              {"intrinsic", p.dof.intrinsic},
              {"pose_independent", p.dof.pose_independent},
              {"min_extrinsic_cosine", p.dof.min_extrinsic_cosine},
              {"largest_null_singular_value", p.dof.kernel.largest_null_singular_value},
              {"smallest_kept_singular_value",
               std::isfinite(p.dof.kernel.smallest_kept_singular_value)
                   ? nlohmann::json(p.dof.kernel.smallest_kept_singular_value)
                   : nlohmann::json(nullptr)}};
  j["posterior"] = {
      {"computed", p.computed},
      {"note", p.note},
      {"covariance", p.form == CovarianceForm::kConditional ? "conditional" : "projected"}};
  j["prior_std"] = Numbers(p.prior_std_rho);
  j["prior_std_alpha"] = Numbers(p.prior_std_alpha);
  j["posterior_std"] = Numbers(p.posterior_std_rho);
  j["posterior_std_alpha"] = Numbers(p.posterior_std_alpha);
  j["eigenvariations"] = EigenvariationsJson(p.eigenvariations);
  j["intrinsic_eigenvariations"] = EigenvariationsJson(p.intrinsic_eigenvariations);
}

}  // namespace

std::string MapScanToJson(const MapScan& map, const MapScanJsonContext& context,
                          const Posterior* posterior) {
  nlohmann::json j;
  j["format"] = "priormap.map_scan";
  j["version"] = 1;
  j["input"] = context.input;
  j["scan_index"] = context.scan_index;
  j["prior"] = context.prior_name;
  j["feasible"] = map.feasible;
  j["max_violation"] = Number(map.max_violation);
  j["objective"] = Number(map.objective);
  j["rho"] = Numbers(map.rho);
  j["alpha"] = Numbers(map.alpha);
  j["initial_alpha"] = Numbers(map.initial_alpha);
  nlohmann::json inmodel = nlohmann::json::array();
  for (std::uint8_t v : map.inmodel) inmodel.push_back(v != 0);
  j["inmodel"] = std::move(inmodel);
  j["inmodel_beams"] = map.inmodel_beams;
  nlohmann::json topology = nlohmann::json::array();
  for (Link l : map.links) topology.push_back(ToString(l));
  j["topology"] = std::move(topology);
  // A full-turn scan's in-model points form a ring: the link from the last to the first.
  j["closed"] = map.closed;
  if (map.closed) j["closing_link"] = ToString(map.closing_link);
  j["regions"] = Ranges(map.regions);
  j["surfaces"] = Ranges(map.surfaces);
  j["stats"] = {{"outer_rounds", map.stats.outer_rounds},
                {"inner_solves", map.stats.inner_solves},
                {"newton_steps", map.stats.newton_steps},
                {"refinement_trials", map.stats.refinement_trials},
                {"seconds", map.stats.seconds_total},
                {"seconds_outer", map.stats.seconds_outer},
                {"seconds_refine", map.stats.seconds_refine}};
  if (posterior) {
    AddPosterior(*posterior, j);
    j["stats"]["seconds_dof"] = posterior->seconds;
  }
  return j.dump();
}

}  // namespace priormap::priorlets
