// Polygonal random fields on sonar (issue 7's speed), one core: Metropolis-Hastings proposals per
// second with the sonar likelihood on the real RoboND rings and on simulated office logs of about
// 3,000 and 29,000 readings (the paper's Gates Hall set has 29,120), and the sonar grid's rate.
// Each proposal benchmark burns its chain in first (setup, untimed), then times further steps,
// with the built-in model (the paper's form) or the fitted one of docs/sonar.md (multipath on),
// and with the fitted one under delayed acceptance (docs/prf-moves.md), whose steps screen the
// moves on a quarter of the readings first.
#include <memory>
#include <optional>

#include <benchmark/benchmark.h>

#include <priormap/core/robond_sonar_io.hpp>
#include <priormap/core/sonar_simulate.hpp>
#include <priormap/grid/sonar_grid.hpp>
#include <priormap/prf/sampler.hpp>
#include <priormap/prf/sonar_likelihood.hpp>
#include <priormap/prf/sonar_mapping.hpp>
#include <priormap/prf/sonar_model_io.hpp>

namespace {

using namespace priormap;
using namespace priormap::prf;

constexpr double kCellSize = 0.5;
constexpr std::uint64_t kBurnIn = 200000;
constexpr std::uint64_t kStepsPerIteration = 5000;

const Log* RoboNdLog() {
  static const std::optional<Log> log = []() -> std::optional<Log> {
    auto read = ReadRoboNdSonar(PRIORMAP_SHARED_DATA_DIR "/sonar-roboND/measurement.txt",
                                PRIORMAP_SHARED_DATA_DIR "/sonar-roboND/poses.txt");
    if (!read.ok()) return std::nullopt;
    return std::move(read).value();
  }();
  return log ? &*log : nullptr;
}

// The office scene's trajectory (25 m at 0.25 m/s) with a pioneer16 ring at `rate` rings per
// second.
Log OfficeLog(double rate) {
  const Scene scene = *BuiltinScene("office");
  const auto trajectory = TrajectoryFromWaypoints(scene.waypoints, 0.25, rate);
  return SimulateSonarLog(scene, *SonarSensor::Preset("pioneer16"), trajectory, 1);
}

// The fitted model shipped with the examples (docs/sonar.md): corner reflectors, the clear
// mixture and multipath.
const SonarModel* FittedModel() {
  static const std::optional<SonarModel> model = []() -> std::optional<SonarModel> {
    auto read = ReadSonarModel(PRIORMAP_EXAMPLES_DIR "/formats/sonar-model-simulated.json");
    if (!read.ok()) return std::nullopt;
    return read.value();
  }();
  return model ? &*model : nullptr;
}

void ProposalsPerSecond(benchmark::State& state, const Log& log, double max_range,
                        const SonarModel& model = {}, int screen_stride = 1) {
  auto selected =
      SelectSonarReadings(log, {.first_scan = 0, .end_scan = std::nullopt, .max_range = max_range});
  auto data = std::make_shared<const SonarData>(std::move(selected).value());
  SamplerOptions options;
  options.p = 0.1;
  options.screen_stride = screen_stride;
  PrfSampler sampler(Coloring(WindowAround(*data, 1.0), kCellSize), options, 1,
                     std::make_unique<SonarLikelihood>(data, model));
  // The screen joins after the burn-in, so that the screened steps are timed from the state the
  // unscreened benchmark of the same readings times.
  sampler.Run(kBurnIn);
  if (screen_stride > 1)
    sampler.SetScreen(
        std::make_unique<SonarLikelihood>(ThinnedSonarData(*data, screen_stride), model));
  const MoveCounter before = Total(sampler.counters());
  for (auto _ : state) sampler.Run(kStepsPerIteration);
  // The timed steps' counts alone.
  const MoveCounter after = Total(sampler.counters());
  const auto timed = [&](std::uint64_t MoveCounter::*count) {
    return static_cast<double>(after.*count - before.*count) /
           static_cast<double>(after.proposed - before.proposed);
  };
  state.counters["readings"] = static_cast<double>(data->readings.size());
  state.counters["edges"] = sampler.coloring().stats().edges;
  state.counters["log_posterior"] = sampler.LogPosterior();
  state.counters["acceptance"] = timed(&MoveCounter::accepted);
  state.counters["screened_out"] = timed(&MoveCounter::screened_out);
  state.counters["proposals_per_s"] = benchmark::Counter(
      static_cast<double>(kStepsPerIteration * state.iterations()), benchmark::Counter::kIsRate);
}

void BM_SonarProposalsRoboNd(benchmark::State& state) {
  const Log* log = RoboNdLog();
  if (log == nullptr) {
    state.SkipWithError("../shared/data/sonar-roboND is not readable");
    return;
  }
  ProposalsPerSecond(state, *log, 5.11);
}
BENCHMARK(BM_SonarProposalsRoboNd)->Unit(benchmark::kMillisecond)->UseRealTime();

// 2 rings/s: about 3,300 readings; 18 rings/s: about 29,000.
void BM_SonarProposalsOffice(benchmark::State& state) {
  ProposalsPerSecond(state, OfficeLog(static_cast<double>(state.range(0))), 5.0);
}
BENCHMARK(BM_SonarProposalsOffice)
    ->Arg(2)
    ->Arg(18)
    ->ArgName("rings_per_s")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_SonarProposalsOfficeFitted(benchmark::State& state) {
  const SonarModel* model = FittedModel();
  if (model == nullptr) {
    state.SkipWithError("examples/formats/sonar-model-simulated.json is not readable");
    return;
  }
  ProposalsPerSecond(state, OfficeLog(static_cast<double>(state.range(0))), 5.0, *model);
}
BENCHMARK(BM_SonarProposalsOfficeFitted)
    ->Arg(2)
    ->Arg(18)
    ->ArgName("rings_per_s")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The fitted model's 29k readings, screened on a quarter of them.
void BM_SonarProposalsOfficeScreened(benchmark::State& state) {
  const SonarModel* model = FittedModel();
  if (model == nullptr) {
    state.SkipWithError("examples/formats/sonar-model-simulated.json is not readable");
    return;
  }
  ProposalsPerSecond(state, OfficeLog(18.0), 5.0, *model, static_cast<int>(state.range(0)));
}
// A fixed 100,000 timed steps (7-16 s). Left to itself, the library stops at the first window
// over half a second (10,000 steps at these rates), whose spread hides a 5 % change, and it
// repeats the 100-second burn-in for each trial it makes to find that window.
BENCHMARK(BM_SonarProposalsOfficeScreened)
    ->Arg(4)
    ->Arg(8)
    ->Arg(16)
    ->ArgName("screen_stride")
    ->Iterations(20)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_SonarGridInsert(benchmark::State& state) {
  const Log log = OfficeLog(18.0);
  const grid::SonarGridOptions options;
  const Box2 extent = grid::SonarGrid::ExtentOf(log, 0, log.scans.size(), options);
  std::size_t readings = 0;
  for (auto _ : state) {
    grid::SonarGrid map(extent, options);
    for (const Scan& ring : log.scans) readings += map.Insert(ring);
    benchmark::DoNotOptimize(map.LogOdds(0, 0));
  }
  state.counters["readings_per_s"] =
      benchmark::Counter(static_cast<double>(readings), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SonarGridInsert)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
