// Split-R̂: a hand-computed case, near 1 for independent chains of one distribution, large for
// chains stuck apart or drifting, and the constant cases.
#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include <priormap/core/rng.hpp>
#include <priormap/prf/rhat.hpp>

namespace priormap::prf {
namespace {

TEST(SplitRhat, MatchesAHandComputation) {
  // Halves {1,2}, {3,4}, {2,3}, {4,5}: means 1.5, 3.5, 2.5, 4.5 (grand 3, B/n = 5/3),
  // variances 0.5 each (W = 0.5); n = 2: R̂ = sqrt((0.5·0.5 + 5/3) / 0.5).
  const std::vector<std::vector<double>> traces = {{1, 2, 3, 4}, {2, 3, 4, 5}};
  EXPECT_NEAR(SplitRhat(traces), std::sqrt((0.25 + 5.0 / 3.0) / 0.5), 1e-12);
}

TEST(SecondHalfMean, AveragesTheHalfThatSplitRhatKeeps) {
  // Four values: the last two. Five: the last two as well, the middle one left out.
  EXPECT_DOUBLE_EQ(SecondHalfMean(std::vector<double>{1, 2, 3, 5}), 4.0);
  EXPECT_DOUBLE_EQ(SecondHalfMean(std::vector<double>{1, 2, 100, 3, 5}), 4.0);
  // Equal second halves at different first halves leave only the first halves apart.
  const std::vector<std::vector<double>> traces = {{0, 1, 7, 9}, {10, 11, 7, 9}};
  EXPECT_DOUBLE_EQ(SecondHalfMean(traces[0]), SecondHalfMean(traces[1]));
  EXPECT_GT(SplitRhat(traces), 1.5);
}

TEST(SplitRhat, IsNearOneForIndependentChainsOfOneDistribution) {
  Rng rng(3);
  std::vector<std::vector<double>> traces(4);
  for (auto& trace : traces)
    for (int i = 0; i < 20000; ++i) trace.push_back(rng.Normal(2.0, 0.5));
  EXPECT_LT(SplitRhat(traces), 1.01);
}

TEST(SplitRhat, FlagsChainsApartAndAChainThatDrifts) {
  Rng rng(4);
  std::vector<std::vector<double>> apart(2);
  for (int i = 0; i < 1000; ++i) {
    apart[0].push_back(rng.Normal(0.0, 1.0));
    apart[1].push_back(rng.Normal(3.0, 1.0));
  }
  EXPECT_GT(SplitRhat(apart), 1.5);
  std::vector<std::vector<double>> drifting(1);
  for (int i = 0; i < 1000; ++i) drifting[0].push_back(0.01 * i + rng.Normal(0.0, 1.0));
  EXPECT_GT(SplitRhat(drifting), 1.5);  // one chain, caught by splitting it
}

TEST(SplitRhat, ConstantTraces) {
  const std::vector<std::vector<double>> same = {{1, 1, 1, 1}, {1, 1, 1, 1}};
  EXPECT_EQ(SplitRhat(same), 1.0);
  const std::vector<std::vector<double>> different = {{0, 0, 0, 0}, {1, 1, 1, 1}};
  EXPECT_EQ(SplitRhat(different), std::numeric_limits<double>::infinity());
}

}  // namespace
}  // namespace priormap::prf
