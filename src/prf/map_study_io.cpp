#include <cmath>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <priormap/prf/map_study_io.hpp>
#include <priormap/prf/mapping_options_json.hpp>
#include <priormap/prf/sonar_model_io.hpp>
#include <priormap/prf/sonar_study.hpp>

namespace priormap::prf {
namespace {

nlohmann::json Number(double value) {
  return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
}

nlohmann::json ScoreJson(const ClassificationScore& s) {
  return {{"points", s.points},
          {"decided", s.decided},
          {"correct", s.correct},
          {"accuracy", Number(s.Accuracy())},
          {"coverage", Number(s.Coverage())},
          {"decided_accuracy", Number(s.DecidedAccuracy())}};
}

nlohmann::json ClassificationJson(const MapClassification& c) {
  return {{"observed", ScoreJson(c.observed)},
          {"sparse", ScoreJson(c.sparse)},
          {"covered", ScoreJson(c.covered)}};
}

std::string PercentText(double fraction) {
  return std::isfinite(fraction) ? fmt::format("{:.1f}", 100.0 * fraction) : "–";
}

nlohmann::json MethodsJson(const std::vector<MethodScores>& methods) {
  nlohmann::json out = nlohmann::json::object();
  for (const MethodScores& m : methods) {
    out[m.method] = ClassificationJson(m.classification);
    out[m.method]["seconds"] = m.seconds;
  }
  return out;
}

nlohmann::json CaseJson(const MapStudyCase& c) {
  nlohmann::json poses = nlohmann::json::array();
  for (const Se2& pose : c.poses) poses.push_back({pose.x(), pose.y(), pose.theta()});
  std::size_t hits = 0;
  for (const LaserBeam& beam : c.data->beams) hits += beam.max_reading ? 0 : 1;
  nlohmann::json j = {
      {"scene", c.scene},
      {"sensor", c.sensor},
      {"seed", c.seed},
      {"poses", poses},
      {"beams", c.data->beams.size()},
      {"hits", hits},
      {"max_range", c.data->max_range},
      {"window",
       {c.prf.window.min.x(), c.prf.window.min.y(), c.prf.window.max.x(), c.prf.window.max.y()}},
      {"methods", MethodsJson(c.methods)},
      {"prf",
       {{"proposals", c.prf.proposals},
        {"proposals_per_second", c.prf.ProposalsPerSecond()},
        {"resumed_steps", c.prf.resumed_steps},
        {"rhat_log_posterior", Number(c.prf.rhat_log_posterior)},
        {"rhat_point_colours", Number(c.prf.rhat_point_colours)}}},
      {"wall_time_s", c.wall_time_s}};
  if (c.prf.map)
    j["map"] = {{"edges", c.prf.map->stats().edges},
                {"scored_length_m", c.walls.scored_length},
                {"border_length_m", c.walls.border_length},
                {"mean_distance_m", Number(c.walls.mean_distance)},
                {"p90_distance_m", Number(c.walls.p90_distance)},
                {"max_distance_m", Number(c.walls.max_distance)},
                {"supported_length_m", c.walls.supported_length},
                {"supported_mean_distance_m", Number(c.walls.supported_mean_distance)},
                {"supported_p90_distance_m", Number(c.walls.supported_p90_distance)},
                {"supported_max_distance_m", Number(c.walls.supported_max_distance)},
                {"wall_points", c.walls.wall_points},
                {"recovered_fraction", Number(c.walls.recovered_fraction)}};
  return j;
}

std::string Percent(double value) {
  return PercentText(value);
}

std::string Centimetres(double value) {
  return std::isfinite(value) ? fmt::format("{:.1f}", 100.0 * value) : "–";
}

const MethodScores* Find(const std::vector<MethodScores>& methods, const std::string& name) {
  for (const MethodScores& m : methods)
    if (m.method == name) return &m;
  return nullptr;
}

// "accuracy (coverage)" of a method over one part, in percent.
std::string Cell(const MethodScores* m, const ClassificationScore MapClassification::*part,
                 bool coverage) {
  if (!m) return "–";
  const ClassificationScore& s = m->classification.*part;
  return coverage ? fmt::format("{} ({})", Percent(s.Accuracy()), Percent(s.Coverage()))
                  : Percent(s.Accuracy());
}

}  // namespace

nlohmann::json MapStudyOptionsJson(const MapStudyOptions& options) {
  const MappingOptions& m = options.mapping;
  std::vector<std::string> scenes, sensors;
  for (const Scene& scene : options.scenes) scenes.push_back(scene.name);
  for (const RangeSensor& sensor : options.sensors) sensors.push_back(sensor.name);
  return {{"scenes", scenes},
          {"sensors", sensors},
          {"poses", options.poses},
          {"beam_step", options.beam_step},
          {"max_range", options.max_range},
          {"resolution", options.resolution},
          {"band", options.band},
          {"truth_resolution", options.truth_resolution},
          {"wall_tolerance", options.walls.tolerance},
          {"p", m.sampler.p},
          {"sigma", m.model.sigma},
          {"samples", m.samples},
          {"burn_in", m.burn_in},
          {"chains", m.chains},
          {"anneal_steps", m.anneal_steps},
          {"seed", options.seed}};
}

std::string MapStudySummaryJson(const MapStudyResult& study, const MapStudyOptions& options) {
  nlohmann::json j;
  j["format"] = "priormap.prf_study";
  j["version"] = 1;
  j["options"] = MapStudyOptionsJson(options);
  j["wall_time_s"] = study.wall_time_s;
  j["cases"] = nlohmann::json::array();
  for (const MapStudyCase& c : study.cases) j["cases"].push_back(CaseJson(c));
  j["overall"] = MethodsJson(study.overall);
  return j.dump(2) + "\n";
}

std::string MapStudyMarkdownTable(const MapStudyResult& study) {
  std::string table =
      "| case | beams | observed cells (sparse %) | observed: grid (coverage) | PRF | MAP | "
      "sparse: grid (coverage) | PRF | MAP | MAP walls: mean / p90 (cm) | "
      "walls where beams ended: mean / p90 (cm) | recovered % | grid ms | PRF s |\n"
      "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  const auto row = [&](const std::string& name, const std::string& beams,
                       const std::vector<MethodScores>& methods, const std::string& walls,
                       const std::string& recovered) {
    const MethodScores* grid = Find(methods, "grid");
    const MethodScores* posterior = Find(methods, "prf posterior");
    const MethodScores* map = Find(methods, "prf map");
    const ClassificationScore& observed = posterior->classification.observed;
    const ClassificationScore& sparse = posterior->classification.sparse;
    table += fmt::format(
        "| {} | {} | {} ({}) | {} | {} | {} | {} | {} | {} | {} | {} | {:.1f} | {:.1f} |\n", name,
        beams, observed.points,
        Percent(static_cast<double>(sparse.points) / static_cast<double>(observed.points)),
        Cell(grid, &MapClassification::observed, true),
        Cell(posterior, &MapClassification::observed, false),
        Cell(map, &MapClassification::observed, false),
        Cell(grid, &MapClassification::sparse, true),
        Cell(posterior, &MapClassification::sparse, false),
        Cell(map, &MapClassification::sparse, false), walls, recovered,
        grid ? 1e3 * grid->seconds : 0.0, map ? map->seconds : posterior->seconds);
  };
  std::size_t beams = 0;
  for (const MapStudyCase& c : study.cases) {
    beams += c.data->beams.size();
    row(c.Name(), std::to_string(c.data->beams.size()), c.methods,
        fmt::format("{} / {} | {} / {}", Centimetres(c.walls.mean_distance),
                    Centimetres(c.walls.p90_distance), Centimetres(c.walls.supported_mean_distance),
                    Centimetres(c.walls.supported_p90_distance)),
        Percent(c.walls.recovered_fraction));
  }
  if (study.cases.size() > 1) row("**all**", std::to_string(beams), study.overall, "– | –", "–");
  return table;
}

}  // namespace priormap::prf

namespace priormap::prf {
namespace {

nlohmann::json ContourJson(const ContourWallScore& w) {
  return {{"contour_length_m", w.contour_length},
          {"mean_distance_m", Number(w.mean_distance)},
          {"p90_distance_m", Number(w.p90_distance)},
          {"walls_seen", w.walls_seen},
          {"walls_missed", w.walls_missed},
          {"recovered_fraction", Number(w.recovered_fraction)}};
}

}  // namespace

nlohmann::json SonarStudyOptionsJson(const SonarStudyOptions& options) {
  const MappingOptions& m = options.mapping;
  std::vector<std::string> scenes;
  for (const Scene& scene : options.scenes) scenes.push_back(scene.name);
  nlohmann::json j = {{"scenes", scenes},
                      {"sensor", options.sensor.name},
                      {"max_range", options.sensor.max_range},
                      {"speed", options.speed},
                      {"rate", options.rate},
                      {"resolution", options.resolution},
                      {"band", options.band},
                      {"wall_tolerance", options.walls.tolerance},
                      {"p", m.sampler.p},
                      {"samples", m.samples},
                      {"burn_in", m.burn_in},
                      {"chains", m.chains},
                      {"seed", options.seed},
                      {"start_at_truth", options.start_at_truth},
                      {"orientation_rad", m.sampler.orientation.angle},
                      {"sonar_model", nlohmann::json::parse(FormatSonarModel(options.model))}};
  j.update(SamplingOptionsJson(m));
  return j;
}

std::string SonarStudySummaryJson(const SonarStudyResult& study, const SonarStudyOptions& options) {
  nlohmann::json j;
  j["format"] = "priormap.prf_sonar_study";
  j["version"] = 1;
  j["options"] = SonarStudyOptionsJson(options);
  j["wall_time_s"] = study.wall_time_s;
  j["cases"] = nlohmann::json::array();
  for (const SonarStudyCase& c : study.cases) {
    nlohmann::json chains = nlohmann::json::array();
    for (const ChainSummary& chain : c.prf.chains)
      chains.push_back({{"log_posterior", chain.log_posterior},
                        {"log_prior", chain.log_prior},
                        {"log_likelihood", chain.log_likelihood},
                        {"edges", chain.edges},
                        {"swap_rates", SwapRates(chain.swaps)}});
    nlohmann::json methods = nlohmann::json::object();
    for (const SonarStudyMethod& method : c.methods) {
      methods[method.method] = ClassificationJson(method.classification);
      methods[method.method]["walls"] = ContourJson(method.walls);
      methods[method.method]["seconds"] = method.seconds;
    }
    j["cases"].push_back({{"scene", c.scene},
                          {"seed", c.seed},
                          {"readings", c.readings},
                          {"max_readings", c.max_readings},
                          {"rings", c.ring_poses.size()},
                          {"methods", methods},
                          {"proposals_per_second", c.prf.ProposalsPerSecond()},
                          {"resumed_steps", c.prf.resumed_steps},
                          {"rhat_log_posterior", Number(c.prf.rhat_log_posterior)},
                          {"rhat_point_colours", Number(c.prf.rhat_point_colours)},
                          {"truth_log_posterior", Number(c.truth_log_posterior)},
                          {"truth_log_likelihood", Number(c.truth_log_likelihood)},
                          {"chains", chains},
                          {"wall_time_s", c.wall_time_s}});
  }
  return j.dump(2) + "\n";
}

std::string SonarStudyMarkdownTable(const SonarStudyResult& study) {
  std::string table =
      "| case | readings (max-range) | method | observed: accuracy (coverage) | sparse | "
      "walls missed / seen | recovered % | 0.5 contour to walls: mean / p90 (cm) | s |\n"
      "|---|---:|---|---:|---:|---:|---:|---:|---:|\n";
  for (const SonarStudyCase& c : study.cases) {
    for (const SonarStudyMethod& m : c.methods) {
      const ClassificationScore& observed = m.classification.observed;
      table += fmt::format(
          "| {} | {} ({}) | {} | {} ({}) | {} | {} / {} | {} | {} / {} | {:.1f} |\n", c.scene,
          c.readings, c.max_readings, m.method, PercentText(observed.Accuracy()),
          PercentText(observed.Coverage()), PercentText(m.classification.sparse.Accuracy()),
          m.walls.walls_missed, m.walls.walls_seen, PercentText(m.walls.recovered_fraction),
          Centimetres(m.walls.mean_distance), Centimetres(m.walls.p90_distance), m.seconds);
    }
  }
  return table;
}

}  // namespace priormap::prf
