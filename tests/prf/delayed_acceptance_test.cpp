// Delayed acceptance (SamplerOptions::screen_stride) must leave the target alone whatever the
// screen. The check uses data terms whose posterior is known in closed form: a term
// L(χ) = (p′/p)^|E| · exp(−2(p′ − p) Σ|e|) turns the sampler's Arak(p) prior into exactly the
// Arak(p′) process (the density's only factors in p are p^|E| and exp(−2pΣ|e|)). A chain on such
// a term, screened by another that would lead it to Arak(p_s) on its own, must still match
// Arak(p′)'s closed forms (as in prior_stats_test.cpp: mean edge count, same colour at a
// distance, crossings of fixed segments, each within 4 batch-means standard errors), and must
// not match Arak(p_s): with the second stage left out it would.
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <priormap/core/rng.hpp>
#include <priormap/prf/arak.hpp>
#include <priormap/prf/batch_means.hpp>
#include <priormap/prf/prior_stats.hpp>
#include <priormap/prf/sampler.hpp>

namespace priormap::prf {
namespace {

constexpr double kMaxStandardErrors = 4.0;

// log L = a |E| + b Σ|e|, with `weight` dividing it (a screen's log-likelihood is multiplied by
// the stride).
class ArakTilt final : public DataTerm {
 public:
  ArakTilt(double from_p, double to_p, double weight = 1.0)
      : per_edge_(std::log(to_p / from_p) / weight), per_metre_(-2.0 * (to_p - from_p) / weight) {}

  std::optional<std::string> Reset(const Coloring& coloring) override {
    total_ = Of(coloring.stats());
    return std::nullopt;
  }
  std::optional<FixedLogLik> Evaluate(const Coloring& coloring, const Edit& edit) override {
    EditEffect effect;
    if (!coloring.Evaluate(edit, &effect)) return std::nullopt;
    pending_ = Of(effect.delta);
    return pending_;
  }
  void Commit(std::span<const EdgeId>) override { total_ += pending_; }
  [[nodiscard]] FixedLogLik log_likelihood() const override { return total_; }
  [[nodiscard]] FixedLogLik RecomputeLogLikelihood(const Coloring& coloring) const override {
    return Of(coloring.stats());
  }
  [[nodiscard]] std::optional<std::string> FindInconsistency(const Coloring&) const override {
    return std::nullopt;  // sums of rounded changes drift from the rounded total by design
  }
  [[nodiscard]] std::unique_ptr<DataTerm> Clone() const override {
    return std::make_unique<ArakTilt>(*this);
  }

 private:
  [[nodiscard]] FixedLogLik Of(const ColoringStats& s) const {
    return ToFixed(per_edge_ * s.edges + per_metre_ * s.total_length);
  }
  double per_edge_;
  double per_metre_;
  FixedLogLik total_ = 0;
  FixedLogLik pending_ = 0;
};

struct Segment2 {
  Vec2 a;
  Vec2 b;
};

struct ChainStats {
  Estimate edges;
  std::vector<Estimate> same_colour;  // per distance
  std::vector<Estimate> crossings;
  MoveCounters counters{};
};

const std::vector<double> kDistances{0.1, 0.3};

// Samples Arak(prior_p) × tilt to target_p in the unit square, screened (stride 4) by a tilt
// to screen_p when given.
ChainStats Sample(double prior_p, double target_p, std::optional<double> screen_p,
                  std::uint64_t seed) {
  const Window window{Vec2::Zero(), Vec2::Ones()};
  SamplerOptions options;
  options.p = prior_p;
  options.birth_scale = 0.3;
  options.step_scales = {0.01, 0.05, 0.2};
  constexpr int kStride = 4;
  if (screen_p) options.screen_stride = kStride;
  PrfSampler sampler(Coloring(window, 0.25), options, seed,
                     std::make_unique<ArakTilt>(prior_p, target_p));
  if (screen_p) sampler.SetScreen(std::make_unique<ArakTilt>(prior_p, *screen_p, kStride));

  Rng placement(seed + 100);
  std::vector<std::vector<Segment2>> segments(kDistances.size());
  for (std::size_t k = 0; k < kDistances.size(); ++k)
    while (segments[k].size() < 16) {
      const Vec2 a(placement.Uniform(), placement.Uniform());
      const Vec2 b = a + kDistances[k] * UnitVector(placement.Uniform(0.0, 2.0 * std::numbers::pi));
      if (window.ContainsInterior(b)) segments[k].push_back({a, b});
    }
  sampler.Run(200000);
  const std::size_t n = 20000;
  std::vector<double> edges(n);
  std::vector<std::vector<double>> same(kDistances.size(), std::vector<double>(n));
  std::vector<std::vector<double>> crossings = same;
  for (std::size_t i = 0; i < n; ++i) {
    sampler.Run(100);
    edges[i] = sampler.coloring().stats().edges;
    for (std::size_t k = 0; k < kDistances.size(); ++k) {
      double even = 0.0, total = 0.0;
      for (const Segment2& s : segments[k]) {
        const int count = sampler.coloring().CountCrossings(s.a, s.b);
        even += count % 2 == 0;
        total += count;
      }
      same[k][i] = even / 16.0;
      crossings[k][i] = total / 16.0;
    }
  }
  ChainStats stats;
  stats.edges = BatchMeans(edges, 40);
  for (std::size_t k = 0; k < kDistances.size(); ++k) {
    stats.same_colour.push_back(BatchMeans(same[k], 40));
    stats.crossings.push_back(BatchMeans(crossings[k], 40));
  }
  stats.counters = sampler.counters();
  return stats;
}

// The largest standard score of the chain's statistics against Arak(p)'s closed forms.
double WorstScore(const ChainStats& s, double p) {
  const Window window{Vec2::Zero(), Vec2::Ones()};
  double worst = StandardScore(s.edges, ExpectedEdges(p, window));
  for (std::size_t k = 0; k < kDistances.size(); ++k) {
    worst =
        std::max(worst, StandardScore(s.same_colour[k], SameColourProbability(p, kDistances[k])));
    worst = std::max(worst, StandardScore(s.crossings[k], ExpectedCrossings(p, kDistances[k])));
  }
  return worst;
}

TEST(ArakTilt, TurnsTheSamplersPriorIntoAnotherArakProcess) {
  // The check of the check: without a screen, the tilt alone gives Arak(2), not Arak(1).
  const ChainStats s = Sample(1.0, 2.0, std::nullopt, 5);
  EXPECT_LE(WorstScore(s, 2.0), kMaxStandardErrors);
  EXPECT_GT(WorstScore(s, 1.0), 3 * kMaxStandardErrors);
  EXPECT_LT(s.edges.standard_error, 0.05 * ExpectedEdges(2.0, {Vec2::Zero(), Vec2::Ones()}));
}

TEST(DelayedAcceptance, KeepsTheTargetWhateverTheScreen) {
  // Prior Arak(1), target Arak(2); the screen alone would lead to Arak(3), or to Arak(1).
  for (const double screen_p : {3.0, 1.0}) {
    SCOPED_TRACE("screen towards p = " + std::to_string(screen_p));
    const ChainStats s = Sample(1.0, 2.0, screen_p, 7);
    EXPECT_LE(WorstScore(s, 2.0), kMaxStandardErrors);
    EXPECT_GT(WorstScore(s, screen_p), 3 * kMaxStandardErrors);
    // Both stages reject: the screen some moves the target takes, the second stage the rest.
    const MoveCounter total = Total(s.counters);
    EXPECT_GT(total.screened_out, total.proposed / 20);
    EXPECT_GT(total.accepted, total.proposed / 20);
  }
}

TEST(DelayedAcceptance, AScreenEqualToTheDataChangesNothingButTheRandomDraws) {
  // With the screen equal to the data, the second stage's ratio is 1: every move that passes the
  // screen is accepted, and the chain still samples the target.
  const ChainStats s = Sample(1.0, 2.0, 2.0, 9);
  EXPECT_LE(WorstScore(s, 2.0), kMaxStandardErrors);
  const MoveCounter total = Total(s.counters);
  EXPECT_EQ(total.accepted + total.screened_out + total.invalid, total.proposed);
}

}  // namespace
}  // namespace priormap::prf
