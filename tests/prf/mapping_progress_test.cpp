// MappingProgress: every report shows every chain at its own latest report, so that a run's
// status line follows all its chains instead of whichever reported last.
#include <cstddef>
#include <filesystem>
#include <vector>

#include <gtest/gtest.h>

#include <priormap/prf/chain_checkpoint.hpp>
#include <priormap/prf/mapping.hpp>

#include "mapping_testing.hpp"
#include "testing/temp_dir.hpp"

namespace priormap::prf {
namespace {

MappingOptions TwoChains() {
  MappingOptions options;
  options.sampler.p = 0.5;
  options.burn_in = 3000;
  options.samples = 3000;
  options.chains = 2;
  options.seed = 4;
  options.trace_every = 500;
  options.chunk = 500;
  return options;
}

TEST(MappingProgress, EachReportHoldsEveryChainAtItsLatestReport) {
  const MappingOptions options = TwoChains();
  std::vector<MappingProgress> reports;
  const MappingResult result = RunMapping(LaserMappingData(RoomData(), options), options,
                                          [&](const MappingProgress& p) { reports.push_back(p); });
  ASSERT_TRUE(result.complete);
  ASSERT_EQ(result.chains.size(), 2u);
  // One report per chunk of each chain.
  ASSERT_EQ(reports.size(), 2 * (options.burn_in + options.samples) / options.chunk);
  for (std::size_t k = 0; k < reports.size(); ++k) {
    ASSERT_EQ(reports[k].chains.size(), 2u) << "report " << k;
    if (k > 0) {
      EXPECT_GT(reports[k].steps_done, reports[k - 1].steps_done);
    }
  }
  // The first report comes from one chain, before the other has reported.
  EXPECT_NE(reports.front().chains[0].reported, reports.front().chains[1].reported);
  const MappingProgress& last = reports.back();
  EXPECT_EQ(last.steps_done, last.steps_total);
  MoveCounters summed{};
  for (std::size_t c = 0; c < 2; ++c) {
    ASSERT_TRUE(last.chains[c].reported) << "chain " << c;
    EXPECT_EQ(last.chains[c].log_posterior, result.chains[c].log_posterior) << "chain " << c;
    EXPECT_EQ(last.chains[c].data_stride, 1);
    for (std::size_t t = 0; t < summed.size(); ++t) summed[t] += result.chains[c].counters[t];
  }
  // Chains from different seeds end apart: the report is not one chain's state twice.
  EXPECT_NE(last.chains[0].log_posterior, last.chains[1].log_posterior);
  for (std::size_t t = 0; t < summed.size(); ++t) {
    EXPECT_EQ(last.counters[t].proposed, summed[t].proposed) << MoveTypeName(MoveType(t));
    EXPECT_EQ(last.counters[t].accepted, summed[t].accepted) << MoveTypeName(MoveType(t));
    EXPECT_EQ(last.counters[t].invalid, summed[t].invalid) << MoveTypeName(MoveType(t));
    EXPECT_EQ(last.counters[t].screened_out, summed[t].screened_out) << MoveTypeName(MoveType(t));
  }
}

TEST(MappingProgress, AChainRestoredAtItsEndIsReportedThoughItTakesNoStep) {
  const MappingOptions options = TwoChains();
  const MappingData data = LaserMappingData(RoomData(), options);
  const testing::TempDir checkpoints;
  const MappingSession first = {.checkpoint_directory = checkpoints.path(),
                                .checkpoint_every_s = 1e9};
  const MappingResult whole = RunMapping(data, options, {}, first);
  ASSERT_TRUE(whole.complete);
  // Chain 0 is restored at its end; chain 1, without its checkpoint, starts afresh.
  ASSERT_TRUE(std::filesystem::remove(ChainCheckpointPath(checkpoints.path(), 1)));
  MappingSession resumed = first;
  resumed.resume = true;
  std::vector<MappingProgress> reports;
  const MappingResult result = RunMapping(
      data, options, [&](const MappingProgress& p) { reports.push_back(p); }, resumed);
  ASSERT_TRUE(result.complete);
  // First what the checkpoints restored (chain 0 at its end, nothing of chain 1), before any step;
  // then only chain 1 steps, one report per chunk; each shows chain 0's end.
  const std::uint64_t per_chain = options.burn_in + options.samples;
  ASSERT_EQ(reports.size(), 1 + per_chain / options.chunk);
  EXPECT_EQ(reports.front().steps_done, per_chain);
  EXPECT_EQ(reports.front().steps_resumed, per_chain);
  EXPECT_EQ(reports.front().steps_total, 2 * per_chain);
  EXPECT_FALSE(reports.front().chains[1].reported);
  for (const MappingProgress& p : reports) {
    ASSERT_EQ(p.chains.size(), 2u);
    ASSERT_TRUE(p.chains[0].reported);
    EXPECT_EQ(p.chains[0].log_posterior, whole.chains[0].log_posterior);
  }
  EXPECT_EQ(reports.back().chains[1].log_posterior, whole.chains[1].log_posterior);
  // The acceptance counts chain 0's moves too.
  EXPECT_EQ(Total(reports.back().counters).proposed,
            Total(whole.chains[0].counters).proposed + Total(whole.chains[1].counters).proposed);
}

}  // namespace
}  // namespace priormap::prf
