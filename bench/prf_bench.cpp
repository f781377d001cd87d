// Polygonal random fields (issue 6's speed targets), one core: Metropolis-Hastings proposals per
// second on real laser data (intel-corrected, about the paper's 5,550 measurements), and how the
// rate scales with the number of measurements over the same building. Each benchmark burns its
// chain in first (setup, untimed), then times further steps of the same chain.
#include <cstdio>
#include <memory>
#include <optional>

#include <benchmark/benchmark.h>

#include <priormap/core/log_io.hpp>
#include <priormap/prf/laser_likelihood.hpp>
#include <priormap/prf/sampler.hpp>

namespace {

using namespace priormap;
using namespace priormap::prf;

constexpr double kCellSize = 0.5;
constexpr std::uint64_t kBurnIn = 500000;
constexpr std::uint64_t kStepsPerIteration = 20000;

const Log* IntelLog() {
  static const std::optional<Log> log = []() -> std::optional<Log> {
    auto read = ReadLog(PRIORMAP_SHARED_DATA_DIR "/laser-corrected/intel-corrected.log.gz");
    if (!read.ok()) return std::nullopt;
    return std::move(read).value();
  }();
  return log ? &*log : nullptr;
}

void ProposalsPerSecond(benchmark::State& state, std::size_t end_scan, std::size_t beam_step) {
  const Log* log = IntelLog();
  if (log == nullptr) {
    state.SkipWithError("../shared/data/laser-corrected/intel-corrected.log.gz is not readable");
    return;
  }
  auto selected = SelectBeams(
      *log, {.first_scan = 0, .end_scan = end_scan, .beam_step = beam_step, .max_range = 20.0});
  auto data = std::make_shared<const LaserData>(std::move(selected).value());
  SamplerOptions options;
  options.p = 0.1;
  PrfSampler sampler(Coloring(WindowAround(*data, 1.0), kCellSize), options, 1,
                     std::make_unique<LaserLikelihood>(data, LaserModel{}, kCellSize));
  sampler.Run(kBurnIn);
  for (auto _ : state) sampler.Run(kStepsPerIteration);
  state.counters["beams"] = static_cast<double>(data->beams.size());
  state.counters["edges"] = sampler.coloring().stats().edges;
  state.counters["log_posterior"] = sampler.LogPosterior();
  state.counters["acceptance"] = Total(sampler.counters()).AcceptanceRate();
  state.counters["proposals_per_s"] = benchmark::Counter(
      static_cast<double>(kStepsPerIteration * state.iterations()), benchmark::Counter::kIsRate);
}

// The paper's data size: 185 scans of the Intel lab, every 6th beam.
void BM_ProposalsIntel5550(benchmark::State& state) {
  ProposalsPerSecond(state, 185, 6);
}
BENCHMARK(BM_ProposalsIntel5550)->Unit(benchmark::kMillisecond)->UseRealTime();

// The whole Intel lab (910 scans) at 5k, 20k and 50k measurements: same area, denser beams.
void BM_ProposalsIntelWhole(benchmark::State& state) {
  ProposalsPerSecond(state, 910, static_cast<std::size_t>(state.range(0)));
}
BENCHMARK(BM_ProposalsIntelWhole)
    ->Arg(33)
    ->Arg(8)
    ->Arg(3)
    ->ArgName("beam_step")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
