// The chains' part of `priormap prf`'s status line: every chain in chain order while they fit,
// ranges beyond four, and which values are of a thinned stage's fraction of the readings; the
// annealing's once it runs.
#include "chains_status.hpp"

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

}  // namespace
}  // namespace priormap::app
