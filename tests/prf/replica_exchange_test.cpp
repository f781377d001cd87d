// The pieces of replica exchange that need no chain: the ladder, the swap ratio against the
// tempered densities it compares, and the ladder's bookkeeping of swaps. That swaps keep the
// cold replica's law is shown statistically in prior_stats_test.cpp; that a mapping run with
// replicas resumes exactly, in burn_in_and_start_test.cpp.
#include <cmath>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include <priormap/prf/arak.hpp>
#include <priormap/prf/replica_exchange.hpp>

namespace priormap::prf {
namespace {

TEST(GeometricLadder, RisesGeometricallyFromOneToTheTop) {
  EXPECT_EQ(GeometricLadder(1, 8.0), std::vector<double>{1.0});
  const std::vector<double> ladder = GeometricLadder(4, 8.0);
  ASSERT_EQ(ladder.size(), 4u);
  EXPECT_EQ(ladder[0], 1.0);
  EXPECT_NEAR(ladder[1], 2.0, 1e-12);
  EXPECT_NEAR(ladder[2], 4.0, 1e-12);
  EXPECT_NEAR(ladder[3], 8.0, 1e-12);
}

// The ratio is π_a(y) π_b(x) / (π_a(x) π_b(y)) for π_T ∝ exp(h/T), computed from the densities.
TEST(LogSwapRatio, IsTheRatioOfTheTemperedDensities) {
  const auto pi = [](double h, double t) { return std::exp(h / t); };
  for (const auto& [a, ta, b, tb] : std::vector<std::array<double, 4>>{
           {-3.0, 1.0, -1.0, 2.0}, {2.5, 1.0, -4.0, 1.7}, {0.3, 1.3, 0.3, 3.0}}) {
    const double expected = std::log(pi(b, ta) * pi(a, tb) / (pi(a, ta) * pi(b, tb)));
    EXPECT_NEAR(LogSwapRatio(a, ta, b, tb), expected, 1e-12);
  }
  // A better state always moves down to the colder rung.
  EXPECT_GT(LogSwapRatio(-5.0, 1.0, -1.0, 2.0), 0.0);
}

// A replica's tempered density is its log-posterior less the log of the Arak reference measure.
TEST(TemperedLogDensity, LeavesOutTheReferenceMeasure) {
  SamplerOptions options;
  options.p = 2.0;
  options.free_space = 0.4;
  PrfSampler sampler(Coloring(Window{Vec2::Zero(), Vec2(2, 2)}, 0.5), options, 5);
  sampler.Run(20000);
  const ColoringStats& stats = sampler.coloring().stats();
  ASSERT_GT(stats.edges, 0);
  EXPECT_NEAR(TemperedLogDensity(sampler), -ArakPotential(stats, 2.0) - 0.4 * sampler.black_area(),
              1e-9);
}

std::vector<std::unique_ptr<PrfSampler>> Replicas(int count) {
  std::vector<std::unique_ptr<PrfSampler>> replicas;
  for (int k = 0; k < count; ++k) {
    SamplerOptions options;
    options.p = 1.0;
    replicas.push_back(std::make_unique<PrfSampler>(Coloring(Window{Vec2::Zero(), Vec2(2, 2)}, 0.5),
                                                    options, 10 + k));
  }
  return replicas;
}

// Rounds alternate between the even and the odd pairs; swapped states take their new rung's
// temperature; the same seed and rounds make the same swaps.
TEST(ReplicaLadder, AlternatesPairsAndMovesTemperaturesWithTheRungs) {
  const auto run = [] {
    ReplicaLadder ladder(Replicas(4), GeometricLadder(4, 3.0), 77);
    for (std::uint64_t round = 0; round < 200; ++round) {
      ladder.Run(200);
      ladder.Exchange(round);
      for (std::size_t k = 0; k < 4; ++k)
        EXPECT_DOUBLE_EQ(ladder.replicas()[k]->options().temperature, ladder.ladder()[k]);
    }
    return ladder.swaps();
  };
  const std::vector<SwapCounter> swaps = run();
  ASSERT_EQ(swaps.size(), 3u);
  EXPECT_EQ(swaps[0].proposed, 100u);  // even rounds
  EXPECT_EQ(swaps[1].proposed, 100u);  // odd rounds
  EXPECT_EQ(swaps[2].proposed, 100u);
  for (const SwapCounter& s : swaps) EXPECT_GT(s.accepted, 0u);
  const std::vector<SwapCounter> again = run();
  for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(again[k].accepted, swaps[k].accepted);

  // Two replicas are one pair, offered every round.
  ReplicaLadder pair(Replicas(2), {1.0, 2.0}, 1);
  for (std::uint64_t round = 0; round < 10; ++round) pair.Exchange(round);
  EXPECT_EQ(pair.swaps()[0].proposed, 10u);
}

// TakeBest hands on the replica of highest log-posterior, at the cold rung's temperature;
// TakeCold the cold one, whatever its log-posterior.
TEST(ReplicaLadder, TakesTheBestOrTheColdReplica) {
  const auto ladder_after_steps = [] {
    ReplicaLadder ladder(Replicas(4), GeometricLadder(4, 3.0), 5);
    ladder.set_scale(2.0);
    ladder.Run(3000);  // no exchange: the replicas' log-posteriors are their own
    return ladder;
  };
  ReplicaLadder ladder = ladder_after_steps();
  std::size_t best = 0;
  for (std::size_t k = 1; k < 4; ++k)
    if (ladder.replicas()[k]->LogPosterior() > ladder.replicas()[best]->LogPosterior()) best = k;
  ASSERT_NE(best, 0u) << "the test wants a hot replica to lead";
  const double best_log_posterior = ladder.replicas()[best]->LogPosterior();
  const double cold_log_posterior = ladder.replicas()[0]->LogPosterior();
  const std::unique_ptr<PrfSampler> taken = std::move(ladder).TakeBest();
  EXPECT_EQ(taken->LogPosterior(), best_log_posterior);
  EXPECT_DOUBLE_EQ(taken->options().temperature, 2.0);
  EXPECT_EQ(ladder_after_steps().TakeCold()->LogPosterior(), cold_log_posterior);
}

TEST(ReplicaLadder, ScalesEveryRung) {
  ReplicaLadder ladder(Replicas(3), GeometricLadder(3, 4.0), 1);
  ladder.set_scale(5.0);
  EXPECT_DOUBLE_EQ(ladder.replicas()[0]->options().temperature, 5.0);
  EXPECT_DOUBLE_EQ(ladder.replicas()[2]->options().temperature, 20.0);
}

}  // namespace
}  // namespace priormap::prf
