#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <string>

#include <fmt/format.h>
#include <tbb/parallel_for.h>
#include <tbb/task_group.h>

#include <priormap/core/binary_io.hpp>
#include <priormap/core/check.hpp>
#include <priormap/core/rng.hpp>
#include <priormap/prf/chain_checkpoint.hpp>
#include <priormap/prf/estimates.hpp>
#include <priormap/prf/laser_likelihood.hpp>
#include <priormap/prf/mapping.hpp>
#include <priormap/prf/rhat.hpp>
#include <priormap/prf/weighted_data_term.hpp>

namespace priormap::prf {
namespace {

using Clock = std::chrono::steady_clock;

// The annealing's temperature falls from 1 to its final value in this many stages.
constexpr std::uint64_t kAnnealStages = 100;

std::uint64_t AnnealStageSteps(const MappingOptions& options) {
  return std::max<std::uint64_t>(1, options.anneal_steps / kAnnealStages);
}

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

// Points whose colours enter R̂: for evenly spread beams that hit something, one point midway
// (seen free) and one 0.1 m behind the hit (likely occupied, often uncertain).
std::vector<Vec2> TracePoints(const LaserData& data, const Window& window, int count) {
  std::vector<std::size_t> hits;
  for (std::size_t i = 0; i < data.beams.size(); ++i)
    if (!data.beams[i].max_reading) hits.push_back(i);
  std::vector<Vec2> points;
  if (hits.empty() || count <= 0) return points;
  const int pairs = std::max(1, count / 2);
  for (int k = 0; k < pairs; ++k) {
    const LaserBeam& beam = data.beams[hits[static_cast<std::size_t>(k) * hits.size() /
                                            static_cast<std::size_t>(pairs)]];
    for (double along : {0.5 * beam.range, beam.range + 0.1}) {
      const Vec2 p = beam.origin + along * beam.direction;
      if (window.ContainsInterior(p)) points.push_back(p);
    }
  }
  return points;
}

// The end points of the readings that hit something, inside the window: the guide points of
// the guided triangle births.
std::vector<Vec2> HitPoints(const LaserData& data, const Window& window) {
  std::vector<Vec2> points;
  for (const LaserBeam& beam : data.beams) {
    if (beam.max_reading) continue;
    const Vec2 p = beam.origin + beam.range * beam.direction;
    if (window.ContainsInterior(p)) points.push_back(p);
  }
  return points;
}

}  // namespace

std::string RasterSizeProblem(const Window& window, double resolution) {
  const double cells =
      std::ceil(window.Width() / resolution) * std::ceil(window.Height() / resolution);
  if (cells <= kMaxRasterCells) return {};
  return fmt::format(
      "the {:.1f} m x {:.1f} m window would make rasters of {:.3g} cells, more "
      "than {:.0e}",
      window.Width(), window.Height(), cells, kMaxRasterCells);
}

std::uint64_t AnnealingSteps(const MappingOptions& options) {
  return options.anneal_steps == 0 ? 0 : kAnnealStages * AnnealStageSteps(options);
}

double MappingResult::ProposalsPerSecond() const {
  const double seconds = sampling_time_s + annealing_time_s;
  return seconds > 0.0 ? static_cast<double>(proposals) / seconds : 0.0;
}

WarmStage WarmStageOf(const MappingOptions& options) {
  if (options.warm_burn_in.temperature == 1.0 || options.warm_burn_in.steps == 0) return {};
  std::uint64_t begin = 0;
  for (const ThinnedBurnIn& stage : options.thinned_burn_in) begin += stage.steps;
  return {begin, begin + options.warm_burn_in.steps};
}

double BurnInTemperature(const MappingOptions& options, std::uint64_t step) {
  const WarmStage warm = WarmStageOf(options);
  const double floor =
      warm.begin <= step && step < warm.end ? options.warm_burn_in.temperature : 1.0;
  const std::uint64_t cooling = options.burn_in / 2;
  if (options.burn_in_temperature == 1.0 || step >= cooling) return floor;
  const std::uint64_t block = step / kTemperatureBlock * kTemperatureBlock;
  return std::max(floor, std::pow(options.burn_in_temperature,
                                  1.0 - static_cast<double>(block) / static_cast<double>(cooling)));
}

std::uint64_t BurnInTemperatureEnd(const MappingOptions& options, std::uint64_t step) {
  std::uint64_t end = std::numeric_limits<std::uint64_t>::max();
  const std::uint64_t cooling = options.burn_in / 2;
  if (options.burn_in_temperature != 1.0 && step < cooling)
    end = std::min(cooling, (step / kTemperatureBlock + 1) * kTemperatureBlock);
  const WarmStage warm = WarmStageOf(options);
  if (step < warm.begin)
    end = std::min(end, warm.begin);
  else if (step < warm.end)
    end = std::min(end, warm.end);
  return end;
}

bool KeptByThinning(std::size_t i, int stride, int phase) {
  return stride <= 1 ||
         SplitMix64(i) % static_cast<std::uint64_t>(stride) == static_cast<std::uint64_t>(phase);
}

BurnInStage BurnInStageAt(const MappingOptions& options, std::uint64_t step) {
  std::uint64_t end = 0;
  if (step < options.burn_in)
    for (const ThinnedBurnIn& stage : options.thinned_burn_in) {
      const std::uint64_t begin = end;
      end += stage.steps;
      if (step >= end || end > options.burn_in) continue;
      if (options.thinned_rotation == 0 || stage.stride == 1) return {stage.stride, 0, end};
      const std::uint64_t turn = (step - begin) / options.thinned_rotation;
      const auto phase = static_cast<int>(turn % static_cast<std::uint64_t>(stage.stride));
      return {stage.stride, phase, std::min(end, begin + (turn + 1) * options.thinned_rotation)};
    }
  return {1, 0, std::numeric_limits<std::uint64_t>::max()};
}

MappingData LaserMappingData(std::shared_ptr<const LaserData> data, const MappingOptions& options) {
  MappingData d;
  d.window = WindowAround(*data, options.margin);
  d.trace_points = TracePoints(*data, d.window, options.trace_points);
  d.guide_points = HitPoints(*data, d.window);
  d.fingerprint = RunFingerprint(*data, options);
  d.data_fingerprint = LaserDataFingerprint(*data, options.model);
  d.make_data_term = [data, model = options.model, cell_size = options.cell_size] {
    return std::make_unique<LaserLikelihood>(data, model, cell_size);
  };
  d.make_thinned_data_term = [data, model = options.model, cell_size = options.cell_size](
                                 int stride, int phase) {
    auto thinned = std::make_shared<LaserData>();
    thinned->sensors = data->sensors;  // every sensor stays in white
    thinned->max_range = data->max_range;
    for (std::size_t i = 0; i < data->beams.size(); ++i)
      if (KeptByThinning(i, stride, phase)) thinned->beams.push_back(data->beams[i]);
    return std::make_unique<LaserLikelihood>(std::move(thinned), model, cell_size);
  };
  return d;
}

MappingResult RunMapping(std::shared_ptr<const LaserData> data, const MappingOptions& options,
                         const std::function<void(const MappingProgress&)>& progress,
                         const MappingSession& session) {
  return RunMapping(LaserMappingData(std::move(data), options), options, progress, session);
}

namespace {

// The contracts of the options and the data, checked before anything runs.
void CheckRunOptions(const MappingData& data, const MappingOptions& run_options) {
  PRIORMAP_CHECK(run_options.chains >= 1, "at least one chain");
  PRIORMAP_CHECK(
      run_options.burn_in_temperature >= 1.0 && std::isfinite(run_options.burn_in_temperature),
      "the burn-in temperature must be finite and at least 1");
  std::uint64_t thinned_steps = 0;
  for (const ThinnedBurnIn& stage : run_options.thinned_burn_in) {
    PRIORMAP_CHECK(stage.stride >= 1, "a thinned burn-in stride must be at least 1");
    // Saturating, so that stages whose sum would wrap cannot pass as a short burn-in.
    thinned_steps +=
        std::min(stage.steps, std::numeric_limits<std::uint64_t>::max() - thinned_steps);
  }
  PRIORMAP_CHECK(thinned_steps <= run_options.burn_in,
                 "the thinned burn-in stages must fit in the burn-in");
  PRIORMAP_CHECK(run_options.warm_burn_in.temperature >= 1.0 &&
                     std::isfinite(run_options.warm_burn_in.temperature),
                 "the warm burn-in's temperature must be finite and at least 1");
  PRIORMAP_CHECK(run_options.warm_burn_in.steps <= run_options.burn_in - thinned_steps,
                 "the warm burn-in must fit in the burn-in after the thinned stages");
  PRIORMAP_CHECK(thinned_steps == 0 || data.make_thinned_data_term,
                 "these data offer no thinned data term for the thinned burn-in");
  const int screen_stride = run_options.sampler.screen_stride;
  PRIORMAP_CHECK(screen_stride == 1 || data.make_thinned_data_term,
                 "these data offer no thinned data term to screen moves with");
  PRIORMAP_CHECK(run_options.trace_every >= 1 && run_options.chunk >= 1,
                 "positive trace and chunk");
}

// The ladder's temperatures (GeometricLadder checks the count and the top).
std::vector<double> CheckedLadderTemperatures(const MappingOptions& run_options) {
  std::vector<double> ladder_temperatures =
      GeometricLadder(run_options.burn_in_replicas, run_options.replica_temperature);
  PRIORMAP_CHECK(run_options.replica_steps <= run_options.burn_in,
                 "the replicas' steps must fit in the burn-in");
  return ladder_temperatures;
}

// The options with the guide of the guided births, which every sampler (fresh, restored or
// annealing) shares.
MappingOptions WithBirthGuide(const MappingData& data, const MappingOptions& run_options) {
  MappingOptions options = run_options;
  if (!options.sampler.guide && options.sampler.weights[MoveKind::kGuidedTriangle] > 0.0)
    options.sampler.guide = std::make_shared<const BirthGuide>(
        data.guide_points, options.sampler.birth_scale, options.guide_jitter);
  return options;
}

// A run from another start is another run: its checkpoints are not this one's.
std::uint64_t CheckpointFingerprint(const MappingData& data) {
  if (!data.start) return data.fingerprint;
  BinaryWriter out;
  out.Put(data.fingerprint);
  data.start->Save(out);
  return Fnv1a64(out.bytes());
}

// One call of RunMapping, whose steps are its member functions. The fields are the run's state
// that the steps share (RunMapping's locals once), not an interface, hence a struct.
struct MappingRun {
  MappingRun(const MappingData& run_data, const MappingOptions& run_options,
             const std::function<void(const MappingProgress&)>& run_progress,
             const MappingSession& run_session);

  MappingResult Run();

  void RestoreOrStartChain(std::size_t c);
  void MakeLadder(std::size_t c, std::vector<std::unique_ptr<PrfSampler>> hot);
  void RestoreAnnealing();
  void CountRestoredSteps();
  void RunChain(std::size_t c);
  std::uint64_t PrepareChunk(std::size_t c, std::uint64_t s);
  void UseStageData(std::size_t c, const BurnInStage& stage);
  void RecordTraces(std::size_t c, std::uint64_t target);
  void ReportChain(std::size_t c, std::uint64_t steps);
  void FinishChain(std::size_t c);
  void PoolEstimates();
  void ComputeRhat();
  void Anneal();

  std::unique_ptr<DataTerm> MakeLikelihood() const { return data.make_data_term(); }
  // The data term of a thinned stage's share, weighed up by its stride when asked to.
  std::unique_ptr<DataTerm> MakeThinnedLikelihood(const BurnInStage& stage) const {
    std::unique_ptr<DataTerm> term = data.make_thinned_data_term(stage.stride, stage.phase);
    if (!options.thinned_weighed) return term;
    return std::make_unique<WeightedDataTerm>(std::move(term), stage.stride);
  }
  void ScreenIfAsked(PrfSampler& sampler) const;
  std::uint64_t ChainSeed(std::size_t c) const { return SplitMix64(options.seed + c); }
  // The chain: its ladder's cold replica while it has one (whose sampler changes with swaps).
  PrfSampler& Chain(std::size_t c) { return ladders[c] ? ladders[c]->cold() : *samplers[c]; }
  void LeaveLadderIfDone(std::size_t c);
  void Checkpoint(std::size_t c, bool now, Clock::time_point& last_checkpoint);
  void Report();
  bool StopRequested() const;
  std::uint64_t BudgetLeft(std::uint64_t first, std::uint64_t now) const;
  std::uint64_t ThisSession() const { return steps_done.load() - resumed + hot_steps.load(); }

  const MappingData& data;
  const std::function<void(const MappingProgress&)>& progress;
  const MappingSession& session;
  const int screen_stride;
  const std::vector<double> ladder_temperatures;
  const std::uint64_t ladder_end;
  const Clock::time_point start;
  MappingResult result;
  const MappingOptions options;
  const std::size_t chains;
  const std::filesystem::path& checkpoints;
  const std::uint64_t fingerprint;
  SamplerOptions sampler_options;

  std::vector<std::unique_ptr<PrfSampler>> samplers;
  std::vector<std::optional<ReplicaLadder>> ladders;
  const std::size_t hot_replicas;
  std::vector<std::unique_ptr<PosteriorEstimates>> estimates;
  // Bytes, not vector<bool>'s packed bits: the chains write their flags from parallel threads.
  std::vector<std::uint8_t> recording;
  std::vector<std::uint64_t> session_start;

  const std::uint64_t end;
  const std::uint64_t anneal_end;
  std::optional<LoadedAnneal> restored_annealing;
  const std::filesystem::path anneal_path;

  std::mutex progress_mutex;  // guards the progress callback and what it reports
  std::vector<ChainProgress> chain_progress;
  std::vector<MoveCounters> chain_counters;
  std::uint64_t resumed = 0;
  std::atomic<std::uint64_t> steps_done{0};
  std::uint64_t steps_total = 0;
  std::optional<AnnealingProgress> annealing_progress;
  std::atomic<std::uint64_t> hot_steps{0};  // of the replicas other than the chains, this session
  std::atomic<bool> stopped{false};
  // The share of the readings in each chain's data term: samplers are made or restored with
  // every reading.
  struct DataShare {
    int stride = 1;
    int phase = 0;
  };
  std::vector<DataShare> shares;
};

MappingRun::MappingRun(const MappingData& run_data, const MappingOptions& run_options,
                       const std::function<void(const MappingProgress&)>& run_progress,
                       const MappingSession& run_session)
    : data(run_data),
      progress(run_progress),
      session(run_session),
      screen_stride(run_options.sampler.screen_stride),
      ladder_temperatures(CheckedLadderTemperatures(run_options)),
      // Where the ladders end and the chains go on alone.
      ladder_end(run_options.replica_steps == 0 ? run_options.burn_in : run_options.replica_steps),
      start(Clock::now()),
      options(WithBirthGuide(data, run_options)),
      chains(static_cast<std::size_t>(options.chains)),
      checkpoints(session.checkpoint_directory),
      fingerprint(CheckpointFingerprint(data)),
      sampler_options(options.sampler),
      samplers(chains),
      ladders(chains),
      hot_replicas(ladder_temperatures.size() - 1),
      estimates(chains),
      recording(chains, 0),
      session_start(chains, 0),
      end(options.burn_in + options.samples),
      anneal_end(end + AnnealingSteps(options)),
      anneal_path(AnnealCheckpointPath(checkpoints)),
      chain_progress(chains),
      chain_counters(chains),
      shares(chains) {
  result.window = data.window;
  result.trace_points = data.trace_points;
  PRIORMAP_CHECK(!session.resume || !checkpoints.empty(), "resuming needs a checkpoint directory");
  if (!checkpoints.empty()) {
    std::filesystem::create_directories(checkpoints);
    // Checkpoint writes killed mid-way (SIGKILL) leave temporaries that nothing else removes
    // until the run completes.
    RemoveStaleCheckpointTemporaries(checkpoints);
  }
  sampler_options.temperature = 1.0;
  result.chains.resize(chains);
}

MappingResult MappingRun::Run() {
  // Chains from their checkpoints (or afresh), before any runs, so that progress counts them.
  tbb::parallel_for(std::size_t{0}, chains, [&](std::size_t c) { RestoreOrStartChain(c); });
  RestoreAnnealing();
  CountRestoredSteps();
  tbb::parallel_for(std::size_t{0}, chains, [&](std::size_t c) { RunChain(c); });
  result.sampling_time_s = Seconds(start);
  result.proposals = ThisSession();
  if (stopped) {
    result.complete = false;
    result.wall_time_s = Seconds(start);
    return std::move(result);
  }
  PoolEstimates();
  ComputeRhat();
  if (options.anneal_steps > 0) Anneal();
  result.wall_time_s = Seconds(start);
  return std::move(result);
}

// A chain in a replica-exchange burn-in is its ladder's cold replica (samplers[c] is then
// empty) until the ladder ends.
void MappingRun::RestoreOrStartChain(std::size_t c) {
  estimates[c] = std::make_unique<PosteriorEstimates>(result.window, options.raster_resolution);
  result.chains[c].point_traces.assign(result.trace_points.size(), {});
  const auto path = ChainCheckpointPath(checkpoints, c);
  if (session.resume && std::filesystem::exists(path)) {
    LoadedChain loaded = LoadChainCheckpoint(
        path, fingerprint, c, result.window, options, [this] { return MakeLikelihood(); },
        estimates[c].get(), &result.chains[c]);
    const std::uint64_t steps = loaded.sampler->steps();
    if (steps > options.burn_in + options.samples)
      throw BinaryFormatError(path.string() + ": a chain past the run's end");
    // At the ladder's end both are right: a periodic checkpoint after its last round still holds
    // the hot replicas (the chain leaves the ladder at its next step), a stop's has left it.
    const bool consistent = hot_replicas == 0 ? loaded.hot.empty()
                                              : (loaded.hot.size() == hot_replicas &&
                                                 steps <= ladder_end && ladder_end > 0) ||
                                                    (loaded.hot.empty() && steps >= ladder_end);
    if (!consistent)
      throw BinaryFormatError(path.string() + ": a chain with the wrong number of replicas");
    samplers[c] = std::move(loaded.sampler);
    recording[c] = loaded.recording ? 1 : 0;
    if (recording[c]) samplers[c]->ContinueRecordingInto(estimates[c].get());
    if (!loaded.hot.empty()) MakeLadder(c, std::move(loaded.hot));
  } else {
    const auto fresh = [&](std::uint64_t seed) {
      return std::make_unique<PrfSampler>(
          data.start ? *data.start : Coloring(result.window, options.cell_size), sampler_options,
          seed, MakeLikelihood());
    };
    samplers[c] = fresh(ChainSeed(c));
    if (hot_replicas > 0 && ladder_end > 0) {
      std::vector<std::unique_ptr<PrfSampler>> hot;
      for (std::size_t k = 1; k <= hot_replicas; ++k) hot.push_back(fresh(ChainSeed(c) + k));
      MakeLadder(c, std::move(hot));
    }
  }
  session_start[c] = ladders[c] ? ladders[c]->cold().steps() : samplers[c]->steps();
}

void MappingRun::MakeLadder(std::size_t c, std::vector<std::unique_ptr<PrfSampler>> hot) {
  std::vector<std::unique_ptr<PrfSampler>> replicas;
  replicas.push_back(std::move(samplers[c]));
  for (auto& replica : hot) replicas.push_back(std::move(replica));
  ladders[c].emplace(std::move(replicas), ladder_temperatures, SplitMix64(ChainSeed(c) ^ 1),
                     result.chains[c].swaps);
}

// The annealing from its checkpoint, before any chain runs, so that its steps are among the
// restored ones from the first report on (as the chains' are). Which chain it continues is
// checked once the chains have ended.
void MappingRun::RestoreAnnealing() {
  if (options.anneal_steps > 0 && session.resume && std::filesystem::exists(anneal_path)) {
    restored_annealing =
        LoadAnnealCheckpoint(anneal_path, fingerprint, result.window, options, MakeLikelihood());
    const std::uint64_t steps = restored_annealing->sampler->steps();
    if (steps < end || steps > anneal_end)
      throw BinaryFormatError(anneal_path.string() + ": an annealing step outside the annealing");
  }
}

void MappingRun::CountRestoredSteps() {
  // A chain restored at its end takes no step this session, so it would never report.
  for (std::size_t c = 0; c < chains; ++c)
    if (session_start[c] >= end) {
      const PrfSampler& finished = ladders[c] ? ladders[c]->cold() : *samplers[c];
      chain_progress[c] = {.reported = true, .log_posterior = finished.LogPosterior()};
      chain_counters[c] = finished.counters();
    }
  for (std::size_t c = 0; c < chains; ++c) resumed += std::min(session_start[c], end);
  if (restored_annealing) resumed += restored_annealing->sampler->steps() - end;
  result.resumed_steps = resumed;
  steps_done = resumed;
  steps_total = chains * end + (anneal_end - end);
  // What the checkpoints restored, at once: a chain restored at its end never reports, and the
  // others only after their first chunk.
  if (progress && resumed > 0) Report();
}

// Every chain as it stood at its latest report (under progress_mutex once the chains run).
void MappingRun::Report() {
  MoveCounters counters{};
  for (const MoveCounters& of_chain : chain_counters) AddCounters(&counters, of_chain);
  progress({.steps_done = steps_done.load(),
            .steps_total = steps_total,
            .steps_resumed = resumed,
            .seconds = Seconds(start),
            .chains = chain_progress,
            .counters = counters,
            .annealing = annealing_progress});
}

// A chain also stops when another chain's task threw (its exception cancels this run's
// loops), rather than run to its end before the exception reaches the caller.
bool MappingRun::StopRequested() const {
  return (session.stop && session.stop->load()) ||
         (session.also_stop && session.also_stop->load()) || tbb::is_current_task_group_canceling();
}

std::uint64_t MappingRun::BudgetLeft(std::uint64_t first, std::uint64_t now) const {
  return session.stop_after_steps == 0 ? std::numeric_limits<std::uint64_t>::max()
                                       : first + session.stop_after_steps - now;
}

// A chain on all the data screens its moves with thinned data, when asked to (delayed
// acceptance); the screen's state is a function of the coloring, so it is made anew on resume.
void MappingRun::ScreenIfAsked(PrfSampler& sampler) const {
  if (screen_stride > 1 && !sampler.has_screen())
    sampler.SetScreen(data.make_thinned_data_term(screen_stride, 0));
}

// Past its ladder's end, the chain goes on alone from the cold replica.
void MappingRun::LeaveLadderIfDone(std::size_t c) {
  std::optional<ReplicaLadder>& ladder = ladders[c];
  if (!ladder || Chain(c).steps() < ladder_end) return;
  samplers[c] =
      options.replica_pick_best ? std::move(*ladder).TakeBest() : std::move(*ladder).TakeCold();
  ladder.reset();
}

void MappingRun::Checkpoint(std::size_t c, bool now, Clock::time_point& last_checkpoint) {
  if (checkpoints.empty()) return;
  if (!now && Seconds(last_checkpoint) < session.checkpoint_every_s) return;
  const std::optional<ReplicaLadder>& ladder = ladders[c];
  SaveChainCheckpoint(ChainCheckpointPath(checkpoints, c), fingerprint, c, Chain(c),
                      ladder ? ladder->hot() : std::vector<const PrfSampler*>{},
                      recording[c] ? estimates[c].get() : nullptr, result.chains[c]);
  last_checkpoint = Clock::now();
}

void MappingRun::RunChain(std::size_t c) {
  std::optional<ReplicaLadder>& ladder = ladders[c];
  ChainSummary& summary = result.chains[c];
  auto last_checkpoint = Clock::now();
  // The step count is the chain's clock: where the burn-in ends, traces are taken, replicas
  // exchange and the session stops depend on it alone, so chunks and restarts do not change
  // the course.
  while (Chain(c).steps() < end) {
    const std::uint64_t s = Chain(c).steps();
    if (StopRequested() || BudgetLeft(session_start[c], s) == 0) {
      stopped = true;
      break;
    }
    LeaveLadderIfDone(c);
    PrfSampler& sampler = Chain(c);
    if (s >= options.burn_in && !recording[c]) {
      sampler.RecordInto(estimates[c].get());
      recording[c] = 1;
    }
    const std::uint64_t target = PrepareChunk(c, s);
    if (ladder) {
      ladder->Run(target - s);
      hot_steps += (ladder->replicas().size() - 1) * (target - s);
      if (target % kExchangeEvery == 0) {
        ladder->Exchange(target / kExchangeEvery);
        summary.swaps = ladder->swaps();
      }
    } else {
      sampler.Run(target - s);
    }
    RecordTraces(c, target);
    ReportChain(c, target - s);
    Checkpoint(c, false, last_checkpoint);
  }
  FinishChain(c);
  Checkpoint(c, true, last_checkpoint);
  const PrfSampler& sampler = Chain(c);
  summary.counters = sampler.counters();
  summary.log_posterior = sampler.LogPosterior();
  summary.log_prior = sampler.LogPrior();
  summary.log_likelihood = sampler.LogLikelihood();
  summary.last = sampler.coloring();
  summary.edges = sampler.coloring().stats().edges;
}

// Sets the chain's data term and temperature for the chunk from step s, and returns where the
// chunk ends: at the stage's end, the burn-in's, a temperature block's, an exchange round's, the
// ladder's, the next trace record or the session's budget, whichever comes first.
std::uint64_t MappingRun::PrepareChunk(std::size_t c, std::uint64_t s) {
  std::optional<ReplicaLadder>& ladder = ladders[c];
  PrfSampler& sampler = Chain(c);
  // The data of this step's stage (thinned in the first stages of the burn-in).
  const BurnInStage stage = BurnInStageAt(options, s);
  UseStageData(c, stage);
  std::uint64_t target = std::min({end, s + options.chunk, stage.end});
  if (s < options.burn_in) {
    target = std::min(target, options.burn_in);
    const double temperature = BurnInTemperature(options, s);
    if (ladder) {
      ladder->set_scale(temperature);
      target = std::min({target, (s / kExchangeEvery + 1) * kExchangeEvery, ladder_end});
    } else {
      sampler.set_temperature(temperature);
    }
    target = std::min(target, BurnInTemperatureEnd(options, s));
  } else {
    sampler.set_temperature(1.0);
    const std::uint64_t into = s - options.burn_in;
    target =
        std::min(target, options.burn_in + (into / options.trace_every + 1) * options.trace_every);
  }
  return s + std::min(target - s, BudgetLeft(session_start[c], s));
}

// The chain's data term (and every replica's) for the stage, and the screen on all the data.
void MappingRun::UseStageData(std::size_t c, const BurnInStage& stage) {
  std::optional<ReplicaLadder>& ladder = ladders[c];
  PrfSampler& sampler = Chain(c);
  if (stage.stride != shares[c].stride || stage.phase != shares[c].phase) {
    const auto replace = [&](PrfSampler& replica) {
      replica.ReplaceDataTerm(stage.stride == 1 ? MakeLikelihood() : MakeThinnedLikelihood(stage));
    };
    if (ladder)
      for (const auto& replica : ladder->replicas()) replace(*replica);
    else
      replace(sampler);
    shares[c] = {stage.stride, stage.phase};
  }
  if (stage.stride == 1) {
    if (ladder)
      for (const auto& replica : ladder->replicas()) ScreenIfAsked(*replica);
    else
      ScreenIfAsked(sampler);
  }
}

void MappingRun::RecordTraces(std::size_t c, std::uint64_t target) {
  if (target > options.burn_in && (target - options.burn_in) % options.trace_every == 0) {
    ChainSummary& summary = result.chains[c];
    summary.log_posterior_trace.push_back(Chain(c).LogPosterior());
    for (std::size_t k = 0; k < result.trace_points.size(); ++k)
      summary.point_traces[k].push_back(
          Chain(c).coloring().ColourAt(result.trace_points[k]) == Colour::kBlack ? 1.0 : 0.0);
  }
}

void MappingRun::ReportChain(std::size_t c, std::uint64_t steps) {
  if (progress) {
    std::lock_guard lock(progress_mutex);
    // Counted under the lock: a count taken before another chain's report would reach that
    // report with this chain's steps but not its state.
    steps_done += steps;
    chain_progress[c] = {.reported = true,
                         .log_posterior = Chain(c).LogPosterior(),
                         .data_stride = shares[c].stride};
    chain_counters[c] = Chain(c).counters();
    Report();
  } else {
    steps_done += steps;
  }
}

void MappingRun::FinishChain(std::size_t c) {
  LeaveLadderIfDone(c);  // a ladder to the run's end (a burn-in without samples)
  PrfSampler& sampler = Chain(c);
  // A burn-in thinned to its end, with no samples after it: back to every reading.
  if (shares[c].stride != 1 && sampler.steps() >= options.burn_in) {
    sampler.ReplaceDataTerm(MakeLikelihood());
    shares[c] = {};
  }
  if (sampler.steps() >= end && !recording[c]) {  // no samples: recording never began
    sampler.RecordInto(estimates[c].get());
    recording[c] = 1;
  }
}

// Pooled estimates: every chain records the same number of samples.
void MappingRun::PoolEstimates() {
  result.raster = estimates[0]->grid();
  result.black_fraction = Eigen::MatrixXd::Zero(result.raster.ny, result.raster.nx);
  result.white_fraction = result.black_fraction;
  result.chain_spread = result.black_fraction;
  if (options.samples == 0)
    for (ChainSummary& chain : result.chains) chain.black_fraction = result.black_fraction;
  if (options.samples > 0) {
    Eigen::MatrixXd lowest, highest;
    for (std::size_t c = 0; c < chains; ++c) {
      const Eigen::MatrixXd black = estimates[c]->BlackFraction(samplers[c]->steps());
      result.chains[c].black_fraction = black;
      result.black_fraction += black;
      result.white_fraction += estimates[c]->WhiteFraction(samplers[c]->steps());
      lowest = c == 0 ? black : lowest.cwiseMin(black);
      highest = c == 0 ? black : highest.cwiseMax(black);
    }
    result.black_fraction /= static_cast<double>(chains);
    result.white_fraction /= static_cast<double>(chains);
    result.chain_spread = highest - lowest;
  }
}

void MappingRun::ComputeRhat() {
  // R̂ needs at least 4 trace records per chain.
  if (result.chains[0].log_posterior_trace.size() >= 4) {
    std::vector<std::vector<double>> traces;
    for (const ChainSummary& chain : result.chains) traces.push_back(chain.log_posterior_trace);
    result.rhat_log_posterior = SplitRhat(traces);
    result.rhat_point_colours = 1.0;
    for (std::size_t k = 0; k < result.trace_points.size(); ++k) {
      traces.clear();
      for (const ChainSummary& chain : result.chains) traces.push_back(chain.point_traces[k]);
      result.rhat_point_colours = std::max(result.rhat_point_colours, SplitRhat(traces));
    }
  } else {
    result.rhat_log_posterior = result.rhat_point_colours = std::nan("");
  }
}

void MappingRun::Anneal() {
  // From the chain that ended highest; the temperature falls geometrically from 1 in
  // kAnnealStages stages. The annealing step count, past the chain's end, is its clock.
  const auto annealing_start = Clock::now();
  std::size_t best = 0;
  for (std::size_t c = 1; c < chains; ++c)
    if (result.chains[c].log_posterior > result.chains[best].log_posterior) best = c;
  const std::uint64_t per_stage = AnnealStageSteps(options);
  std::unique_ptr<PrfSampler> annealing;
  if (restored_annealing) {
    if (restored_annealing->chain != best)
      throw BinaryFormatError(fmt::format(
          "{}: the annealing of chain {}, but chain {} ends with the highest log posterior",
          anneal_path.string(), restored_annealing->chain, best));
    annealing = std::move(restored_annealing->sampler);
  } else {
    annealing = std::move(samplers[best]);
    annealing->RecordInto(nullptr);
  }
  ScreenIfAsked(*annealing);
  const std::uint64_t first = annealing->steps();
  auto last_checkpoint = Clock::now();
  while (annealing->steps() < anneal_end) {
    const std::uint64_t a = annealing->steps() - end;
    if (StopRequested() || BudgetLeft(first, annealing->steps()) == 0) {
      result.complete = false;
      break;
    }
    const std::uint64_t stage = a / per_stage;
    const double fraction = static_cast<double>(stage + 1) / static_cast<double>(kAnnealStages);
    const double temperature = std::pow(options.anneal_final_temperature, fraction);
    annealing->set_temperature(temperature);
    const std::uint64_t n = std::min(
        {(stage + 1) * per_stage - a, options.chunk, BudgetLeft(first, annealing->steps())});
    annealing->Run(n);
    steps_done += n;
    if (progress) {
      std::lock_guard lock(progress_mutex);
      // The annealing goes on from its chain's counters, so the sum stays a run's total.
      chain_counters[best] = annealing->counters();
      annealing_progress = {
          .chain = best, .temperature = temperature, .log_posterior = annealing->LogPosterior()};
      Report();
    }
    if (!checkpoints.empty() && Seconds(last_checkpoint) >= session.checkpoint_every_s) {
      SaveAnnealCheckpoint(anneal_path, fingerprint, best, *annealing);
      last_checkpoint = Clock::now();
    }
  }
  if (!checkpoints.empty()) SaveAnnealCheckpoint(anneal_path, fingerprint, best, *annealing);
  result.proposals = ThisSession();
  result.annealing_time_s = Seconds(annealing_start);
  if (result.complete) {
    result.map = annealing->coloring();
    result.map_log_posterior = annealing->LogPosterior();
  }
}

}  // namespace

MappingResult RunMapping(const MappingData& data, const MappingOptions& run_options,
                         const std::function<void(const MappingProgress&)>& progress,
                         const MappingSession& session) {
  CheckRunOptions(data, run_options);
  MappingRun run(data, run_options, progress, session);
  return run.Run();
}

}  // namespace priormap::prf
