// MappingResult::chain_spread, where the chains disagree: per cell, the largest minus the smallest
// chain's P(black); and ChainSummary::black_fraction, each chain's own P(black). A chain of a run
// is the one-chain run of its seed (chain c of seed s has seed s + c), which lets the test rebuild
// each chain's estimate on its own.
#include <gtest/gtest.h>

#include <priormap/prf/mapping.hpp>

#include "mapping_testing.hpp"

namespace priormap::prf {
namespace {

MappingOptions ShortRun(int chains, std::uint64_t seed) {
  MappingOptions options;
  options.sampler.p = 0.5;
  options.burn_in = 3000;
  options.samples = 4000;
  options.chains = chains;
  options.seed = seed;
  options.trace_every = 500;
  return options;
}

TEST(ChainSpread, IsTheLargestMinusTheSmallestChainsBlackFraction) {
  const MappingData data = LaserMappingData(RoomData(), ShortRun(1, 1));
  const MappingResult both = RunMapping(data, ShortRun(2, 7), {});
  const MappingResult first = RunMapping(data, ShortRun(1, 7), {});
  const MappingResult second = RunMapping(data, ShortRun(1, 8), {});
  ASSERT_TRUE(both.complete && first.complete && second.complete);
  ASSERT_EQ(both.chain_spread.rows(), both.black_fraction.rows());
  ASSERT_EQ(both.chain_spread.cols(), both.black_fraction.cols());

  const Eigen::MatrixXd pooled = (first.black_fraction + second.black_fraction) / 2.0;
  const Eigen::MatrixXd spread = (first.black_fraction - second.black_fraction).cwiseAbs();
  EXPECT_LT((both.black_fraction - pooled).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((both.chain_spread - spread).cwiseAbs().maxCoeff(), 1e-12);
  // Each chain keeps its own estimate: the one-chain run of its seed.
  ASSERT_EQ(both.chains.size(), 2u);
  EXPECT_LT((both.chains[0].black_fraction - first.black_fraction).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((both.chains[1].black_fraction - second.black_fraction).cwiseAbs().maxCoeff(), 1e-12);
  // Short chains from the empty map do not agree everywhere: the test compares something.
  EXPECT_GT(both.chain_spread.maxCoeff(), 0.5);
  EXPECT_EQ(both.chain_spread.minCoeff(), 0.0);
}

TEST(ChainSpread, IsZeroWithOneChain) {
  const MappingData data = LaserMappingData(RoomData(), ShortRun(1, 1));
  const MappingResult one = RunMapping(data, ShortRun(1, 7), {});
  ASSERT_TRUE(one.complete);
  EXPECT_GT(one.black_fraction.maxCoeff(), 0.0);
  EXPECT_EQ(one.chain_spread.cwiseAbs().maxCoeff(), 0.0);
}

}  // namespace
}  // namespace priormap::prf
