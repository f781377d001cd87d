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

// Two chains of 6000 steps, then 2000 steps of annealing in 100 stages of 20.
MappingOptions TwoChainsAnnealed() {
  MappingOptions options = TwoChains();
  options.anneal_steps = 2000;
  return options;
}

// The annealing's steps are part of the run: the share reaches its end with the annealing's last
// step, not the chains', and the proposals count them.
TEST(MappingProgress, TheAnnealingIsInTheShareAndInTheProposals) {
  const MappingOptions options = TwoChainsAnnealed();
  ASSERT_EQ(AnnealingSteps(options), 2000u);
  std::vector<MappingProgress> reports;
  const MappingResult result = RunMapping(LaserMappingData(RoomData(), options), options,
                                          [&](const MappingProgress& p) { reports.push_back(p); });
  ASSERT_TRUE(result.complete);
  ASSERT_TRUE(result.map);
  const std::uint64_t chain_steps = 2 * (options.burn_in + options.samples);
  EXPECT_EQ(result.proposals, chain_steps + 2000);
  EXPECT_EQ(result.resumed_steps, 0u);
  EXPECT_GT(result.annealing_time_s, 0.0);
  // One report per chunk of each chain, then one per chunk of the annealing (a stage each here).
  ASSERT_EQ(reports.size(), chain_steps / options.chunk + 100);
  for (std::size_t k = 0; k < reports.size(); ++k) {
    EXPECT_EQ(reports[k].steps_total, chain_steps + 2000) << "report " << k;
    if (k > 0) {
      EXPECT_GT(reports[k].steps_done, reports[k - 1].steps_done) << "report " << k;
    }
    // The annealing reports once the chains have all ended, and only then.
    EXPECT_EQ(reports[k].annealing.has_value(), reports[k].steps_done > chain_steps)
        << "report " << k;
  }
  const MappingProgress& chains_end = reports[chain_steps / options.chunk - 1];
  EXPECT_EQ(chains_end.steps_done, chain_steps);
  const MappingProgress& last = reports.back();
  EXPECT_EQ(last.steps_done, last.steps_total);
  ASSERT_TRUE(last.annealing);
  const std::size_t best = result.chains[1].log_posterior > result.chains[0].log_posterior ? 1 : 0;
  EXPECT_EQ(last.annealing->chain, best);
  EXPECT_EQ(last.annealing->temperature, options.anneal_final_temperature);
  EXPECT_EQ(last.annealing->log_posterior, result.map_log_posterior);
  // The chains stay at their ends; the counters go on with the annealing's moves.
  for (std::size_t c = 0; c < 2; ++c)
    EXPECT_EQ(last.chains[c].log_posterior, result.chains[c].log_posterior) << "chain " << c;
  EXPECT_EQ(Total(last.counters).proposed - Total(chains_end.counters).proposed, 2000u);
}

// A run stopped in its annealing resumes with the annealing's steps among the restored ones:
// this session's proposals and the restored steps add up to the whole run's.
TEST(MappingProgress, AnAnnealingResumedFromItsCheckpointCountsItsStepsAsRestored) {
  const MappingOptions options = TwoChainsAnnealed();
  const MappingData data = LaserMappingData(RoomData(), options);
  const MappingResult whole = RunMapping(data, options, {});
  ASSERT_TRUE(whole.complete);
  const testing::TempDir checkpoints;
  const std::uint64_t per_chain = options.burn_in + options.samples;
  // 1: 5000 steps a chain; 2: the chains' last 1000 and 1200 of the annealing's 2000 steps.
  std::uint64_t proposals = 0;
  for (const bool resume : {false, true}) {
    MappingSession session = StoppingSession(checkpoints.path(), resume ? 1200 : 5000);
    session.resume = resume;
    const MappingResult part = RunMapping(data, options, {}, session);
    ASSERT_FALSE(part.complete);
    proposals += part.proposals;
  }
  EXPECT_EQ(proposals, 2 * per_chain + 1200);
  ASSERT_TRUE(std::filesystem::exists(AnnealCheckpointPath(checkpoints.path())));

  std::vector<MappingProgress> reports;
  MappingSession last = StoppingSession(checkpoints.path(), 0);
  last.resume = true;
  const MappingResult result = RunMapping(
      data, options, [&](const MappingProgress& p) { reports.push_back(p); }, last);
  ASSERT_TRUE(result.complete);
  ASSERT_TRUE(result.map && whole.map);
  EXPECT_EQ(result.map_log_posterior, whole.map_log_posterior);
  EXPECT_EQ(result.resumed_steps, 2 * per_chain + 1200);
  EXPECT_EQ(result.proposals, 800u);
  // First what the checkpoints restored, the annealing's 1200 steps included; then the
  // annealing's reports, from there to the end.
  ASSERT_GE(reports.size(), 2u);
  EXPECT_EQ(reports.front().steps_resumed, 2 * per_chain + 1200);
  EXPECT_EQ(reports.front().steps_done, reports.front().steps_resumed);
  EXPECT_FALSE(reports.front().annealing);
  for (std::size_t k = 0; k < reports.size(); ++k) {
    EXPECT_EQ(reports[k].steps_total, 2 * per_chain + 2000) << "report " << k;
    EXPECT_EQ(reports[k].steps_resumed, reports.front().steps_resumed) << "report " << k;
    if (k > 0) {
      EXPECT_GT(reports[k].steps_done, reports[k - 1].steps_done) << "report " << k;
      EXPECT_TRUE(reports[k].annealing) << "report " << k;
    }
  }
  EXPECT_EQ(reports.back().steps_done, reports.back().steps_total);
}

}  // namespace
}  // namespace priormap::prf
