// Priorlet evaluation and compilation speed (issue 3 targets, recorded in docs/benchmarks.md):
// value + gradient + Hessian of every term of a block per call, one core; compile time per prior.
#include <benchmark/benchmark.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/rng.hpp>
#include <priormap/dsl/prior_library.hpp>

namespace priormap::dsl {
namespace {

// 1024 random configurations (x, phi) of a block, cycled through by the benchmarks.
struct Points {
  std::vector<std::vector<double>> x, phi;
};

Points RandomPoints(int order) {
  Rng rng(1);
  Points points;
  for (int n = 0; n < 1024; ++n) {
    std::vector<double> x(2 * static_cast<std::size_t>(order)),
        phi(static_cast<std::size_t>(order));
    for (int i = 0; i < order; ++i) {
      x[static_cast<std::size_t>(i)] = rng.Uniform(0.5, 5.0);
      x[static_cast<std::size_t>(order + i)] = rng.Uniform(-kPi, kPi);
      phi[static_cast<std::size_t>(i)] = -1.0 + 0.1 * i + 0.01 * rng.Uniform();
    }
    points.x.push_back(std::move(x));
    points.phi.push_back(std::move(phi));
  }
  return points;
}

// Every call evaluates at a new x. With `new_phi` the beam angles change too (a new window of
// the scan); otherwise they stay (Newton iterations on one window), as the engine mostly calls.
void EvaluateBlock(benchmark::State& state, const std::string& prior_name, bool new_phi) {
  const CompiledPrior prior = PriorLibrary().Load(prior_name).value();
  const CompiledBlock& block = *prior.block(BlockKind::kSameRegion);
  const Points points = RandomPoints(prior.order());
  const std::size_t nt = static_cast<std::size_t>(block.num_terms()),
                    nv = static_cast<std::size_t>(block.num_variables());
  std::vector<double> values(nt), gradients(nt * nv), hessians(nt * nv * nv);
  BlockEvaluator evaluator(block);
  std::size_t i = 0;
  for (auto _ : state) {
    const std::size_t k = i++ & 1023;
    evaluator.Evaluate(points.x[k], points.phi[new_phi ? k : 0], values.data(), gradients.data(),
                       hessians.data());
    benchmark::DoNotOptimize(hessians.data());
    benchmark::ClobberMemory();
  }
  state.counters["evals/s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["tape"] = static_cast<double>(block.TapeLengths()[2]);
}

// All 1024 windows per call through EvaluateBatch, as the engine evaluates every window of a
// scan in each Newton step; "evals/s" counts windows.
void EvaluateBlockBatch(benchmark::State& state, const std::string& prior_name) {
  const CompiledPrior prior = PriorLibrary().Load(prior_name).value();
  const CompiledBlock& block = *prior.block(BlockKind::kSameRegion);
  const Points points = RandomPoints(prior.order());
  const std::size_t n = points.x.size();
  const std::size_t nt = static_cast<std::size_t>(block.num_terms()),
                    nv = static_cast<std::size_t>(block.num_variables());
  std::vector<double> x, phi;
  for (std::size_t i = 0; i < n; ++i) {
    x.insert(x.end(), points.x[i].begin(), points.x[i].end());
    phi.insert(phi.end(), points.phi[i].begin(), points.phi[i].end());
  }
  std::vector<double> values(n * nt), gradients(n * nt * nv), hessians(n * nt * nv * nv);
  BlockEvaluator evaluator(block);
  for (auto _ : state) {
    evaluator.EvaluateBatch(n, x, phi, values.data(), gradients.data(), hessians.data());
    benchmark::DoNotOptimize(hessians.data());
    benchmark::ClobberMemory();
  }
  state.counters["evals/s"] =
      benchmark::Counter(static_cast<double>(state.iterations() * n), benchmark::Counter::kIsRate);
}

void BM_PolygonalSameRegionBatch(benchmark::State& state) {
  EvaluateBlockBatch(state, "Polygonal prior");
}
void BM_CircularSameRegionBatch(benchmark::State& state) {
  EvaluateBlockBatch(state, "Circular prior");
}
BENCHMARK(BM_PolygonalSameRegionBatch)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_CircularSameRegionBatch)->Unit(benchmark::kMicrosecond);

void BM_PolygonalSameRegion(benchmark::State& state) {
  EvaluateBlock(state, "Polygonal prior", false);
}
void BM_PolygonalSameRegionNewPhi(benchmark::State& state) {
  EvaluateBlock(state, "Polygonal prior", true);
}
void BM_CircularSameRegion(benchmark::State& state) {
  EvaluateBlock(state, "Circular prior", false);
}
void BM_CircularSameRegionNewPhi(benchmark::State& state) {
  EvaluateBlock(state, "Circular prior", true);
}
BENCHMARK(BM_PolygonalSameRegion);
BENCHMARK(BM_PolygonalSameRegionNewPhi);
BENCHMARK(BM_CircularSameRegion);
BENCHMARK(BM_CircularSameRegionNewPhi);

// Parse + resolve `specializes` + check + lower + differentiate + build tapes.
void BM_Compile(benchmark::State& state, const std::string& name) {
  const PriorLibrary library;
  for (auto _ : state) benchmark::DoNotOptimize(library.Load(name));
}
BENCHMARK_CAPTURE(BM_Compile, polygonal, std::string("Polygonal prior"))
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Compile, rectangular, std::string("Rectangular prior"))
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Compile, rectangular_relaxed, std::string("Rectangular prior (relaxed)"))
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Compile, rectangular_relaxed_alternative,
                  std::string("Rectangular prior (relaxed - alternative)"))
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Compile, circular, std::string("Circular prior"))
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Compile, circular_radius, std::string("Circular prior (with prior on radius)"))
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Compile, splines, std::string("Splines prior"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Compile, straight_or_circular, std::string("Straight or circular prior"))
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace priormap::dsl

BENCHMARK_MAIN();
