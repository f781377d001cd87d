// priormap prf rhat: R̂ over the chains of several `priormap prf` runs of one posterior (other
// seeds, other machines), from their run.json, trace.csv and point_traces.csv.
#include <cmath>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <priormap/core/file_io.hpp>
#include <priormap/prf/pooled_rhat.hpp>

#include "cli_support.hpp"
#include "commands.hpp"

namespace priormap::app {
namespace {

namespace fs = std::filesystem;

struct RhatCliOptions {
  std::vector<std::string> runs;
};

// What a run's posterior is made of in its run.json: runs that differ here sample different
// posteriors, and R̂ across them means nothing. The sampler's settings (burn-in, moves,
// delayed acceptance, ...) may differ.
nlohmann::json TargetOf(const nlohmann::json& run) {
  nlohmann::json target;
  for (const char* key :
       {"log", "range", "sensor", "beam_step", "max_range", "p", "sigma", "sonar_model"})
    if (run.contains(key)) target[key] = run[key];
  if (run.contains("posterior"))
    for (const char* key : {"free_space", "orientation_deg", "orientation_weight"})
      if (run["posterior"].contains(key)) target["posterior"][key] = run["posterior"][key];
  return target;
}

nlohmann::json ReadJsonFile(const fs::path& path) {
  const std::string text = ValueOrThrow(ReadFileText(path));
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    const TextPosition at = PositionOfOffset(text, e.byte == 0 ? 0 : e.byte - 1);
    throw UserError(fmt::format("{}:{}:{}: expected the JSON a `priormap prf` run writes ({})",
                                path.string(), at.line, at.col, e.what()));
  }
}

template <typename T>
T Member(const nlohmann::json& document, const char* key, const fs::path& path) {
  if (!document.contains(key))
    throw UserError(fmt::format("{}: expected the member '{}'", path.string(), key));
  try {
    return document[key].get<T>();
  } catch (const nlohmann::json::exception&) {
    throw UserError(fmt::format("{}: the member '{}' has the wrong type", path.string(), key));
  }
}

// R̂ is +inf when every half of every chain is constant but the halves differ; JSON has no
// infinity, and null would read as "not computed".
nlohmann::ordered_json RhatJson(double rhat) {
  return std::isinf(rhat) ? nlohmann::ordered_json("inf") : nlohmann::ordered_json(rhat);
}

struct LoadedRun {
  prf::PooledRun pooled;
  nlohmann::json target;
  nlohmann::json trace_points;  // null for runs that did not write them
  bool has_point_traces = false;
};

LoadedRun LoadRun(const std::string& dir) {
  const fs::path root(dir);
  const fs::path run_path = root / "run.json";
  const nlohmann::json run = ReadJsonFile(run_path);
  if (!run.contains("format") || run["format"] != "priormap prf run")
    throw UserError(
        fmt::format("{}: expected a `priormap prf` run (\"format\": \"priormap prf "
                    "run\")",
                    run_path.string()));
  LoadedRun loaded;
  loaded.pooled.name = dir;
  loaded.target = TargetOf(run);
  const auto seed = Member<std::uint64_t>(run, "seed", run_path);
  const auto chains = Member<std::size_t>(run, "chains", run_path);
  for (std::size_t c = 0; c < chains; ++c) loaded.pooled.chain_seeds.push_back(seed + c);

  const fs::path trace_path = root / "trace.csv";
  prf::RunTraces traces = ValueOrThrow(
      prf::ParseLogPosteriorTrace(ValueOrThrow(ReadFileText(trace_path)), trace_path.string()));
  if (traces.log_posterior.size() != chains)
    throw UserError(fmt::format("{} has {} chains, {} says {}", trace_path.string(),
                                traces.log_posterior.size(), run_path.string(), chains));
  const fs::path point_path = root / "point_traces.csv";
  if (fs::exists(point_path)) {
    traces = ValueOrThrow(prf::ParsePointTraces(ValueOrThrow(ReadFileText(point_path)),
                                                point_path.string(), std::move(traces)));
    loaded.has_point_traces = true;
  }
  loaded.pooled.traces = std::move(traces);
  const fs::path summary_path = root / "summary.json";
  if (fs::exists(summary_path)) {
    const nlohmann::json summary = ReadJsonFile(summary_path);
    if (summary.contains("trace_points")) loaded.trace_points = summary["trace_points"];
  }
  return loaded;
}

void RunRhat(const RhatCliOptions& o) {
  std::vector<LoadedRun> runs;
  for (const std::string& dir : o.runs) runs.push_back(LoadRun(dir));
  for (const LoadedRun& run : runs) {
    if (run.target != runs.front().target)
      throw UserError(fmt::format(
          "{} maps another posterior than {} (run.json differs in the log, the sensor, the "
          "model or the priors): pool runs of one posterior only",
          run.pooled.name, runs.front().pooled.name));
    if (!run.trace_points.is_null() && !runs.front().trace_points.is_null() &&
        run.trace_points != runs.front().trace_points)
      throw UserError(
          fmt::format("{} traced other points than {}", run.pooled.name, runs.front().pooled.name));
  }
  std::vector<prf::PooledRun> pooled_runs;
  for (const LoadedRun& run : runs) pooled_runs.push_back(run.pooled);
  const auto pooled = prf::PoolRhat(pooled_runs);
  if (const auto* problem = std::get_if<std::string>(&pooled)) throw UserError(*problem);
  const prf::PooledRhat& r = std::get<prf::PooledRhat>(pooled);

  nlohmann::ordered_json out;
  out["chains"] = r.chains;
  out["records"] = r.records;
  out["rhat"]["log_posterior"] = RhatJson(r.log_posterior);
  if (r.point_colours) {
    out["rhat"]["point_colours"] = RhatJson(*r.point_colours);
    out["rhat"]["points"] = r.points;
  } else {
    out["rhat"]["point_colours"] = nullptr;
    out["rhat"]["why_no_point_colours"] =
        "not every run wrote point_traces.csv with the same number of points";
  }
  out["runs"] = nlohmann::ordered_json::array();
  std::size_t chain = 0;
  for (const LoadedRun& run : runs) {
    nlohmann::ordered_json entry;
    entry["run"] = run.pooled.name;
    entry["chain_seeds"] = run.pooled.chain_seeds;
    entry["second_half_means"] = nlohmann::ordered_json::array();
    for (std::size_t c = 0; c < run.pooled.traces.log_posterior.size(); ++c)
      entry["second_half_means"].push_back(r.second_half_means[chain++]);
    out["runs"].push_back(entry);
  }
  fmt::print("{}\n", out.dump(2));
}

}  // namespace

void AddPrfRhatCommand(CLI::App& prf_cmd) {
  auto o = std::make_shared<RhatCliOptions>();
  CLI::App* cmd = prf_cmd.add_subcommand(
      "rhat",
      "Split R-hat over the chains of several `priormap prf` runs of one posterior (other seeds, "
      "other machines): more chains than one run's, as JSON on standard output");
  cmd->add_option("runs", o->runs, "Output directories of `priormap prf` runs (-o)")
      ->required()
      ->check(CLI::ExistingDirectory);
  cmd->callback([o] { RunRhat(*o); });
}

}  // namespace priormap::app
