// The chains' part of `priormap prf`'s status line: every chain in chain order while they fit,
// ranges beyond four, and which values are of a thinned stage's fraction of the readings; the
// annealing's once it runs.
#include "chains_status.hpp"

#include <algorithm>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

namespace priormap::app {
namespace {

prf::ChainProgress At(double log_posterior, int data_stride = 1) {
  return {.reported = true, .log_posterior = log_posterior, .data_stride = data_stride};
}

TEST(ChainsLogPosteriors, OneChainAsBefore) {
  EXPECT_EQ(ChainsLogPosteriors({At(23602.92)}), "log posterior 23602.9");
  EXPECT_EQ(ChainsLogPosteriors({At(757.94, 16)}), "log posterior 757.9 (on 1/16 of the readings)");
}

TEST(ChainsLogPosteriors, ListsUpToFourChainsInChainOrder) {
  EXPECT_EQ(ChainsLogPosteriors({At(24120.31), At(-5.04)}), "log posteriors 24120.3, -5.0");
  EXPECT_EQ(ChainsLogPosteriors({At(884.7, 16), At(700.2, 16), At(1.0, 16), At(2.0, 16)}),
            "log posteriors 884.7, 700.2, 1.0, 2.0 (on 1/16 of the readings)");
}

TEST(ChainsLogPosteriors, MarksEachValueWhereTheStagesDiffer) {
  EXPECT_EQ(ChainsLogPosteriors({At(20928.9), At(5227.7, 4)}),
            "log posteriors 20928.9, 5227.7 (on 1/4)");
  EXPECT_EQ(ChainsLogPosteriors({At(4283.4, 4), At(979.0, 16)}),
            "log posteriors 4283.4 (on 1/4), 979.0 (on 1/16)");
}

TEST(ChainsLogPosteriors, KeepsAChainThatHasNotReportedInItsPlace) {
  EXPECT_EQ(ChainsLogPosteriors({prf::ChainProgress{}, At(391.0, 16), prf::ChainProgress{}}),
            "log posteriors ..., 391.0, ... (on 1/16 of the readings)");
  EXPECT_EQ(ChainsLogPosteriors({prf::ChainProgress{}, prf::ChainProgress{}}), "");
}

TEST(ChainsLogPosteriors, GivesEachStagesRangeBeyondFourChains) {
  EXPECT_EQ(ChainsLogPosteriors({At(3.0), At(1.0), At(2.0), At(4.0), At(5.0)}),
            "log posteriors 1.0 to 5.0 over 5 chains");
  EXPECT_EQ(ChainsLogPosteriors({At(12224.8), At(12445.5), At(2366.3, 4), At(11806.3),
                                 prf::ChainProgress{}, At(2520.3, 4), At(12035.7, 16)}),
            "log posteriors 11806.3 to 12445.5 over 3 chains; 2366.3 to 2520.3 over 2 chains "
            "(on 1/4); 12035.7 (on 1/16); 6 of 7 chains reported");
  EXPECT_EQ(ChainsLogPosteriors(
                {At(1.0, 2), At(2.0, 2), At(3.0, 2), At(4.0, 2), At(5.0, 2), prf::ChainProgress{}}),
            "log posteriors 1.0 to 5.0 over 5 chains (on 1/2 of the readings); 5 of 6 chains "
            "reported");
}

TEST(MappingState, TheChainsWhileTheyRunThenTheAnnealing) {
  prf::MappingProgress progress;
  progress.chains = {At(6139.04), At(6131.49)};
  EXPECT_EQ(MappingState(progress), "log posteriors 6139.0, 6131.5");
  progress.annealing =
      prf::AnnealingProgress{.chain = 1, .temperature = 0.25, .log_posterior = 6150.26};
  EXPECT_EQ(MappingState(progress), "annealing chain 1 at T 0.25, log posterior 6150.3");
}

// Two chains of 10,000-step chunks at 10k steps/s each: every second both report, a few
// milliseconds apart. Over the milliseconds between two lines the rate read 4 M steps/s.
TEST(RecentRate, ReportsMillisecondsApartDoNotMakeASpike) {
  RecentRate rate(2.0);
  EXPECT_EQ(rate.Add(0.0, 0), 0.0);
  double last = 0.0;
  for (int k = 1; k <= 6; ++k) {
    const double t = k;
    last = rate.Add(t, 20000 * static_cast<std::uint64_t>(k) - 10000);  // chain 0
    EXPECT_NEAR(last, 20000.0, 10000.0 / std::min(t, 2.0) + 1.0) << t;
    last = rate.Add(t + 0.005, 20000 * static_cast<std::uint64_t>(k));  // chain 1
    EXPECT_NEAR(last, 20000.0, 10000.0 / std::min(t, 2.0) + 1.0) << t;
  }
}

// The rate follows a change of pace within the window: a thinned stage ends, the full data's
// steps cost ten times as much.
TEST(RecentRate, FollowsAChangeOfPaceWithinItsWindow) {
  RecentRate rate(2.0);
  std::uint64_t steps = 0;
  rate.Add(0.0, steps);
  for (int k = 1; k <= 10; ++k) EXPECT_DOUBLE_EQ(rate.Add(0.5 * k, steps += 50000), 100000.0);
  for (int k = 11; k <= 14; ++k) rate.Add(0.5 * k, steps += 5000);
  EXPECT_DOUBLE_EQ(rate.Add(7.5, steps += 5000), 10000.0);
}

TEST(RecentRate, IsZeroWithoutElapsedTime) {
  RecentRate rate;
  EXPECT_EQ(rate.Add(3.0, 100), 0.0);
  EXPECT_EQ(rate.Add(3.0, 200), 0.0);
}

}  // namespace
}  // namespace priormap::app
