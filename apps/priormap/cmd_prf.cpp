// priormap prf: polygonal random fields (Paskin & Thrun). `prior-stats` samples the Arak prior
// with no data and compares the chain with the process's closed forms.
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <priormap/prf/moves.hpp>
#include <priormap/prf/prior_stats.hpp>

#include "cli_support.hpp"
#include "commands.hpp"

namespace priormap::app {
namespace {

struct PriorStatsCliOptions {
  prf::PriorStatsOptions stats;
  std::vector<double> distances;
  std::vector<std::string> moves;
};

// "triangle, boundary_triangle, ...": the names --moves takes, for its help and its errors.
std::string MoveKindList() {
  std::string list;
  for (int k = 0; k < prf::kNumMoveKinds; ++k)
    list += fmt::format("{}{}", k ? ", " : "", prf::MoveKindName(static_cast<prf::MoveKind>(k)));
  return list;
}

nlohmann::json EstimateJson(const prf::Estimate& e, double closed_form) {
  return {{"estimate", e.mean},
          {"se", e.standard_error},
          {"closed_form", closed_form},
          {"z", prf::StandardScore(e, closed_form)}};
}

void RunPriorStatsCommand(PriorStatsCliOptions o) {
  prf::PriorStatsOptions& s = o.stats;
  if (!o.distances.empty()) {
    s.distances.clear();
    for (double d : o.distances) {
      if (!(d > 0.0 && d < s.window))
        throw UserError(fmt::format("--distances: {} is not inside (0, window = {})", d, s.window));
      s.distances.push_back(d / s.window);
    }
  }
  if (!o.moves.empty()) {
    s.sampler.weights.weight.fill(0.0);
    for (const std::string& name : o.moves) {
      const auto kind = prf::ParseMoveKind(name);
      if (!kind)
        throw UserError(
            fmt::format("--moves: unknown move kind '{}' (expected: {})", name, MoveKindList()));
      s.sampler.weights[*kind] = 1.0;
    }
  }
  if (s.samples < 2 * s.batches)
    throw UserError(fmt::format("--samples must be at least {} (two per batch)", 2 * s.batches));
  const prf::PriorStatsResult r = prf::RunPriorStats(s);

  nlohmann::json out;
  out["p"] = s.p;
  out["window"] = s.window;
  out["samples"] = s.samples;
  out["thin"] = s.thin;
  out["burn_in"] = s.burn_in;
  out["seed"] = s.seed;
  out["steps"] = r.steps;
  out["wall_time_s"] = r.seconds;
  out["steps_per_second"] = static_cast<double>(r.steps) / r.seconds;
  out["mean_edges"] = r.edges.mean;
  out["mean_edges_se"] = r.edges.standard_error;
  out["expected_edges"] = r.expected_edges;
  out["black_fraction"] = EstimateJson(r.black_fraction, 0.5);
  out["same_colour"] = nlohmann::json::array();
  out["crossings"] = nlohmann::json::array();
  for (const prf::DistanceStats& d : r.by_distance) {
    nlohmann::json same = EstimateJson(d.same_colour, d.expected_same_colour);
    same["distance"] = d.distance;
    out["same_colour"].push_back(same);
    out["crossings"].push_back({{"distance", d.distance},
                                {"mean", EstimateJson(d.crossings, d.expected_crossings)},
                                {"none", EstimateJson(d.no_crossing, d.expected_no_crossing)}});
  }
  nlohmann::json acceptance;
  for (int t = 0; t < prf::kNumMoveTypes; ++t) {
    const prf::MoveCounter& c = r.counters[static_cast<std::size_t>(t)];
    acceptance[std::string(prf::MoveTypeName(static_cast<prf::MoveType>(t)))] = {
        {"proposed", c.proposed},
        {"invalid", c.invalid},
        {"accepted", c.accepted},
        {"rate",
         c.proposed ? static_cast<double>(c.accepted) / static_cast<double>(c.proposed) : 0.0}};
  }
  out["acceptance"] = acceptance;
  fmt::print("{}\n", out.dump(2));
}

void AddPriorStats(CLI::App& prf_cmd) {
  auto o = std::make_shared<PriorStatsCliOptions>();
  CLI::App* cmd = prf_cmd.add_subcommand(
      "prior-stats",
      "Sample the Arak prior with no data in an L x L window and compare with its closed forms "
      "(JSON on stdout): the evidence that the sampler's moves are right");
  cmd->add_option("--p", o->stats.p, "Scale parameter p of the Arak process (1/length)")
      ->check(PositiveValue())
      ->capture_default_str();
  cmd->add_option("--window", o->stats.window, "Side L of the square window")
      ->check(PositiveValue())
      ->capture_default_str();
  cmd->add_option("--samples", o->stats.samples, "Recorded states")
      ->check(CLI::Range(std::uint64_t{1}, std::uint64_t{1} << 40))
      ->capture_default_str();
  cmd->add_option("--thin", o->stats.thin, "Sampler steps between recorded states")
      ->check(CLI::Range(std::uint64_t{1}, std::uint64_t{1} << 40))
      ->capture_default_str();
  cmd->add_option("--burn-in", o->stats.burn_in, "Sampler steps before the first record")
      ->capture_default_str();
  cmd->add_option("--seed", o->stats.seed, "Random seed; the same seed gives the same result")
      ->capture_default_str();
  cmd->add_option("--distances", o->distances,
                  "Distances d for P(same colour) and the crossings (absolute, < L; default "
                  "0.05, 0.1, 0.2, 0.4 times L)")
      ->delimiter(',');
  cmd->add_option("--moves", o->moves,
                  "Only these move kinds (comma-separated: " + MoveKindList() + ")")
      ->delimiter(',');
  cmd->callback([o] { RunPriorStatsCommand(*o); });
}

}  // namespace

void AddPrfCommand(CLI::App& app) {
  CLI::App* cmd =
      app.add_subcommand("prf", "Polygonal random fields (Paskin & Thrun): prior-stats");
  cmd->require_subcommand(1);
  AddPriorStats(*cmd);
}

}  // namespace priormap::app
