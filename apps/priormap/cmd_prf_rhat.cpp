// priormap prf rhat: R̂ over the chains of several `priormap prf` runs of one posterior (other
// seeds, other machines), from their run.json, trace.csv and point_traces.csv.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <priormap/core/file_io.hpp>
#include <priormap/core/utf8.hpp>
#include <priormap/prf/pooled_rhat.hpp>
#include <priormap/prf/rhat.hpp>

#include "cli_support.hpp"
#include "commands.hpp"
#include "json_whole_number.hpp"
#include "prf_run_file.hpp"

namespace priormap::app {
namespace {

namespace fs = std::filesystem;

struct RhatCliOptions {
  std::vector<std::string> runs;
};

nlohmann::json ReadJsonFile(const fs::path& path) {
  const std::string text = ValueOrThrow(ReadFileText(path));
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    const std::size_t offset = e.byte == 0 ? 0 : e.byte - 1;
    TextPosition at = PositionOfOffset(text, offset);
    at.col = CharacterColumnInText(text, offset);
    throw UserError(fmt::format("{}:{}:{}: expected the JSON a `priormap prf` run writes ({})",
                                path.string(), at.line, at.col, e.what()));
  } catch (const nlohmann::json::exception& e) {
    throw UserError(fmt::format("{}: expected the JSON a `priormap prf` run writes ({})",
                                path.string(), e.what()));
  }
}

template <typename T>
T Member(const nlohmann::json& document, const char* key, const fs::path& path) {
  if (!document.contains(key))
    throw UserError(fmt::format("{}: expected the member '{}'", path.string(), key));
  try {
    if constexpr (std::is_integral_v<T>) {
      return WholeNumberMember<T>(document, key);
    } else {
      return document[key].get<T>();
    }
  } catch (const JsonNumberError& e) {
    throw UserError(fmt::format("{}: {}", path.string(), e.what()));
  } catch (const nlohmann::json::exception&) {
    throw UserError(fmt::format("{}: the member '{}' has the wrong type", path.string(), key));
  }
}

// R̂ is +inf when every half of every chain is constant but the halves differ, which is not "not
// computed" (null). PoolRhat maps huge log-posteriors into range first, so NaN is not expected;
// should one come, it is written "nan".
nlohmann::ordered_json RhatJson(double rhat) {
  if (std::isnan(rhat)) return "nan";
  return nlohmann::ordered_json(NumberOrInfinityText(rhat));
}

// What a run's posterior is made of: runs that differ in one of these sample different
// posteriors, and R̂ across them means nothing. The sampler's settings (burn-in, moves, delayed
// acceptance, ...) may differ. The data are compared by their fingerprint (the readings and the
// data model), so that runs made elsewhere, of a log under another name, pool; runs made before
// summary.json held it are compared by the log's and model's file names and the data's size.
using Target = std::vector<std::pair<const char*, nlohmann::json>>;

struct LoadedRun {
  prf::PooledRun pooled;
  MappingCliOptions options;
  nlohmann::json summary;
  fs::path summary_path;
  nlohmann::json trace_points;  // null for runs made before summary.json listed them
};

Target TargetOf(const LoadedRun& loaded, bool by_fingerprint) {
  const auto file_name = [](const std::string& path) { return fs::path(path).filename().string(); };
  const nlohmann::json& summary = loaded.summary;
  const fs::path& at = loaded.summary_path;
  const MappingCliOptions& run = loaded.options;
  const prf::SamplerOptions& sampler = run.mapping.sampler;
  Target data;
  if (by_fingerprint)
    data = {{"data fingerprint", Member<std::string>(summary, "data_fingerprint", at)}};
  else
    data = {{"log file name", file_name(run.log)},
            {"sonar model file name", file_name(run.sonar_model)},
            {"readings", Member<std::uint64_t>(summary, "beams", at)},
            {"sensor positions", Member<std::uint64_t>(summary, "sensor_positions", at)}};
  Target target = {{"window", Member<nlohmann::json>(summary, "window", at)},
                   {"sensor", Member<std::string>(summary, "sensor", at)},
                   {"range", run.range},
                   {"beam_step", run.selection.beam_step},
                   {"max_range", run.selection.max_range},
                   {"p", sampler.p},
                   {"sigma", run.mapping.model.sigma},
                   {"free_space", sampler.free_space},
                   {"orientation_weight", sampler.orientation.weight},
                   // The orientation prior's angle matters only when it has a weight.
                   {"orientation angle (rad)", sampler.orientation.weight != 0.0
                                                   ? nlohmann::json(sampler.orientation.angle)
                                                   : nlohmann::json()}};
  target.insert(target.begin(), data.begin(), data.end());
  return target;
}

LoadedRun LoadRun(const std::string& dir) {
  const fs::path root(dir);
  const fs::path summary_path = root / "summary.json";
  // A run writes summary.json last and then removes its checkpoints; before that, its trace
  // files may still be those of an earlier run in the same directory.
  if (!fs::exists(summary_path) || fs::exists(root / "checkpoints"))
    throw UserError(fmt::format(
        "{}: not a complete `priormap prf` run (expected its summary.json and no checkpoints; "
        "a stopped run completes with `priormap prf --resume {}`)",
        dir, dir));
  const fs::path run_path = root / "run.json";
  LoadedRun loaded;
  loaded.options = ReadRunFile(run_path, MappingCliOptions{});
  loaded.summary = ReadJsonFile(summary_path);
  loaded.summary_path = summary_path;
  loaded.pooled.name = dir;
  if (loaded.summary.contains("trace_points")) {
    loaded.trace_points = loaded.summary["trace_points"];
    if (!loaded.trace_points.is_array())
      throw UserError(
          fmt::format("{}: the member 'trace_points' has the wrong type (expected an "
                      "array of points)",
                      summary_path.string()));
  }

  const fs::path trace_path = root / "trace.csv";
  prf::RunTraces traces = ValueOrThrow(
      prf::ParseLogPosteriorTrace(ValueOrThrow(ReadFileText(trace_path)), trace_path.string()));
  const int chains = loaded.options.mapping.chains;
  if (chains < 1 || static_cast<std::size_t>(chains) != traces.log_posterior.size())
    throw UserError(fmt::format("{}:1:1: expected a column for each chain, {} as {} says, found {}",
                                trace_path.string(), chains, run_path.string(),
                                traces.log_posterior.size()));
  for (int c = 0; c < chains; ++c)
    loaded.pooled.chain_seeds.push_back(loaded.options.mapping.seed +
                                        static_cast<std::uint64_t>(c));
  const fs::path point_path = root / "point_traces.csv";
  if (fs::exists(point_path))
    traces = ValueOrThrow(prf::ParsePointTraces(ValueOrThrow(ReadFileText(point_path)),
                                                point_path.string(), std::move(traces)));
  // A point's position in summary.json is found by its index in point_traces.csv: both must
  // hold as many points.
  if (!traces.point_colours.empty() && loaded.trace_points.is_array() &&
      loaded.trace_points.size() != traces.point_colours[0].size())
    throw UserError(fmt::format(
        "{}:1:1: expected a column per chain for each trace point, {} as {} lists, found {} "
        "per chain",
        point_path.string(), loaded.trace_points.size(), summary_path.string(),
        traces.point_colours[0].size()));
  loaded.pooled.traces = std::move(traces);
  return loaded;
}

// The trace points whose R̂ is not below the threshold, worst first, with where they are and
// how often each chain (run after run) held them black: where the chains' maps differ.
nlohmann::ordered_json DisagreeingPoints(const prf::PooledRhat& r,
                                         const nlohmann::json* trace_points) {
  std::vector<const prf::PointRhat*> disagreeing;
  for (const prf::PointRhat& point : r.point_rhats)
    if (!(point.rhat < prf::kConvergedRhat)) disagreeing.push_back(&point);
  // Colours are read as 0 or 1 only, so a point's R̂ is finite or +inf, never NaN.
  std::ranges::stable_sort(disagreeing, std::greater{}, &prf::PointRhat::rhat);
  nlohmann::ordered_json out = nlohmann::ordered_json::array();
  for (const prf::PointRhat* point : disagreeing) {
    nlohmann::ordered_json entry;
    entry["point"] = point->point;
    if (trace_points != nullptr && point->point < trace_points->size())
      entry["at"] = (*trace_points)[point->point];
    entry["rhat"] = RhatJson(point->rhat);
    entry["black"] = point->black;
    out.push_back(std::move(entry));
  }
  return out;
}

void RunRhat(const RhatCliOptions& o) {
  std::vector<LoadedRun> runs;
  for (const std::string& dir : o.runs) runs.push_back(LoadRun(dir));
  const bool by_fingerprint = std::ranges::all_of(
      runs, [](const LoadedRun& run) { return run.summary.contains("data_fingerprint"); });
  const LoadedRun& first = runs.front();
  const Target first_target = TargetOf(first, by_fingerprint);
  const LoadedRun* traced = nullptr;  // the first run whose summary lists its trace points
  for (const LoadedRun& run : runs) {
    const Target target = TargetOf(run, by_fingerprint);
    for (std::size_t k = 0; k < target.size(); ++k) {
      const auto& [key, value] = target[k];
      const nlohmann::json& first_value = first_target[k].second;
      if (value != first_value)
        throw UserError(
            fmt::format("{} maps another posterior than {}: its {} is {}, not {} (pool runs of one "
                        "posterior only)",
                        run.pooled.name, first.pooled.name, key, value.dump(), first_value.dump()));
    }
    if (run.trace_points.is_null()) continue;
    if (traced == nullptr) traced = &run;
    if (run.trace_points != traced->trace_points)
      throw UserError(
          fmt::format("{} traced other points than {}", run.pooled.name, traced->pooled.name));
  }
  std::vector<prf::PooledRun> pooled_runs;
  for (LoadedRun& run : runs) pooled_runs.push_back(std::move(run.pooled));
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
    out["disagreeing_points"] = DisagreeingPoints(r, traced ? &traced->trace_points : nullptr);
  } else {
    out["rhat"]["point_colours"] = nullptr;
    out["rhat"]["why_no_point_colours"] =
        "not every run wrote point_traces.csv (runs made before it existed pool their "
        "log-posterior only)";
  }
  out["runs"] = nlohmann::ordered_json::array();
  std::size_t chain = 0;
  for (const prf::PooledRun& run : pooled_runs) {
    nlohmann::ordered_json entry;
    entry["run"] = run.name;
    entry["chain_seeds"] = run.chain_seeds;
    entry["second_half_means"] = nlohmann::ordered_json::array();
    for (std::size_t c = 0; c < run.traces.log_posterior.size(); ++c)
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
