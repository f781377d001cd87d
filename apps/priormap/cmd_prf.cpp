// priormap prf: polygonal random fields (Paskin & Thrun). Without a subcommand it maps a
// localized laser log (posterior chains, estimates, R̂, optional annealed MAP map);
// `prior-stats` samples the Arak prior with no data and compares the chain with the process's
// closed forms.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <unistd.h>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include <priormap/core/binary_io.hpp>
#include <priormap/core/file_io.hpp>
#include <priormap/core/log_io.hpp>
#include <priormap/core/map_server.hpp>
#include <priormap/prf/chain_checkpoint.hpp>
#include <priormap/prf/mapping.hpp>
#include <priormap/prf/moves.hpp>
#include <priormap/prf/polygon_map.hpp>
#include <priormap/prf/pooled_rhat.hpp>
#include <priormap/prf/prior_stats.hpp>
#include <priormap/prf/rhat.hpp>
#include <priormap/prf/sonar_mapping.hpp>
#include <priormap/prf/sonar_model_io.hpp>
#include <priormap/render/prf_figures.hpp>

#include "chain_states.hpp"
#include "chains_status.hpp"
#include "cli_support.hpp"
#include "commands.hpp"
#include "directory_lock.hpp"
#include "graceful_stop.hpp"
#include "log_selection.hpp"
#include "prf_posterior_options.hpp"
#include "prf_run_file.hpp"
#include "sensor_choice.hpp"

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

nlohmann::json AcceptanceJson(const prf::MoveCounters& counters) {
  nlohmann::json acceptance;
  for (int t = 0; t < prf::kNumMoveTypes; ++t) {
    const prf::MoveCounter& c = counters[static_cast<std::size_t>(t)];
    acceptance[std::string(prf::MoveTypeName(static_cast<prf::MoveType>(t)))] = {
        {"proposed", c.proposed},
        {"invalid", c.invalid},
        {"accepted", c.accepted},
        {"screened_out", c.screened_out},
        {"rate", c.AcceptanceRate()}};
  }
  return acceptance;
}

nlohmann::json EstimateJson(const prf::Estimate& e, double closed_form) {
  return {{"estimate", e.mean},
          {"se", e.standard_error},
          {"closed_form", closed_form},
          {"z", NumberOrInfinityText(prf::StandardScore(e, closed_form))}};
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
  out["mean_edges_z"] = NumberOrInfinityText(prf::StandardScore(r.edges, r.expected_edges));
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
  out["acceptance"] = AcceptanceJson(r.counters);
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
      ->transform(StepCount())
      ->check(CLI::Range(std::uint64_t{1}, kMaxStepCount))
      ->capture_default_str();
  cmd->add_option("--thin", o->stats.thin, "Sampler steps between recorded states")
      ->transform(StepCount())
      ->check(CLI::Range(std::uint64_t{1}, kMaxStepCount))
      ->capture_default_str();
  cmd->add_option("--burn-in", o->stats.burn_in, "Sampler steps before the first record")
      ->transform(StepCount())
      ->capture_default_str();
  cmd->add_option("--seed", o->stats.seed, "Random seed; the same seed gives the same result")
      ->transform(SeedValue())
      ->capture_default_str();
  cmd->add_option("--distances", o->distances,
                  "Distances d for P(same colour) and the crossings (absolute, < L; default "
                  "0.05, 0.1, 0.2, 0.4 times L)")
      ->delimiter(',')
      ->check(PositiveValue());  // and below --window, checked against it in the run
  cmd->add_option("--moves", o->moves,
                  "Only these move kinds (comma-separated: " + MoveKindList() + ")")
      ->delimiter(',')
      ->check(CLI::Validator(
          [](std::string& name) -> std::string {
            if (prf::ParseMoveKind(name)) return {};
            return fmt::format("unknown move kind '{}' (expected: {})", name, MoveKindList());
          },
          ""));
  cmd->callback([o] { RunPriorStatsCommand(*o); });
}

// The run saved in DIR/run.json, with this session's settings from `session`.
MappingCliOptions RunFromJson(const std::filesystem::path& dir, const MappingCliOptions& session) {
  const std::filesystem::path path = dir / "run.json";
  if (!std::filesystem::exists(path))
    throw UserError(
        fmt::format("--resume {}: no run.json there (not the output directory of a "
                    "priormap prf run)",
                    dir.string()));
  MappingCliOptions o = ReadRunFile(path, session);
  if (std::filesystem::exists(dir / "summary.json") &&
      !std::filesystem::exists(dir / "checkpoints"))
    throw UserError(
        fmt::format("--resume {}: the run is complete (its summary.json is written); "
                    "nothing to resume",
                    dir.string()));
  o.out = dir.string();
  return o;
}

// One status line: redrawn in place on a terminal, every 10 % elsewhere.
class MappingStatus {
 public:
  MappingStatus() : terminal_(isatty(fileno(stderr)) != 0) {}
  void operator()(const prf::MappingProgress& p) {
    const auto percent =
        static_cast<int>(100 * p.steps_done / std::max<std::uint64_t>(1, p.steps_total));
    if (!terminal_ && percent / 10 == last_percent_ / 10 && p.steps_done != p.steps_total) return;
    if (percent == last_percent_ && p.steps_done != p.steps_total) return;
    last_percent_ = percent;
    // The rates are recent ones, not since the start: a stage on the full data costs several
    // times a thinned one, and a running average would hide the change for long.
    if (!started_) {
      rate_.Add(0.0, p.steps_resumed);
      started_ = true;
    }
    if (p.steps_done == p.steps_resumed) {  // the report of what the checkpoints restored
      fmt::print(stderr, "{:3d}% restored from the checkpoints\n", percent);
      return;
    }
    const prf::MoveCounter total = prf::Total(p.counters);
    prf::MoveCounter interval;
    interval.proposed = total.proposed - last_total_.proposed;
    interval.accepted = total.accepted - last_total_.accepted;
    const std::string line = fmt::format("{:3d}% {:.0f}k proposals/s, acceptance {:.1f}%, {}",
                                         percent, rate_.Add(p.seconds, p.steps_done) / 1e3,
                                         100.0 * interval.AcceptanceRate(), MappingState(p));
    last_total_ = total;
    // Erased to the line's end: a line shorter than the last must not keep the last one's tail.
    if (terminal_)
      fmt::print(stderr, "\r{}\x1b[K{}", line, p.steps_done == p.steps_total ? "\n" : "");
    else
      fmt::print(stderr, "{}\n", line);
  }

 private:
  bool terminal_;
  int last_percent_ = -1;
  bool started_ = false;
  RecentRate rate_;
  // A resumed run's counters hold the restored steps' too, so its first line's acceptance is
  // over the whole run so far; later lines are exact.
  prf::MoveCounter last_total_;
};

// The run's readings, laser beams or sonar cones (--sensor), as RunMapping takes them.
struct SelectedData {
  prf::MappingData mapping;
  bool sonar = false;
  std::size_t readings = 0;
  std::vector<Vec2> sensors;
  double max_range = 0.0;
};

SelectedData SelectData(const Log& log, const MappingCliOptions& o) {
  SelectedData d;
  const std::size_t end = o.selection.end_scan.value_or(log.scans.size());
  d.sonar = ResolveSensor(o.sensor, log, o.selection.first_scan, end) == Sensor::kSonar;
  if (d.sonar) {
    // Laser options a sonar run would drop without a word: refused, so that a run does what
    // its run.json says.
    if (o.selection.beam_step != 1)
      throw UserError(
          fmt::format("--beam-step {} is for laser scans: a sonar run uses every "
                      "reading of each ring (thin the rings with --range)",
                      o.selection.beam_step));
    if (o.sigma_given || o.mapping.model.sigma != prf::LaserModel{}.sigma)
      throw UserError(
          fmt::format("--sigma {} is the laser beam model's noise: a sonar run takes "
                      "its noise from the sonar model (--sonar-model)",
                      o.mapping.model.sigma));
    const auto sonar = std::make_shared<const prf::SonarData>(
        ValueOrThrow(prf::SelectSonarReadings(log, {.first_scan = o.selection.first_scan,
                                                    .end_scan = o.selection.end_scan,
                                                    .max_range = o.selection.max_range})));
    const prf::SonarModel model = o.sonar_model.empty()
                                      ? prf::SonarModel{}
                                      : ValueOrThrow(prf::ReadSonarModel(o.sonar_model));
    d.mapping = prf::SonarMappingData(sonar, model, o.mapping);
    d.readings = sonar->readings.size();
    d.sensors = sonar->sensors;
    d.max_range = sonar->max_range;
    return d;
  }
  if (!o.sonar_model.empty())
    throw UserError("--sonar-model " + o.sonar_model +
                    " is for sonar rings; this run maps laser beams");
  const auto laser =
      std::make_shared<const prf::LaserData>(ValueOrThrow(prf::SelectBeams(log, o.selection)));
  if (const std::string problem = o.mapping.model.Problem(); !problem.empty())
    throw UserError("laser model: " + problem);
  d.mapping = prf::LaserMappingData(laser, o.mapping);
  d.readings = laser->beams.size();
  d.sensors = laser->sensors;
  d.max_range = laser->max_range;
  return d;
}

// A new run in this directory: what an earlier one left (its checkpoints, or the figures of
// chains or a MAP map this run will not make) would be taken for this one's. Only the names a
// run writes are removed.
void RemoveEarlierRunOutputs(const std::filesystem::path& dir) {
  // Listed before anything is removed, and matched by name alone, so that no other entry (a
  // looping link, say) is even looked at.
  std::vector<std::filesystem::path> outputs = NumberedFiles(dir, "chain", ".png");
  for (auto& state : NumberedFiles(dir, "chain", "_last.geojson"))
    outputs.push_back(std::move(state));
  for (const char* file :
       {"summary.json", "trace.csv", "point_traces.csv", "posterior.png", "posterior.pgm",
        "posterior.yaml", "not_white.png", "chains_disagree.png", "map.geojson", "map.svg",
        "map.png", "map.pgm", "map.yaml"})
    outputs.push_back(dir / file);
  try {
    std::filesystem::remove_all(dir / "checkpoints");
    for (const auto& file : outputs) std::filesystem::remove(file);
  } catch (const std::filesystem::filesystem_error& e) {
    throw UserError(fmt::format("-o {}: cannot remove the earlier run's {}: {}", dir.string(),
                                e.path1().string(), e.code().message()));
  }
}

// The log and the sonar model file, which run.json names and a resume reads again.
std::string RunFiles(const MappingCliOptions& o) {
  return o.sonar_model.empty()
             ? fmt::format("the log {}", o.log)
             : fmt::format("the log {} or the sonar model {}", o.log, o.sonar_model);
}

// How to give up a run's checkpoints for a new run in its directory.
std::string StartAgain(const std::string& dir) {
  return fmt::format(
      "or remove {0}/checkpoints and start a new run there (priormap prf with the "
      "options in {0}/run.json)",
      dir);
}

// A resumed run's data and options as this priormap hashes them against what run.json recorded
// when the run started: checkpoints that cannot match are refused before any is read, saying
// why. (Run files written before the record are judged by the checkpoints alone.)
void RequireTheRunStartedWith(const MappingCliOptions& o, const prf::MappingData& data) {
  if (!o.started_with) return;
  if (o.started_with->data != data.data_fingerprint)
    throw UserError(fmt::format(
        "--resume {0}: the run's data are not those it started with: {1} changed since, or "
        "{0}/run.json was edited (or this priormap, another version than the one that started "
        "the run, reads them otherwise); put them back as they were, {2}",
        o.out, RunFiles(o), StartAgain(o.out)));
  if (o.started_with->run != data.fingerprint)
    throw UserError(fmt::format(
        "--resume {0}: this priormap makes another run of {0}/run.json than the one that started "
        "there: the same data, but other options ({0}/run.json was edited, or another version of "
        "priormap, whose defaults differ, started the run); put run.json back as it was or "
        "continue the run with the priormap that started it, {1}",
        o.out, StartAgain(o.out)));
}

// Why a run cannot resume from a checkpoint, and what to do.
UserError CannotResume(const BinaryFormatError& e, const MappingCliOptions& o) {
  const auto* mismatch = dynamic_cast<const prf::CheckpointMismatchError*>(&e);
  if (mismatch == nullptr)  // damaged
    return UserError(fmt::format(
        "cannot resume: {}; remove that file and resume again: its chain (or, for anneal.ckpt, "
        "the annealing) starts afresh and the run ends as it would have, only the steps the file "
        "held are lost",
        e.what()));
  switch (mismatch->reason()) {
    case prf::CheckpointMismatchError::Reason::kFormatVersion:
      return UserError(
          fmt::format("cannot resume: {}; continue the run with the priormap that started it, {}",
                      e.what(), StartAgain(o.out)));
    case prf::CheckpointMismatchError::Reason::kAnotherRun:
      if (o.started_with)  // the data and options are those run.json recorded
        return UserError(fmt::format(
            "cannot resume: {}: it is not the run {}/run.json describes (copied from another "
            "run's directory?); put back the run's own checkpoints, {}",
            e.what(), o.out, StartAgain(o.out)));
      return UserError(fmt::format(
          "cannot resume: {}: {} or {}/run.json changed since the run started, or another "
          "version of priormap started it; put them back as they were, {}",
          e.what(), RunFiles(o), o.out, StartAgain(o.out)));
    case prf::CheckpointMismatchError::Reason::kAnotherChain:
      break;
  }
  return UserError(fmt::format(
      "cannot resume: {}; put each chain's checkpoint back under its own name, or remove this "
      "one: its chain starts afresh and the run ends as it would have",
      e.what()));
}

// The run (resumed or not) in -o DIR, whose run.json is written, and its outputs.
void RunAndWriteOutputs(const MappingCliOptions& o, const SelectedData& data);

void RunMappingCommand(MappingCliOptions o) {
  const bool resuming = !o.resume.empty();
  // Held to the run's end, and taken before the directory's contents are judged (whether its run
  // is complete, its checkpoints): a running run's are not a stopped one's.
  DirectoryLock lock;
  if (resuming) {
    lock = LockIfExists(o.resume);
    o = RunFromJson(o.resume, o);
  } else {
    ApplyPosteriorOptions(o.posterior, &o.mapping);
  }
  // Before the data are selected: the data's fingerprint, which a checkpoint must match, holds
  // the options as run.json has them.
  if (o.anneal && o.mapping.anneal_steps == 0) o.mapping.anneal_steps = o.mapping.samples;
  if (!o.anneal) o.mapping.anneal_steps = 0;
  // The command line's options (a resumed run's come from run.json, checked as it was read, and
  // set -o).
  if (!resuming && o.log.empty())
    throw UsageError("--log is required (or a subcommand: prior-stats, study, sonar-study)");
  if (!resuming && o.mapping.samples == 0)
    throw UsageError(
        "--samples 0: P(black), R-hat and the annealing's start come from the "
        "samples; at least 1");
  if (o.out.empty()) throw UsageError("-o/--out is required");
  if (!resuming) lock = LockIfExists(o.out);
  // A new run would delete a stopped one's checkpoints, its progress of hours perhaps.
  const std::filesystem::path earlier_checkpoints = std::filesystem::path(o.out) / "checkpoints";
  const auto refuse_a_stopped_run = [&] {
    if (std::error_code ec; !resuming && std::filesystem::is_directory(earlier_checkpoints, ec) &&
                            !std::filesystem::is_empty(earlier_checkpoints, ec))
      throw UserError(fmt::format(
          "-o {0}: it holds a stopped run ({0}/checkpoints); continue it with priormap prf "
          "--resume {0}, or remove {0}/checkpoints to start a new run there",
          o.out));
  };
  refuse_a_stopped_run();
  const Log log = ValueOrThrow(ReadLog(o.log));
  std::tie(o.selection.first_scan, o.selection.end_scan) =
      SelectedScans(ParseScanRange(o.range), log.scans.size());
  const SelectedData data = SelectData(log, o);
  // Each chain keeps rasters of the window at this resolution: too fine a one would end in a
  // bare bad_alloc after the run had started.
  if (const std::string problem =
          prf::RasterSizeProblem(data.mapping.window, o.mapping.raster_resolution);
      !problem.empty())
    throw UserError(fmt::format("--resolution {} m: {}", o.mapping.raster_resolution, problem));
  if (resuming) RequireTheRunStartedWith(o, data.mapping);
  EnsureDirectory(o.out);
  if (!lock.held()) {
    lock = DirectoryLock(o.out);
    // The directory did not exist when it was judged: another run may have made it, and stopped
    // there, since.
    refuse_a_stopped_run();
  }
  const std::filesystem::path dir(o.out);
  if (!resuming) {
    RemoveEarlierRunOutputs(dir);
    o.started_with = {.data = data.mapping.data_fingerprint, .run = data.mapping.fingerprint};
    WriteTextFileAtomically(dir / "run.json", RunJson(o).dump(2) + "\n");
  }
  // Under the lock no other run writes checkpoints here: the temporaries of checkpoint writes
  // killed mid-way are stale, whatever process their PID names now (RunMapping keeps those of
  // PIDs that run). Unlocked (a file system without locks), RunMapping's check alone.
  if (lock.held()) prf::RemoveCheckpointTemporariesOfEndedWriters(dir / "checkpoints");
  fmt::print(stderr, "{} {} from {} sensor positions, R = {} m\n", data.readings,
             data.sonar ? "sonar readings" : "beams", data.sensors.size(), data.max_range);
  // A write that fails (a full disk, a directory made read-only) loses nothing: the checkpoints
  // written stay (each replaced whole or not at all), and a complete run's go only once its
  // outputs are written.
  const auto resumable = [&](const std::exception& e) {
    return UserError(
        fmt::format("{}; the run's checkpoints are kept: once {} can be written, "
                    "continue it with: priormap prf --resume {}",
                    e.what(), o.out, o.out));
  };
  try {
    RunAndWriteOutputs(o, data);
  } catch (const IoError& e) {
    throw resumable(e);
  } catch (const std::filesystem::filesystem_error& e) {
    throw resumable(e);
  }
}

void RunAndWriteOutputs(const MappingCliOptions& o, const SelectedData& data) {
  const std::filesystem::path dir(o.out);
  const prf::MappingSession session{.checkpoint_directory = dir / "checkpoints",
                                    .checkpoint_every_s = o.checkpoint_every_s,
                                    .resume = !o.resume.empty(),
                                    .stop_after_steps = o.stop_after_steps,
                                    .stop = &StopFlag()};
  MappingStatus status;
  prf::MappingResult r;
  {
    const StopOnSignals stop_on_signals;
    try {
      r = prf::RunMapping(data.mapping, o.mapping, std::ref(status), session);
    } catch (const BinaryFormatError& e) {
      throw CannotResume(e, o);
    } catch (const prf::CheckpointReadError& e) {
      throw UserError(fmt::format("cannot resume: {}", e.what()));
    }
  }
  if (r.resumed_steps > 0)
    fmt::print(stderr, "resumed {} steps from {}\n", r.resumed_steps,
               session.checkpoint_directory.string());
  if (!r.complete) {
    fmt::print("stopped and checkpointed in {}; continue with: priormap prf --resume {}\n",
               session.checkpoint_directory.string(), o.out);
    if (StopRequested()) ExitAsStopped();
    return;
  }

  // The run's rasters share one grid.
  const auto on_raster = [&](const Eigen::MatrixXd& values) {
    return prf::SquareCellRaster(values, r.raster);
  };
  const bool several_chains = r.chains.size() > 1;
  const OccupancyRaster posterior = on_raster(r.black_fraction);
  WriteMapServerMap(dir / "posterior.yaml", posterior);
  render::SaveProbabilityFigure(dir / "posterior.png", posterior,
                                fmt::format("PRF posterior P(black), p = {}", o.mapping.sampler.p),
                                data.sensors);
  render::SaveProbabilityFigure(dir / "not_white.png",
                                on_raster((1.0 - r.white_fraction.array()).matrix()),
                                "PRF: 1 - P(cell completely white)", data.sensors);
  if (several_chains)
    render::SaveProbabilityFigure(dir / "chains_disagree.png", on_raster(r.chain_spread),
                                  "PRF: where the chains disagree", data.sensors,
                                  "max - min P(black) over chains");
  const auto chain_figure = [](std::size_t c) { return fmt::format("chain{}.png", c); };
  // Each chain's own map, to see which chain holds what where they disagree, and its last
  // state, to see exactly which structures differ.
  for (std::size_t c = 0; several_chains && c < r.chains.size(); ++c) {
    render::SaveProbabilityFigure(dir / chain_figure(c), on_raster(r.chains[c].black_fraction),
                                  fmt::format("PRF chain {}: P(black)", c), data.sensors);
    if (r.chains[c].last) SaveChainState(dir, c, *r.chains[c].last, r.window);
  }
  // The traces behind R̂, with each trace point's colour, so that `prf rhat` can pool the
  // chains of several runs as this run pools its own.
  prf::RunTraces traces;
  for (std::size_t i = 0; i < r.chains[0].log_posterior_trace.size(); ++i)
    traces.samples.push_back((i + 1) * o.mapping.trace_every);
  for (const prf::ChainSummary& chain : r.chains) {
    traces.log_posterior.push_back(chain.log_posterior_trace);
    traces.point_colours.push_back(chain.point_traces);
  }
  WriteTextFileAtomically(dir / "trace.csv", prf::FormatLogPosteriorTrace(traces));
  WriteTextFileAtomically(dir / "point_traces.csv", prf::FormatPointTraces(traces));

  nlohmann::json summary;
  summary["log"] = std::filesystem::absolute(o.log).string();
  summary["resumed_steps"] = r.resumed_steps;
  summary["range"] = o.range;
  summary["sensor"] = data.sonar ? "sonar" : "laser";
  summary["beams"] = data.readings;  // sonar: readings (cones)
  summary["sensor_positions"] = data.sensors.size();
  // Of the readings and the data model, not of the log's name: `prf rhat` pools by it.
  summary["data_fingerprint"] = fmt::format("{:016x}", data.mapping.data_fingerprint);
  summary["p"] = o.mapping.sampler.p;
  summary["posterior"] = PosteriorOptionsJson(o.mapping);
  summary["seed"] = o.mapping.seed;
  summary["chains"] = o.mapping.chains;
  summary["samples"] = o.mapping.samples;
  summary["burn_in"] = o.mapping.burn_in;
  summary["window"] = {r.window.min.x(), r.window.min.y(), r.window.max.x(), r.window.max.y()};
  summary["wall_time_s"] = r.wall_time_s;
  summary["proposals"] = r.proposals;
  summary["proposals_per_second"] = r.ProposalsPerSecond();
  summary["rhat"] = {{"log_posterior", NumberOrInfinityText(r.rhat_log_posterior)},
                     {"point_colours", NumberOrInfinityText(r.rhat_point_colours)},
                     {"points", r.trace_points.size()}};
  summary["trace_points"] = nlohmann::json::array();
  for (const Vec2& point : r.trace_points)
    summary["trace_points"].push_back({point.x(), point.y()});
  if (several_chains) {
    // The area where the chains' P(black) differ by more than a half: where they hold
    // different maps, which R̂ only summarizes.
    const double cell_area = r.raster.cell.x() * r.raster.cell.y();
    summary["chain_disagreement"] = {
        {"area_over_half_m2",
         static_cast<double>((r.chain_spread.array() > 0.5).count()) * cell_area},
        {"largest", r.chain_spread.maxCoeff()}};
  }
  prf::MoveCounters total{};
  summary["log_posterior"] = nlohmann::json::array();
  summary["log_prior"] = nlohmann::json::array();
  summary["log_likelihood"] = nlohmann::json::array();
  // Where each chain settled: R̂ says that the chains are apart, these say which one.
  const bool rhat_defined = !std::isnan(r.rhat_log_posterior);
  std::vector<double> second_half_means;
  if (rhat_defined) {
    for (const prf::ChainSummary& chain : r.chains)
      second_half_means.push_back(prf::SecondHalfMean(chain.log_posterior_trace));
    summary["log_posterior_second_half_means"] = second_half_means;
  }
  for (const prf::ChainSummary& chain : r.chains) {
    summary["log_posterior"].push_back(chain.log_posterior);
    summary["log_prior"].push_back(chain.log_prior);
    summary["log_likelihood"].push_back(chain.log_likelihood);
    prf::AddCounters(&total, chain.counters);
  }
  summary["acceptance"] = AcceptanceJson(total);
  summary["edges"] = nlohmann::json::array();
  for (const prf::ChainSummary& chain : r.chains) summary["edges"].push_back(chain.edges);
  if (o.mapping.burn_in_replicas > 1) {
    summary["swap_rates"] = nlohmann::json::array();
    for (const prf::ChainSummary& chain : r.chains)
      summary["swap_rates"].push_back(prf::SwapRates(chain.swaps));
  }
  std::string outputs =
      "summary.json, posterior.png, posterior.pgm, posterior.yaml, not_white.png, trace.csv, "
      "point_traces.csv";
  if (several_chains) {
    outputs += ", chains_disagree.png";
    for (std::size_t c = 0; c < r.chains.size(); ++c)
      outputs += ", " + chain_figure(c) + (r.chains[c].last ? ", " + ChainStateFile(c) : "");
  }
  if (r.map) {
    const auto faces = prf::ExtractFaces(*r.map);
    const std::string geojson = prf::FacesToGeoJson(faces, r.window);
    WriteTextFileAtomically(dir / "map.geojson", geojson);
    render::SaveFacesFigure(dir / "map.svg", faces, r.window, "PRF MAP map (annealed)");
    render::SaveFacesFigure(dir / "map.png", faces, r.window, "PRF MAP map (annealed)");
    const OccupancyRaster map_raster =
        prf::SquareCellRaster(prf::ColourRaster(*r.map, r.raster), r.raster);
    WriteMapServerMap(dir / "map.yaml", map_raster);
    summary["map"] = {{"log_posterior", r.map_log_posterior},
                      {"edges", r.map->stats().edges},
                      {"geojson_bytes", geojson.size()},
                      {"compact_bytes", prf::CompactMapBytes(*r.map)},
                      {"raster_pgm_bytes", std::filesystem::file_size(dir / "map.pgm")}};
    outputs += ", map.geojson, map.svg, map.png, map.pgm, map.yaml";
  }
  WriteTextFileAtomically(dir / "summary.json", summary.dump(2) + "\n");
  // The outputs are final; the checkpoints (megabytes per chain) are no longer needed.
  RemoveFinishedCheckpoints(session.checkpoint_directory);
  fmt::print(
      "wrote {} ({}): R-hat {:.3f} (log posterior), {:.3f} (point colours), {:.0f}k "
      "proposals/s\n",
      o.out, outputs, r.rhat_log_posterior, r.rhat_point_colours,
      summary["proposals_per_second"].get<double>() / 1e3);
  // Chains that have not mixed give estimates that depend on the seed, which the maps
  // themselves do not show. R̂ is NaN when there were too few records to compute it.
  if (!rhat_defined) {
    fmt::print(stderr,
               "priormap: warning: too few trace records for R-hat, so convergence is not "
               "checked: --samples must be at least 4 times --trace-every\n");
  } else if (!(r.rhat_log_posterior < prf::kConvergedRhat &&
               r.rhat_point_colours < prf::kConvergedRhat)) {
    fmt::print(stderr,
               "priormap: warning: the chains have not converged (R-hat not below {}): the "
               "estimates depend on the seed; run longer (--burn-in, --samples), or pool the "
               "chains of more runs with `priormap prf rhat`, which also lists the trace points "
               "where the chains disagree\n",
               prf::kConvergedRhat);
    // A chain hundreds of nats below the others holds a poorer map: the pooled maps average
    // it in, and its own figure shows what it lacks.
    if (several_chains) {
      std::vector<std::string> means;
      for (std::size_t c = 0; c < r.chains.size(); ++c)
        means.push_back(fmt::format("{:.1f} ({})", second_half_means[c], chain_figure(c)));
      fmt::print(stderr,
                 "priormap: the chains' mean log-posteriors over the second half of their "
                 "samples: {}\n",
                 fmt::join(means, ", "));
    }
  }
}

void AddMappingOptions(CLI::App& cmd, const std::shared_ptr<MappingCliOptions>& o) {
  cmd.add_option("--log", o->log, "Localized laser log (CARMEN or priormap JSON, .gz or not)");
  cmd.add_option("--range", o->range, "Scans a:b of the log (b exclusive; a: or :b)")
      ->check(ParsedBy("--range", ParseScanRange))
      ->capture_default_str();
  cmd.add_option("--sensor", o->sensor,
                 "Map from laser beams or sonar cones; auto: sonar when the scans are sonar rings")
      ->check(CLI::IsMember({"auto", "laser", "sonar"}))
      ->capture_default_str();
  cmd.add_option("--sonar-model", o->sonar_model,
                 "Sonar model file (priormap.sonar_model JSON, e.g. from prf fit-sonar); "
                 "default: the built-in parameters (docs/sonar.md)");
  cmd.add_option("--beam-step", o->selection.beam_step, "Use every k-th beam of each scan")
      ->check(CLI::Range(std::size_t{1}, std::size_t{100000}))
      ->capture_default_str();
  cmd.add_option("--max-range", o->selection.max_range,
                 "R: readings at or above it are max-range readings, m")
      ->check(PositiveValue())
      ->capture_default_str();
  cmd.add_option("-o,--out", o->out, "Output directory");
  prf::MappingOptions& m = o->mapping;
  cmd.add_option("--p", m.sampler.p, "Scale parameter p of the Arak prior (1/m)")
      ->check(PositiveValue())
      ->capture_default_str();
  cmd.add_option("--samples", m.samples, "Steps recorded per chain after the burn-in")
      ->transform(StepCount())
      ->capture_default_str();
  cmd.add_option("--burn-in", m.burn_in, "Steps per chain before recording")
      ->transform(StepCount())
      ->capture_default_str();
  cmd.add_option("--chains", m.chains, "Chains run in parallel")
      ->check(CLI::Range(1, 256))
      ->capture_default_str();
  cmd.add_option("--seed", m.seed, "Random seed; the same seed gives the same result")
      ->transform(SeedValue())
      ->capture_default_str();
  cmd.add_flag("--anneal", o->anneal, "Anneal the best chain to a MAP polygonal map");
  cmd.add_option("--anneal-steps", m.anneal_steps, "Annealing steps (default: --samples)")
      ->transform(StepCount());
  cmd.add_option("--sigma", m.model.sigma, "Range noise of the beam model, m")
      ->check(PositiveValue())
      ->capture_default_str();
  cmd.add_option("--guided-births", m.sampler.weights[prf::MoveKind::kGuidedTriangle],
                 "Weight of the guided triangle births, which put an edge along the readings' end "
                 "points (the other kinds weigh 0.5 to 2); 0 switches them off")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd.add_option("--guide-jitter", m.guide_jitter,
                 "Half-width of the squares around the end points where guided births put their "
                 "vertices, m")
      ->check(PositiveValueUpTo(100.0, "m"))
      ->capture_default_str();
  cmd.add_option("--cell-size", m.cell_size, "Cell of the edge and beam indices, m")
      ->check(PositiveValue())
      ->capture_default_str();
  cmd.add_option("--resolution", m.raster_resolution, "Cell of the output rasters, m")
      ->check(PositiveValue())
      ->capture_default_str();
  cmd.add_option("--trace-every", m.trace_every, "Steps between trace records (R-hat)")
      ->transform(StepCount())
      ->check(CLI::Range(std::uint64_t{1}, kMaxStepCount))
      ->capture_default_str();
  AddPosteriorOptions(cmd, m, o->posterior);
  cmd.add_flag("--check", m.sampler.check_invariants,
               "Debug: after every accepted move, check the coloring and the incremental "
               "likelihood against recomputation (slow)");
  cmd.add_option("--resume", o->resume,
                 "Continue the stopped run whose output directory is DIR, with its options (from "
                 "DIR/run.json) and checkpoints; the result is that of the uninterrupted run")
      ->option_text("DIR");
  cmd.add_option("--checkpoint-every", o->checkpoint_every_s,
                 "Seconds between a chain's checkpoints (in -o DIR/checkpoints)")
      ->check(PositiveValue())
      ->capture_default_str();
  cmd.add_option("--stop-after-steps", o->stop_after_steps,
                 "Stop each chain (and the annealing), checkpointed, after this many steps in this "
                 "session, to split a long run into sessions; 0: no limit")
      ->transform(StepCount())
      ->capture_default_str();
}

}  // namespace

void AddPrfCommand(CLI::App& app) {
  auto o = std::make_shared<MappingCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "prf",
      "Polygonal random field map of a localized laser or sonar log (Paskin & Thrun): posterior "
      "chains, P(black), R-hat, --anneal for a MAP polygon map; or the subcommands prior-stats, "
      "study, sonar-study, fit-sonar, rhat");
  cmd->require_subcommand(0, 1);
  AddMappingOptions(*cmd, o);
  AddPriorStats(*cmd);
  AddPrfStudyCommand(*cmd);
  AddPrfSonarStudyCommand(*cmd);
  AddPrfFitSonarCommand(*cmd);
  AddPrfRhatCommand(*cmd);
  cmd->callback([o, cmd] {
    if (!cmd->get_subcommands().empty()) return;
    o->sigma_given = cmd->get_option("--sigma")->count() > 0;
    if (!o->resume.empty()) {
      // The run's own options come from DIR/run.json; another value would make another run.
      for (const CLI::Option* option : cmd->get_options()) {
        const std::string name = option->get_name();
        if (option->count() == 0 || name == "--resume" || name == "--checkpoint-every" ||
            name == "--stop-after-steps" || name == "--help")
          continue;
        throw UserError(
            fmt::format("{} cannot be combined with --resume (the run's options are "
                        "those in {}/run.json)",
                        name, o->resume));
      }
    }
    RunMappingCommand(*o);
  });
}

}  // namespace priormap::app
