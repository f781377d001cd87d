#include <cmath>

#include <nlohmann/json.hpp>

#include <priormap/priorlets/map_scan_json.hpp>

namespace priormap::priorlets {
namespace {

nlohmann::json Numbers(const std::vector<double>& values) {
  nlohmann::json array = nlohmann::json::array();
  for (double v : values) {
    if (std::isfinite(v)) {
      array.push_back(v);
    } else {
      array.push_back(nullptr);
    }
  }
  return array;
}

nlohmann::json Ranges(const std::vector<BeamRange>& ranges) {
  nlohmann::json array = nlohmann::json::array();
  for (const BeamRange& r : ranges) array.push_back({r.first, r.last});
  return array;
}

}  // namespace

std::string MapScanToJson(const MapScan& map, const MapScanJsonContext& context) {
  nlohmann::json j;
  j["format"] = "priormap.map_scan";
  j["version"] = 1;
  j["input"] = context.input;
  j["scan_index"] = context.scan_index;
  j["prior"] = context.prior_name;
  j["feasible"] = map.feasible;
  j["max_violation"] = map.max_violation;
  j["objective"] = map.objective;
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
  j["regions"] = Ranges(map.regions);
  j["surfaces"] = Ranges(map.surfaces);
  j["stats"] = {{"outer_rounds", map.stats.outer_rounds},
                {"inner_solves", map.stats.inner_solves},
                {"newton_steps", map.stats.newton_steps},
                {"refinement_trials", map.stats.refinement_trials},
                {"seconds", map.stats.seconds_total},
                {"seconds_outer", map.stats.seconds_outer},
                {"seconds_refine", map.stats.seconds_refine}};
  return j.dump();
}

}  // namespace priormap::priorlets
