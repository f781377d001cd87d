// Prior-map SLAM (issue 5's speed targets): one 1.4 km urban run filtered with and without the
// prior map (one core, the same run each iteration), and the whole 30-run study with both
// filters on every core. The real-time factor is the simulated duration over the run's time.
#include <benchmark/benchmark.h>

#include <priormap/slam/study.hpp>

namespace {

using namespace priormap::slam;

void FilterOneRun(benchmark::State& state, bool with_prior) {
  const UrbanScenarioOptions options;
  const UrbanWorld world = MakeUrbanWorld(options, 1);
  const UrbanRun run = SimulateUrbanRun(world, options, 1, 0);
  SlamOptions slam;
  slam.use_prior_map = with_prior;
  SlamResult result;
  for (auto _ : state) {
    result = RunSlam(run.input, &run.prior_map, slam);
    benchmark::DoNotOptimize(result.frames.data());
  }
  state.counters["path_m"] = world.PathLength();
  state.counters["frames"] = static_cast<double>(result.frames.size());
  state.counters["relations"] = static_cast<double>(result.relations.size());
  state.counters["hypotheses"] = static_cast<double>(result.inference.hypotheses);
  state.counters["realtime_factor"] = benchmark::Counter(
      world.Duration() * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
void BM_UrbanRunWithPrior(benchmark::State& state) {
  FilterOneRun(state, true);
}
void BM_UrbanRunWithoutPrior(benchmark::State& state) {
  FilterOneRun(state, false);
}
BENCHMARK(BM_UrbanRunWithPrior)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_UrbanRunWithoutPrior)->Unit(benchmark::kMillisecond);

// Simulation of one run's noise and prior map (per Monte Carlo run).
void BM_SimulateUrbanRun(benchmark::State& state) {
  const UrbanScenarioOptions options;
  const UrbanWorld world = MakeUrbanWorld(options, 1);
  int run = 0;
  for (auto _ : state) {
    const UrbanRun data = SimulateUrbanRun(world, options, 1, run++);
    benchmark::DoNotOptimize(data.input.frames.data());
  }
}
BENCHMARK(BM_SimulateUrbanRun)->Unit(benchmark::kMillisecond);

// The study: 30 runs x 2 filters, oneTBB over the machine's cores, wall-clock time.
void BM_Study30Runs(benchmark::State& state) {
  StudyOptions options;
  options.runs = 30;
  options.seed = 1;
  for (auto _ : state) {
    const StudyResult study = RunStudy(options);
    benchmark::DoNotOptimize(study.times.data());
  }
}
BENCHMARK(BM_Study30Runs)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
