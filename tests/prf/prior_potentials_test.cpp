// The sampler with the priors of Paskin & Thrun's Sec. 4 (a preference for free space, one for
// two perpendicular orientations) against the Arak process reweighted: a prior exp(−U) times
// the Arak measure has E_U[f] = E[f e^{−U}] / E[e^{−U}] under the Arak process, so the chain
// that samples it must agree with the Arak chain's samples weighted by e^{−U}. Tolerances are
// four batch-means standard errors of the difference (the weighted mean's by the delta method),
// and each prior must move its statistic several standard errors from the Arak value, so that
// a sampler ignoring the prior fails.
//
// PRIORMAP_PRF_CHAIN_SCALE multiplies the chains' lengths: 1 in the default suite (about 4 s),
// 10 in the `slow` label (prf_slow_tests), where errors a third as large show.
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <priormap/prf/arak.hpp>
#include <priormap/prf/batch_means.hpp>
#include <priormap/prf/black_area.hpp>
#include <priormap/prf/sampler.hpp>

#ifndef PRIORMAP_PRF_CHAIN_SCALE
#define PRIORMAP_PRF_CHAIN_SCALE 1
#endif

namespace priormap::prf {
namespace {

constexpr double kMaxStandardErrors = 4.0;
constexpr std::size_t kBatches = 25;

// A 2 m by 2 m window at p = 0.5: about 17 edges, so that the black area varies widely (the
// free-space prior's effect grows with its variance) and the chains mix in a million steps.
const Window kWindow{Vec2::Zero(), Vec2(2, 2)};

struct ChainPlan {
  std::uint64_t burn_in = 20000;
  std::uint64_t thin = 100;
  std::size_t records = 5000 * PRIORMAP_PRF_CHAIN_SCALE;
};

SamplerOptions ArakOptions() {
  SamplerOptions options;
  options.p = 0.5;
  options.birth_scale = 0.6;
  options.step_scales = {0.02, 0.1, 0.4};
  return options;
}

using Statistic = std::function<double(const PrfSampler&)>;

// Runs a chain and records each statistic of its state every `thin` steps after the burn-in.
std::vector<std::vector<double>> Record(const SamplerOptions& options, std::uint64_t seed,
                                        const ChainPlan& plan,
                                        const std::vector<Statistic>& statistics) {
  PrfSampler sampler(Coloring(kWindow, 0.25), options, seed);
  sampler.Run(plan.burn_in);
  std::vector<std::vector<double>> records(statistics.size());
  for (std::size_t i = 0; i < plan.records; ++i) {
    sampler.Run(plan.thin);
    for (std::size_t k = 0; k < statistics.size(); ++k)
      records[k].push_back(statistics[k](sampler));
  }
  return records;
}

// Σ f w / Σ w with its standard error: by the delta method the ratio's error is that of the
// mean of (f − R) w / mean(w), whose batch means carry the chain's autocorrelation.
Estimate WeightedMean(const std::vector<double>& f, const std::vector<double>& w) {
  double sum_fw = 0.0, sum_w = 0.0;
  for (std::size_t i = 0; i < f.size(); ++i) {
    sum_fw += f[i] * w[i];
    sum_w += w[i];
  }
  const double ratio = sum_fw / sum_w;
  const double mean_w = sum_w / static_cast<double>(w.size());
  std::vector<double> z(f.size());
  for (std::size_t i = 0; i < f.size(); ++i) z[i] = (f[i] - ratio) * w[i] / mean_w;
  return {.mean = ratio, .standard_error = BatchMeans(z, kBatches).standard_error};
}

// |a − b| in standard errors of the difference.
double Score(const Estimate& a, const Estimate& b) {
  return std::abs(a.mean - b.mean) /
         std::sqrt(a.standard_error * a.standard_error + b.standard_error * b.standard_error);
}

struct Comparison {
  Estimate arak;        // the Arak chain's plain mean
  Estimate reweighted;  // the Arak chain's mean weighted by e^{−U}
  Estimate direct;      // the mean of the chain with the prior
};

// The statistics of an Arak chain reweighted by e^{-potential} against those of a chain with
// the prior (`with_prior`), each within kMaxStandardErrors; returns the estimates.
std::vector<Comparison> ExpectReweightedArakMatchesPrior(const SamplerOptions& with_prior,
                                                         const ChainPlan& plan,
                                                         const Statistic& potential,
                                                         const std::vector<Statistic>& statistics,
                                                         const std::vector<std::string>& names) {
  std::vector<Statistic> with_potential = statistics;
  with_potential.push_back(potential);
  const auto arak = Record(ArakOptions(), 61, plan, with_potential);
  const auto direct = Record(with_prior, 62, plan, statistics);
  std::vector<double> weights;
  for (double u : arak.back()) weights.push_back(std::exp(-u));
  std::vector<Comparison> comparisons;
  for (std::size_t k = 0; k < statistics.size(); ++k) {
    const Comparison c{.arak = BatchMeans(arak[k], kBatches),
                       .reweighted = WeightedMean(arak[k], weights),
                       .direct = BatchMeans(direct[k], kBatches)};
    EXPECT_LE(Score(c.reweighted, c.direct), kMaxStandardErrors)
        << names[k] << ": reweighted Arak " << c.reweighted.mean << " ± "
        << c.reweighted.standard_error << ", chain with the prior " << c.direct.mean << " ± "
        << c.direct.standard_error << " (Arak " << c.arak.mean << " ± " << c.arak.standard_error
        << ")";
    comparisons.push_back(c);
  }
  return comparisons;
}

TEST(PriorPotentials, TheFreeSpacePriorMatchesTheReweightedArakProcess) {
  // 1 per m²: weights from 1 (all white) to e^{−4} (all black); the black area varies slowly
  // along the chain (no move recolours the whole window), hence the long chains.
  const double beta = 1.0;
  SamplerOptions with_prior = ArakOptions();
  with_prior.free_space = beta;
  const ChainPlan plan{.burn_in = 20000, .thin = 100, .records = 10000 * PRIORMAP_PRF_CHAIN_SCALE};
  const auto black_fraction = [](const PrfSampler& s) {
    return BlackArea(s.coloring()) / kWindow.Area();
  };
  const auto potential = [&](const PrfSampler& s) { return beta * BlackArea(s.coloring()); };
  const auto c = ExpectReweightedArakMatchesPrior(with_prior, plan, potential, {black_fraction},
                                                  {"black fraction"});
  // Less black than the Arak process's one half, by several standard errors.
  EXPECT_LT(c[0].direct.mean, 0.5 - 5.0 * c[0].direct.standard_error)
      << c[0].direct.mean << " ± " << c[0].direct.standard_error;
  EXPECT_LE(Score(c[0].arak, {.mean = 0.5, .standard_error = 0.0}), kMaxStandardErrors);
}

// A chain of `options` with the free-space prior (β = 1) and the orientation prior along the axes
// added matches the reweighted Arak process in its black fraction and edge count, and is less
// black than the Arak process by several standard errors.
void ExpectBothPriorsMatchTheReweightedArakProcess(SamplerOptions options) {
  const OrientationPrior axes{.weight = 1.0, .angle = 0.0};
  const double beta = 1.0;
  options.free_space = beta;
  options.orientation = axes;
  const ChainPlan plan{.burn_in = 20000, .thin = 100, .records = 10000 * PRIORMAP_PRF_CHAIN_SCALE};
  const auto black_fraction = [](const PrfSampler& s) {
    return BlackArea(s.coloring()) / kWindow.Area();
  };
  const auto edges = [](const PrfSampler& s) {
    return static_cast<double>(s.coloring().stats().edges);
  };
  const auto potential = [&](const PrfSampler& s) {
    return beta * BlackArea(s.coloring()) + OrientationPotential(s.coloring().stats(), axes);
  };
  const auto c = ExpectReweightedArakMatchesPrior(options, plan, potential, {black_fraction, edges},
                                                  {"black fraction", "edges"});
  EXPECT_LT(c[0].direct.mean, 0.5 - 5.0 * c[0].direct.standard_error);
}

// The edge shift's flipped ring (old path p, a, b, q and new one) and the vertex jump's
// quadrilateral, often crossing itself, under the free-space prior, whose black-area change and
// refusals they must get right, and with the orientation prior: a chain with both priors and
// the two kinds weighted well above the others matches the reweighted process.
TEST(PriorPotentials, EdgeShiftsAndVertexJumpsUnderBothPriorsMatchTheReweightedArakProcess) {
  SamplerOptions options = ArakOptions();
  options.weights[MoveKind::kEdgeShift] = 4.0;
  options.weights[MoveKind::kVertexJump] = 3.0;
  options.vertex_jump_reach = 0.6;
  options.vertex_jump_jitter = 0.2;
  ExpectBothPriorsMatchTheReweightedArakProcess(options);
}

// The vertex pair's quadrilateral u, v₁, v₂, w, which crosses itself when the pair straddles
// uw, under both priors, with the pairs weighted well above the other kinds.
TEST(PriorPotentials, VertexPairsUnderBothPriorsMatchTheReweightedArakProcess) {
  SamplerOptions options = ArakOptions();
  options.weights[MoveKind::kVertexPair] = 4.0;
  options.vertex_birth_widths = {0.5, 2.0};
  ExpectBothPriorsMatchTheReweightedArakProcess(options);
}

TEST(PriorPotentials, TheOrientationPriorMatchesTheReweightedArakProcess) {
  const OrientationPrior axes{.weight = 1.0, .angle = 0.0};
  SamplerOptions with_prior = ArakOptions();
  with_prior.orientation = axes;
  const auto potential = [&](const PrfSampler& s) {
    return OrientationPotential(s.coloring().stats(), axes);
  };
  // Σ|e| sin²(2θ) per metre of edge: 1/2 for isotropic edges, less along the axes.
  const auto misalignment = [&](const PrfSampler& s) {
    const ColoringStats& stats = s.coloring().stats();
    return stats.total_length > 0.0
               ? OrientationPotential(stats, {.weight = 1.0, .angle = 0.0}) / stats.total_length
               : 0.5;
  };
  const auto edges = [](const PrfSampler& s) {
    return static_cast<double>(s.coloring().stats().edges);
  };
  const auto c = ExpectReweightedArakMatchesPrior(with_prior, ChainPlan{}, potential,
                                                  {misalignment, edges}, {"misalignment", "edges"});
  // Edges turn towards the axes, and fewer of them pay the extra potential.
  EXPECT_LT(c[0].direct.mean, c[0].arak.mean);
  EXPECT_GT(Score(c[0].arak, c[0].direct), kMaxStandardErrors)
      << "misalignment: Arak " << c[0].arak.mean << " ± " << c[0].arak.standard_error
      << ", chain with the prior " << c[0].direct.mean << " ± " << c[0].direct.standard_error;
  EXPECT_LT(c[1].direct.mean, c[1].arak.mean);
}

}  // namespace
}  // namespace priormap::prf
