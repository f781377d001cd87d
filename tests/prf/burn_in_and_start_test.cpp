// Mapping runs with a tempered burn-in (MappingOptions::burn_in_temperature), a thinned one
// (MappingOptions::thinned_burn_in), a warm stage (MappingOptions::warm_burn_in) and a given
// start (MappingData::start): the temperature schedule; which readings a thinned stage keeps,
// where each stage ends, the thinned data term; runs stopped and resumed from checkpoints
// (across changes of temperature and of data term) ending as the uninterrupted run; what a run
// records after a thinned burn-in; chains starting where they are told, and checkpoints of a run
// from another start or schedule refused.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <memory>
#include <tuple>
#include <utility>
#include <variant>
#include <vector>

#include <gtest/gtest.h>

#include <priormap/core/binary_io.hpp>
#include <priormap/core/check.hpp>
#include <priormap/core/range_sensor.hpp>
#include <priormap/core/scene.hpp>
#include <priormap/core/simulate.hpp>
#include <priormap/prf/chain_checkpoint.hpp>
#include <priormap/prf/mapping.hpp>
#include <priormap/prf/weighted_data_term.hpp>

#include "mapping_testing.hpp"
#include "testing/temp_dir.hpp"

namespace priormap::prf {
namespace {

MappingOptions Tempered(std::uint64_t burn_in, double temperature) {
  MappingOptions options;
  options.burn_in = burn_in;
  options.burn_in_temperature = temperature;
  return options;
}

TEST(BurnInTemperature, CoolsGeometricallyBlockByBlockOverTheFirstHalf) {
  // 100000 steps: cooling over the first 50000, five blocks of 10000.
  const MappingOptions options = Tempered(100000, 4.0);
  EXPECT_EQ(BurnInTemperature(options, 0), 4.0);
  EXPECT_EQ(BurnInTemperature(options, 9999), 4.0);
  for (std::uint64_t block = 1; block < 5; ++block) {
    const double expected = std::pow(4.0, 1.0 - static_cast<double>(block) / 5.0);
    const std::uint64_t start = block * kTemperatureBlock;
    EXPECT_NEAR(BurnInTemperature(options, start), expected, 1e-12) << "block " << block;
    // Constant within a block.
    EXPECT_EQ(BurnInTemperature(options, start + kTemperatureBlock / 2),
              BurnInTemperature(options, start));
    EXPECT_EQ(BurnInTemperature(options, start + kTemperatureBlock - 1),
              BurnInTemperature(options, start));
  }
  // Falling from block to block, and 1 from the middle on, after the burn-in too.
  EXPECT_LT(BurnInTemperature(options, 40000), BurnInTemperature(options, 30000));
  EXPECT_GT(BurnInTemperature(options, 49999), 1.0);
  for (std::uint64_t step : {50000, 50001, 75000, 99999, 100000, 250000})
    EXPECT_EQ(BurnInTemperature(options, step), 1.0) << "step " << step;
}

TEST(BurnInTemperature, IsOneThroughoutWithoutTempering) {
  const MappingOptions options = Tempered(100000, 1.0);
  for (std::uint64_t step : {0, 9999, 10000, 49999, 50000, 100000})
    EXPECT_EQ(BurnInTemperature(options, step), 1.0);
  EXPECT_EQ(BurnInTemperature(Tempered(0, 4.0), 0), 1.0);
}

// "1 from the middle of the burn-in on" (mapping.hpp) must hold when the middle is not at a
// block boundary, and for a burn-in shorter than two blocks, whose whole cooling fits in the
// first block.
TEST(BurnInTemperature, IsOneFromTheMiddleOfABurnInThatIsNotAWholeNumberOfBlocks) {
  const MappingOptions uneven = Tempered(130000, 4.0);  // middle at 65000, in block 60000
  EXPECT_EQ(BurnInTemperature(uneven, 65000), 1.0);
  EXPECT_EQ(BurnInTemperature(uneven, 69999), 1.0);
  const MappingOptions short_burn_in = Tempered(5000, 4.0);  // middle at 2500, in block 0
  EXPECT_EQ(BurnInTemperature(short_burn_in, 2500), 1.0);
  EXPECT_EQ(BurnInTemperature(short_burn_in, 4999), 1.0);
}

MappingOptions WarmAfterThinned() {
  MappingOptions options;
  options.burn_in = 300000;
  options.thinned_burn_in = {{.stride = 16, .steps = 100000}, {.stride = 4, .steps = 50000}};
  options.warm_burn_in = {.temperature = 2.0, .steps = 80000};
  return options;
}

TEST(BurnInTemperature, IsTheWarmStagesRightAfterTheThinnedStagesAndOneElsewhere) {
  const MappingOptions options = WarmAfterThinned();
  const WarmStage warm = WarmStageOf(options);
  EXPECT_EQ(warm.begin, 150000u);
  EXPECT_EQ(warm.end, 230000u);
  for (const std::uint64_t step : {0u, 99999u, 149999u, 230000u, 299999u, 300000u})
    EXPECT_EQ(BurnInTemperature(options, step), 1.0) << "step " << step;
  for (const std::uint64_t step : {150000u, 190000u, 229999u})
    EXPECT_EQ(BurnInTemperature(options, step), 2.0) << "step " << step;
  // The run's chunks end where the temperature changes.
  EXPECT_EQ(BurnInTemperatureEnd(options, 0), 150000u);
  EXPECT_EQ(BurnInTemperatureEnd(options, 150000), 230000u);
  EXPECT_EQ(BurnInTemperatureEnd(options, 229999), 230000u);
  EXPECT_EQ(BurnInTemperatureEnd(options, 230000), std::numeric_limits<std::uint64_t>::max());
  // At temperature 1, or of no steps, there is no warm stage.
  MappingOptions none = options;
  none.warm_burn_in.temperature = 1.0;
  EXPECT_EQ(WarmStageOf(none).end, WarmStageOf(none).begin);
  none = options;
  none.warm_burn_in.steps = 0;
  EXPECT_EQ(BurnInTemperature(none, 150000), 1.0);
}

// Within the warm stage the tempered burn-in's temperature counts where it is the higher.
TEST(BurnInTemperature, IsTheHigherOfTheWarmStagesAndTheCoolingOnes) {
  MappingOptions options = Tempered(100000, 4.0);  // 4^(1 - block / 50000)
  options.warm_burn_in = {.temperature = 1.5, .steps = 45000};
  EXPECT_EQ(BurnInTemperature(options, 0), 4.0);
  EXPECT_NEAR(BurnInTemperature(options, 20000), std::pow(4.0, 0.6), 1e-12);
  EXPECT_EQ(BurnInTemperature(options, 40000), 1.5);  // the cooling's 4^0.2 = 1.32 is lower
  EXPECT_NEAR(BurnInTemperature(options, 45000), std::pow(4.0, 0.2), 1e-12);
  EXPECT_EQ(BurnInTemperature(options, 50000), 1.0);
  EXPECT_EQ(BurnInTemperatureEnd(options, 40000), 45000u);
  EXPECT_EQ(BurnInTemperatureEnd(options, 45000), 50000u);
}

TEST(KeptByThinning, KeepsEveryReadingAtStrideOne) {
  for (std::size_t i = 0; i < 1000; ++i) EXPECT_TRUE(KeptByThinning(i, 1));
}

// About 1/stride of the readings, and so of each transducer of a 16-transducer ring (reading i
// is transducer i mod 16): a stride dividing the ring's size must not keep one transducer only.
TEST(KeptByThinning, KeepsAboutOneInStrideOfEveryTransducer) {
  constexpr std::size_t kRing = 16;
  constexpr std::size_t kRings = 4000;
  for (const int stride : {2, 4, 16}) {
    std::vector<int> kept(kRing, 0);
    for (std::size_t i = 0; i < kRing * kRings; ++i)
      if (KeptByThinning(i, stride)) ++kept[i % kRing];
    const double p = 1.0 / stride;
    const double sd = std::sqrt(kRings * p * (1.0 - p));  // binomial
    for (std::size_t t = 0; t < kRing; ++t)
      EXPECT_NEAR(kept[t], kRings * p, 5.0 * sd) << "stride " << stride << ", transducer " << t;
  }
}

// The phases of a stride split the readings: each reading is in exactly one share.
TEST(KeptByThinning, ThePhasesOfAStrideSplitTheReadings) {
  for (const int stride : {2, 3, 16}) {
    std::vector<int> shares(stride, 0);
    for (std::size_t i = 0; i < 20000; ++i) {
      int in = 0;
      for (int phase = 0; phase < stride; ++phase)
        if (KeptByThinning(i, stride, phase)) {
          ++in;
          ++shares[static_cast<std::size_t>(phase)];
        }
      ASSERT_EQ(in, 1) << "reading " << i << ", stride " << stride;
    }
    for (const int kept : shares) EXPECT_NEAR(kept, 20000.0 / stride, 0.1 * 20000.0 / stride);
  }
}

TEST(BurnInStageAt, GoesThroughTheStagesThenUsesEveryReading) {
  MappingOptions options;
  options.burn_in = 300;
  options.thinned_burn_in = {{.stride = 16, .steps = 100}, {.stride = 4, .steps = 50}};
  for (const auto& [step, stride, end] :
       {std::tuple{0u, 16, 100u}, {99u, 16, 100u}, {100u, 4, 150u}, {149u, 4, 150u}}) {
    const BurnInStage stage = BurnInStageAt(options, step);
    EXPECT_EQ(stage.stride, stride) << "step " << step;
    EXPECT_EQ(stage.end, end) << "step " << step;
  }
  for (const std::uint64_t step : {150u, 299u, 300u, 100000u})
    EXPECT_EQ(BurnInStageAt(options, step).stride, 1) << "step " << step;
  options.thinned_burn_in.clear();
  EXPECT_EQ(BurnInStageAt(options, 0).stride, 1);
}

// With a rotation, each stage goes through its stride's shares from the first, a share every
// `thinned_rotation` steps (the last one cut at the stage's end), round again after the last.
TEST(BurnInStageAt, RotatesThroughTheSharesOfEachStage) {
  MappingOptions options;
  options.burn_in = 300;
  options.thinned_burn_in = {{.stride = 3, .steps = 100}, {.stride = 2, .steps = 50}};
  options.thinned_rotation = 30;
  for (const auto& [step, stride, phase, end] : {std::tuple{0u, 3, 0, 30u},
                                                 {29u, 3, 0, 30u},
                                                 {30u, 3, 1, 60u},
                                                 {60u, 3, 2, 90u},
                                                 {90u, 3, 0, 100u},
                                                 {99u, 3, 0, 100u},
                                                 {100u, 2, 0, 130u},
                                                 {130u, 2, 1, 150u},
                                                 {149u, 2, 1, 150u}}) {
    const BurnInStage stage = BurnInStageAt(options, step);
    EXPECT_EQ(stage.stride, stride) << "step " << step;
    EXPECT_EQ(stage.phase, phase) << "step " << step;
    EXPECT_EQ(stage.end, end) << "step " << step;
  }
  const BurnInStage after = BurnInStageAt(options, 150);
  EXPECT_EQ(after.stride, 1);
  EXPECT_EQ(after.phase, 0);
}

// The runs of the resume tests: two chains on RoomData at p = 0.5, traced every 1000 steps,
// in chunks of 3000.
MappingOptions SmallRun(std::uint64_t seed, std::uint64_t burn_in, std::uint64_t samples) {
  MappingOptions options;
  options.sampler.p = 0.5;
  options.burn_in = burn_in;
  options.samples = samples;
  options.chains = 2;
  options.seed = seed;
  options.trace_every = 1000;
  options.chunk = 3000;
  return options;
}

// Runs `options` whole and in sessions of `steps` steps per chain, resumed from checkpoints,
// expects `sessions` sessions and the same estimates, traces and swap counts; returns the whole
// run.
MappingResult ExpectResumesExactly(const MappingData& data, const MappingOptions& options,
                                   std::uint64_t steps, int sessions) {
  const MappingResult whole = RunMapping(data, options, {});
  EXPECT_TRUE(whole.complete);
  testing::TempDir dir;
  const auto [part, count] = RunInSessions(data, options, steps, dir.path());
  EXPECT_EQ(count, sessions);
  EXPECT_EQ(part.black_fraction, whole.black_fraction);
  EXPECT_EQ(part.white_fraction, whole.white_fraction);
  for (std::size_t c = 0; c < whole.chains.size(); ++c) {
    const ChainSummary& a = part.chains[c];
    const ChainSummary& b = whole.chains[c];
    EXPECT_EQ(a.log_posterior_trace, b.log_posterior_trace);
    EXPECT_EQ(a.point_traces, b.point_traces);
    EXPECT_EQ(a.log_posterior, b.log_posterior);
    EXPECT_EQ(a.swaps.size(), b.swaps.size());
    for (std::size_t k = 0; k < std::min(a.swaps.size(), b.swaps.size()); ++k) {
      EXPECT_EQ(a.swaps[k].proposed, b.swaps[k].proposed);
      EXPECT_EQ(a.swaps[k].accepted, b.swaps[k].accepted);
    }
  }
  return whole;
}

MappingOptions TemperedRun() {
  MappingOptions options = SmallRun(9, 40000, 8000);
  options.burn_in_temperature = 4.0;  // at 4, then 2 (block 10000), then 1 from 20000 on
  return options;
}

// Sessions of 7000 steps stop mid-block (7000, 14000, ...): the resumed chains must take up the
// temperature of the block they are in.
TEST(TemperedMapping, AStoppedRunResumesToTheSameResult) {
  const MappingData data = LaserMappingData(RoomData(), TemperedRun());
  const MappingResult whole = ExpectResumesExactly(data, TemperedRun(), 7000, 7);  // 48000 steps

  // The tempering changed the course of the chains (so the comparison above covers it).
  MappingOptions untempered = TemperedRun();
  untempered.burn_in_temperature = 1.0;
  const MappingResult cold = RunMapping(data, untempered, {});
  EXPECT_NE(cold.chains[0].log_posterior_trace, whole.chains[0].log_posterior_trace);
}

MappingOptions ReplicaRun() {
  MappingOptions options = SmallRun(4, 30000, 8000);
  options.thinned_burn_in = {{.stride = 2, .steps = 10000}};
  options.burn_in_replicas = 3;
  options.replica_temperature = 3.0;
  options.replica_steps = 22500;  // not a whole number of rounds
  return options;
}

// Replicas through most of a burn-in that is also thinned at first: sessions of 6500 steps stop
// between exchange rounds, inside the thinned stage and past the ladders' end, and the resumed
// chains must take up their ladders (or go on alone), the rungs' data terms and the swap counts
// where they left them.
TEST(ReplicaMapping, AStoppedRunResumesToTheSameResult) {
  const MappingData data = LaserMappingData(RoomData(), ReplicaRun());
  const MappingResult whole = ExpectResumesExactly(data, ReplicaRun(), 6500, 6);  // 38000 steps
  for (const ChainSummary& chain : whole.chains) {
    ASSERT_EQ(chain.swaps.size(), 2u);
    for (const SwapCounter& swaps : chain.swaps) {
      EXPECT_EQ(swaps.proposed, 11u);  // 22 rounds, each pair every other one
      EXPECT_GT(swaps.accepted, 0u);
    }
  }
  // Every replica's steps are counted: 3 × 22500 with the ladder, 7500 alone and 8000 samples.
  EXPECT_EQ(whole.proposals, 2u * (3u * 22500u + 7500u + 8000u));

  // The replicas changed the course of the chains (so the comparison above covers them).
  MappingOptions alone = ReplicaRun();
  alone.burn_in_replicas = 1;
  const MappingResult single = RunMapping(data, alone, {});
  EXPECT_NE(single.chains[0].log_posterior_trace, whole.chains[0].log_posterior_trace);
}

// The checkpoint written right after the ladder's last round still holds the hot replicas (the
// chain leaves the ladder at its next step). A crash before the next checkpoint leaves it as the
// chain's last, and it must resume: with a pick of the best replica, which that next step makes.
TEST(ReplicaMapping, TheCheckpointAtTheLaddersEndResumes) {
  MappingOptions options = SmallRun(6, 12000, 3000);
  options.chains = 1;
  options.burn_in_replicas = 3;
  options.replica_steps = 9000;  // a whole number of rounds: a chunk ends there
  options.replica_pick_best = true;
  const MappingData data = LaserMappingData(RoomData(), options);
  const MappingResult whole = RunMapping(data, options, {});
  ASSERT_TRUE(whole.complete);

  // Every chunk checkpointed; at the first report past the ladder's end, the checkpoint on disk is
  // the one of its end, as a crash then would leave it.
  testing::TempDir dir;
  testing::TempDir crashed;
  bool saved = false;
  const auto keep_the_ladders_end = [&](const MappingProgress& p) {
    if (saved || p.steps_done <= options.replica_steps) return;
    std::filesystem::copy_file(ChainCheckpointPath(dir.path(), 0),
                               ChainCheckpointPath(crashed.path(), 0));
    saved = true;
  };
  ASSERT_TRUE(RunMapping(data, options, keep_the_ladders_end,
                         {.checkpoint_directory = dir.path(), .checkpoint_every_s = 0.0})
                  .complete);
  ASSERT_TRUE(saved);

  const MappingResult resumed = RunMapping(
      data, options, {},
      {.checkpoint_directory = crashed.path(), .checkpoint_every_s = 1e9, .resume = true});
  ASSERT_TRUE(resumed.complete);
  EXPECT_EQ(resumed.resumed_steps, options.replica_steps);
  EXPECT_EQ(resumed.black_fraction, whole.black_fraction);
  EXPECT_EQ(resumed.chains[0].log_posterior_trace, whole.chains[0].log_posterior_trace);
  EXPECT_EQ(resumed.chains[0].log_posterior, whole.chains[0].log_posterior);
}

// Stops a run of `options` after `steps` per chain; resuming its checkpoints as a run of `other`
// must be refused.
void ExpectResumingAsOtherIsRefused(const MappingOptions& options, const MappingOptions& other,
                                    std::uint64_t steps) {
  testing::TempDir dir;
  ASSERT_FALSE(RunMapping(LaserMappingData(RoomData(), options), options, {},
                          StoppingSession(dir.path(), steps))
                   .complete);
  MappingSession resume = StoppingSession(dir.path(), steps);
  resume.resume = true;
  EXPECT_THROW((void)RunMapping(LaserMappingData(RoomData(), other), other, {}, resume),
               BinaryFormatError);
}

// A checkpoint of a run with replicas is not one of the run without them.
TEST(ReplicaMapping, ACheckpointOfAnotherLadderIsRefused) {
  MappingOptions other = ReplicaRun();
  other.burn_in_replicas = 2;
  ExpectResumingAsOtherIsRefused(ReplicaRun(), other, 5000);
}

// The thinned term scores the kept readings only: on the empty map, where every beam sees
// nothing and scores alike, its log-likelihood is about 1/stride of the full one.
TEST(ThinnedDataTerm, ScoresAboutOneInStrideOfTheReadings) {
  const MappingOptions options;
  const MappingData data = LaserMappingData(RoomData(), options);
  ASSERT_TRUE(data.make_thinned_data_term);
  const Coloring empty(data.window, options.cell_size);
  const auto full = data.make_data_term();
  ASSERT_FALSE(full->Reset(empty).has_value());
  for (const int stride : {2, 4}) {
    const auto thinned = data.make_thinned_data_term(stride, 0);
    ASSERT_FALSE(thinned->Reset(empty).has_value());
    const double ratio = FromFixed(thinned->log_likelihood()) / FromFixed(full->log_likelihood());
    EXPECT_NEAR(ratio, 1.0 / stride, 0.25 / stride) << "stride " << stride;
  }
}

// The shares of a stride score every reading once between them: their log-likelihoods sum to
// the full data's, on the empty map and on a map that a short run found.
TEST(ThinnedDataTerm, TheSharesOfAStrideSumToTheFullLogLikelihood) {
  const MappingOptions options;
  const MappingData data = LaserMappingData(RoomData(), options);
  const Coloring empty(data.window, options.cell_size);
  MappingOptions short_run = SmallRun(3, 3000, 0);
  short_run.chains = 1;
  short_run.anneal_steps = 1000;
  const MappingResult run = RunMapping(data, short_run, {});
  ASSERT_TRUE(run.map.has_value());
  ASSERT_GT(run.map->stats().edges, 0);
  for (const Coloring* coloring : {&empty, &*run.map}) {
    const auto full = data.make_data_term();
    ASSERT_FALSE(full->Reset(*coloring).has_value());
    for (const int stride : {2, 5}) {
      FixedLogLik sum = 0;
      for (int phase = 0; phase < stride; ++phase) {
        const auto share = data.make_thinned_data_term(stride, phase);
        ASSERT_FALSE(share->Reset(*coloring).has_value());
        sum += share->log_likelihood();
      }
      // Each reading's term is rounded to the fixed point once, in whichever term holds it.
      EXPECT_EQ(sum, full->log_likelihood()) << "stride " << stride;
    }
  }
}

MappingOptions WarmRun() {
  MappingOptions options = SmallRun(7, 30000, 8000);
  options.thinned_burn_in = {{.stride = 2, .steps = 8000}};
  options.warm_burn_in = {.temperature = 3.0, .steps = 9000};  // steps 8000 to 17000
  return options;
}

// Sessions of 7000 steps stop in the thinned stage, in the warm one and after it: the resumed
// chains must take up the temperature of the step they are at.
TEST(WarmMapping, AStoppedRunResumesToTheSameResult) {
  const MappingData data = LaserMappingData(RoomData(), WarmRun());
  const MappingResult whole = ExpectResumesExactly(data, WarmRun(), 7000, 6);  // 38000 steps

  // The warm stage changed the course of the chains (so the comparison above covers it).
  MappingOptions cold = WarmRun();
  cold.warm_burn_in = {};
  const MappingResult without = RunMapping(data, cold, {});
  EXPECT_NE(without.chains[0].log_posterior_trace, whole.chains[0].log_posterior_trace);
}

// A checkpoint of a run with a warm stage is not one of the run without it, and a warm stage
// that does not fit in the burn-in after the thinned stages is refused.
TEST(WarmMapping, ACheckpointOfAnotherScheduleAndAStageBeyondTheBurnInAreRefused) {
  MappingOptions other = WarmRun();
  other.warm_burn_in.temperature = 2.0;
  ExpectResumingAsOtherIsRefused(WarmRun(), other, 10000);

  const MappingData data = LaserMappingData(RoomData(), WarmRun());

  MappingOptions too_long = WarmRun();
  too_long.warm_burn_in.steps = 22001;  // the burn-in has 30000 - 8000 = 22000 left
  EXPECT_THROW((void)RunMapping(data, too_long, {}), ContractError);
  MappingOptions too_cold = WarmRun();
  too_cold.warm_burn_in.temperature = 0.5;
  EXPECT_THROW((void)RunMapping(data, too_cold, {}), ContractError);
}

MappingOptions ThinnedRun() {
  MappingOptions options = SmallRun(5, 30000, 10000);
  options.thinned_burn_in = {{.stride = 4, .steps = 10000}, {.stride = 2, .steps = 10000}};
  return options;
}

// Stages whose step counts sum past 2^64 must not wrap round to a sum that fits the burn-in.
TEST(ThinnedMapping, StagesWhoseSumWouldWrapAreRefused) {
  const MappingData data = LaserMappingData(RoomData(), ThinnedRun());
  MappingOptions wrapping = ThinnedRun();
  wrapping.thinned_burn_in = {{.stride = 4, .steps = std::numeric_limits<std::uint64_t>::max()},
                              {.stride = 2, .steps = 2}};
  EXPECT_THROW((void)RunMapping(data, wrapping, {}), ContractError);
}

MappingOptions RotatedRun() {
  MappingOptions options = ThinnedRun();
  options.thinned_rotation = 2500;  // sessions of 7000 stop inside a share
  options.thinned_weighed = true;
  return options;
}

// Rotated and weighed stages: sessions stop mid-share, and the resumed chains must take up the
// share (and weight) of the step they are at. The rotation and the weight each change the
// chains' course, and a checkpoint of the rotated run is not one of the plain thinned run.
TEST(ThinnedMapping, ARotatedWeighedRunResumesToTheSameResultAndIsItsOwnRun) {
  const MappingData data = LaserMappingData(RoomData(), RotatedRun());
  const MappingResult whole = ExpectResumesExactly(data, RotatedRun(), 7000, 6);  // 40000 steps

  MappingOptions unrotated = RotatedRun();
  unrotated.thinned_rotation = 0;
  MappingOptions unweighed = RotatedRun();
  unweighed.thinned_weighed = false;
  for (const MappingOptions& other : {unrotated, unweighed}) {
    const MappingResult result = RunMapping(data, other, {});
    EXPECT_NE(result.chains[0].log_posterior_trace, whole.chains[0].log_posterior_trace);
  }
  ExpectResumingAsOtherIsRefused(RotatedRun(), ThinnedRun(), 5000);
  ExpectResumingAsOtherIsRefused(RotatedRun(), unweighed, 5000);
}

// Sessions of 7000 steps stop inside each stage (7000, 14000, 21000, ...): the resumed chains
// must take up the data term of the stage they are in.
TEST(ThinnedMapping, AStoppedRunResumesToTheSameResult) {
  const MappingData data = LaserMappingData(RoomData(), ThinnedRun());
  const MappingResult whole = ExpectResumesExactly(data, ThinnedRun(), 7000, 6);  // 40000 steps

  // The thinning changed the course of the chains (so the comparison above covers it).
  MappingOptions unthinned = ThinnedRun();
  unthinned.thinned_burn_in.clear();
  const MappingResult full = RunMapping(data, unthinned, {});
  EXPECT_NE(full.chains[0].log_posterior_trace, whole.chains[0].log_posterior_trace);
}

MappingOptions DelayedAcceptanceRun() {
  MappingOptions options = SmallRun(6, 30000, 10000);
  options.thinned_burn_in = {{.stride = 2, .steps = 8000}};
  options.sampler.screen_stride = 4;
  options.anneal_steps = 9000;  // 7000 in the sixth session, 2000 in the seventh
  return options;
}

// Delayed acceptance screens the moves on all the data only: sessions of 7000 steps stop in the
// thinned stage (no screen), in the full-data steps and in the annealing, and the resumed chains
// must make their screens anew and go on exactly, their screened-out counts included.
TEST(DelayedAcceptanceMapping, AStoppedRunResumesToTheSameResult) {
  const MappingData data = LaserMappingData(RoomData(), DelayedAcceptanceRun());
  const MappingResult whole = ExpectResumesExactly(data, DelayedAcceptanceRun(), 7000, 7);
  testing::TempDir dir;
  const MappingResult part = RunInSessions(data, DelayedAcceptanceRun(), 7000, dir.path()).first;
  ASSERT_TRUE(whole.map && part.map);
  EXPECT_EQ(part.map_log_posterior, whole.map_log_posterior);
  for (std::size_t c = 0; c < whole.chains.size(); ++c) {
    const MoveCounter screened = Total(whole.chains[c].counters);
    EXPECT_EQ(Total(part.chains[c].counters).screened_out, screened.screened_out);
    EXPECT_GT(screened.screened_out, 1000u);
  }

  // The screen changed the course of the chains (so the comparison above covers it), and a
  // checkpoint of the screened run is not one of the unscreened run.
  MappingOptions unscreened = DelayedAcceptanceRun();
  unscreened.sampler.screen_stride = 1;
  const MappingResult plain = RunMapping(data, unscreened, {});
  EXPECT_NE(plain.chains[0].log_posterior_trace, whole.chains[0].log_posterior_trace);
  EXPECT_EQ(Total(plain.chains[0].counters).screened_out, 0u);
  ExpectResumingAsOtherIsRefused(DelayedAcceptanceRun(), unscreened, 5000);
}

// A coloring of `window` with a black triangle, away from the sensors' path.
Coloring TriangleStart(const Window& window, const MappingOptions& options, double size) {
  const Vec2 c = window.min + 0.3 * (window.max - window.min);
  const std::vector<NewVertex> vertices = {
      {c, kInterior}, {c + Vec2(size, 0.1), kInterior}, {c + Vec2(0.2, size), kInterior}};
  const std::vector<std::array<int, 2>> edges = {{0, 1}, {1, 2}, {2, 0}};
  return std::get<Coloring>(
      Coloring::FromGraph(window, options.cell_size, vertices, edges, Colour::kWhite));
}

// A prior-only run on a fixed window (no data term), whose chains can only propose boundary
// moves: from a start without boundary vertices they never change it.
MappingData PriorOnly() {
  MappingData data;
  data.window = Window{Vec2::Zero(), Vec2(4, 3)};
  data.trace_points = {Vec2(1.1, 1.0), Vec2(3.1, 2.2)};
  data.fingerprint = 123;
  data.make_data_term = [] { return std::unique_ptr<DataTerm>(); };
  return data;
}

MappingOptions FrozenOptions() {
  MappingOptions options;
  options.sampler.weights.weight.fill(0.0);
  options.sampler.weights[MoveKind::kBoundaryMove] = 1.0;
  options.burn_in = 0;
  options.samples = 1;
  options.chains = 1;
  options.trace_every = 1;
  return options;
}

// What a run records after a thinned burn-in is scored on every reading: with moves that cannot
// change the empty start (boundary moves, and no boundary vertex to move), the recorded
// log-posteriors are exactly those of the run without thinning, and not the thinned term's.
TEST(ThinnedMapping, RecordsTheLogPosteriorOfEveryReadingAfterTheBurnIn) {
  MappingOptions frozen = FrozenOptions();
  frozen.burn_in = 200;
  frozen.samples = 5;
  const MappingData data = LaserMappingData(RoomData(), frozen);
  const MappingResult full = RunMapping(data, frozen, {});

  MappingOptions thinned = frozen;
  thinned.thinned_burn_in = {{.stride = 4, .steps = 200}};
  const MappingResult after_thinning = RunMapping(data, thinned, {});
  ASSERT_EQ(full.chains[0].log_posterior_trace.size(), 5u);
  EXPECT_EQ(after_thinning.chains[0].log_posterior_trace, full.chains[0].log_posterior_trace);
  EXPECT_EQ(after_thinning.chains[0].log_posterior, full.chains[0].log_posterior);
}

TEST(MappingStart, EveryChainStartsFromTheGivenColoring) {
  MappingData data = PriorOnly();
  const MappingOptions options = FrozenOptions();
  data.start = TriangleStart(data.window, options, 1.5);
  const MappingResult result = RunMapping(data, options, {});
  ASSERT_TRUE(result.complete);
  const CellGrid& raster = result.raster;
  int black = 0;
  for (int iy = 0; iy < raster.ny; ++iy)
    for (int ix = 0; ix < raster.nx; ++ix) {
      const Vec2 centre =
          raster.origin + Vec2((ix + 0.5) * raster.cell.x(), (iy + 0.5) * raster.cell.y());
      const double expected = data.start->ColourAt(centre) == Colour::kBlack ? 1.0 : 0.0;
      ASSERT_EQ(result.black_fraction(iy, ix), expected) << "at (" << centre.transpose() << ")";
      black += expected > 0.0 ? 1 : 0;
    }
  EXPECT_GT(black, 50);  // the triangle covers about 1 m² of 0.1 m cells
  EXPECT_EQ(result.chains[0].edges, 3);

  // Without a start, the chains start from the empty white coloring.
  data.start.reset();
  const MappingResult empty = RunMapping(data, options, {});
  EXPECT_EQ(empty.black_fraction.maxCoeff(), 0.0);
}

TEST(MappingStart, ACheckpointOfARunFromAnotherStartIsRefused) {
  MappingData data = PriorOnly();
  MappingOptions options;
  options.sampler.p = 1.0;
  options.burn_in = 2000;
  options.samples = 2000;
  options.chains = 1;
  options.trace_every = 500;
  options.chunk = 500;
  data.start = TriangleStart(data.window, options, 1.5);
  testing::TempDir dir;
  const MappingSession stop = StoppingSession(dir.path(), 1000);
  ASSERT_FALSE(RunMapping(data, options, {}, stop).complete);
  MappingSession resume = stop;
  resume.resume = true;
  resume.stop_after_steps = 0;
  // Another start, or none, is another run.
  MappingData other = data;
  other.start = TriangleStart(data.window, options, 1.2);
  EXPECT_THROW((void)RunMapping(other, options, {}, resume), BinaryFormatError);
  other.start.reset();
  EXPECT_THROW((void)RunMapping(other, options, {}, resume), BinaryFormatError);
  // The same start resumes, to the end of the uninterrupted run.
  const MappingResult resumed = RunMapping(data, options, {}, resume);
  ASSERT_TRUE(resumed.complete);
  EXPECT_EQ(resumed.resumed_steps, 1000u);
  const MappingResult whole = RunMapping(data, options, {});
  EXPECT_EQ(resumed.black_fraction, whole.black_fraction);
  EXPECT_EQ(resumed.chains[0].log_posterior_trace, whole.chains[0].log_posterior_trace);
}

// A weighed term is its inner term's log-likelihood times the weight, recomputed or not, and so
// is its copy; weights below 1 are refused.
TEST(WeightedDataTerm, ScalesItsInnerTermsLogLikelihoodByTheWeight) {
  const MappingOptions options;
  const MappingData data = LaserMappingData(RoomData(), options);
  const Coloring empty(data.window, options.cell_size);
  const auto inner = data.make_thinned_data_term(4, 1);
  ASSERT_FALSE(inner->Reset(empty).has_value());
  WeightedDataTerm weighed(data.make_thinned_data_term(4, 1), 4);
  ASSERT_FALSE(weighed.Reset(empty).has_value());
  EXPECT_NE(inner->log_likelihood(), 0);
  EXPECT_EQ(weighed.log_likelihood(), 4 * inner->log_likelihood());
  EXPECT_EQ(weighed.RecomputeLogLikelihood(empty), 4 * inner->log_likelihood());
  EXPECT_FALSE(weighed.FindInconsistency(empty).has_value());
  const auto copy = weighed.Clone();
  EXPECT_EQ(copy->log_likelihood(), weighed.log_likelihood());
  EXPECT_THROW(WeightedDataTerm(data.make_thinned_data_term(4, 1), 0), ContractError);
  EXPECT_THROW(WeightedDataTerm(nullptr, 2), ContractError);
}

}  // namespace
}  // namespace priormap::prf
