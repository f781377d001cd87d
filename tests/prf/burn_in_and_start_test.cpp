// Mapping runs with a tempered burn-in (MappingOptions::burn_in_temperature), a thinned one
// (MappingOptions::thinned_burn_in) and a given start (MappingData::start): the temperature
// schedule; which readings a thinned stage keeps, where each stage ends, the thinned data term;
// runs stopped and resumed from checkpoints (across changes of temperature and of data term)
// ending as the uninterrupted run; what a run records after a thinned burn-in; chains starting
// where they are told, and checkpoints of a run from another start refused.
#include <cmath>
#include <cstddef>
#include <memory>
#include <tuple>
#include <utility>
#include <variant>
#include <vector>

#include <gtest/gtest.h>

#include <priormap/core/binary_io.hpp>
#include <priormap/core/range_sensor.hpp>
#include <priormap/core/scene.hpp>
#include <priormap/core/simulate.hpp>
#include <priormap/prf/mapping.hpp>

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

MappingOptions TemperedRun() {
  MappingOptions options;
  options.sampler.p = 0.5;
  options.burn_in = 40000;  // at 4, then 2 (block 10000), then 1 from 20000 on
  options.burn_in_temperature = 4.0;
  options.samples = 8000;
  options.chains = 2;
  options.seed = 9;
  options.trace_every = 1000;
  options.chunk = 3000;
  return options;
}

TEST(TemperedMapping, AStoppedRunResumesToTheSameResult) {
  const MappingData data = LaserMappingData(RoomData(), TemperedRun());
  const MappingResult whole = RunMapping(data, TemperedRun(), {});
  ASSERT_TRUE(whole.complete);

  // Sessions of 7000 steps stop mid-block (7000, 14000, ...): the resumed chains must take up
  // the temperature of the block they are in.
  testing::TempDir dir;
  const auto [part, sessions] = RunInSessions(data, TemperedRun(), 7000, dir.path());
  EXPECT_EQ(sessions, 7);  // 48000 steps a chain
  EXPECT_EQ(part.black_fraction, whole.black_fraction);
  EXPECT_EQ(part.white_fraction, whole.white_fraction);
  for (std::size_t c = 0; c < 2; ++c) {
    EXPECT_EQ(part.chains[c].log_posterior_trace, whole.chains[c].log_posterior_trace);
    EXPECT_EQ(part.chains[c].point_traces, whole.chains[c].point_traces);
    EXPECT_EQ(part.chains[c].log_posterior, whole.chains[c].log_posterior);
  }

  // The tempering changed the course of the chains (so the comparison above covers it).
  MappingOptions untempered = TemperedRun();
  untempered.burn_in_temperature = 1.0;
  const MappingResult cold = RunMapping(data, untempered, {});
  EXPECT_NE(cold.chains[0].log_posterior_trace, whole.chains[0].log_posterior_trace);
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
    const auto thinned = data.make_thinned_data_term(stride);
    ASSERT_FALSE(thinned->Reset(empty).has_value());
    const double ratio = FromFixed(thinned->log_likelihood()) / FromFixed(full->log_likelihood());
    EXPECT_NEAR(ratio, 1.0 / stride, 0.25 / stride) << "stride " << stride;
  }
}

MappingOptions ThinnedRun() {
  MappingOptions options;
  options.sampler.p = 0.5;
  options.burn_in = 30000;
  options.thinned_burn_in = {{.stride = 4, .steps = 10000}, {.stride = 2, .steps = 10000}};
  options.samples = 10000;
  options.chains = 2;
  options.seed = 5;
  options.trace_every = 1000;
  options.chunk = 3000;
  return options;
}

TEST(ThinnedMapping, AStoppedRunResumesToTheSameResult) {
  const MappingData data = LaserMappingData(RoomData(), ThinnedRun());
  const MappingResult whole = RunMapping(data, ThinnedRun(), {});
  ASSERT_TRUE(whole.complete);

  // Sessions of 7000 steps stop inside each stage (7000, 14000, 21000, ...): the resumed chains
  // must take up the data term of the stage they are in.
  testing::TempDir dir;
  const auto [part, sessions] = RunInSessions(data, ThinnedRun(), 7000, dir.path());
  EXPECT_EQ(sessions, 6);  // 40000 steps a chain
  EXPECT_EQ(part.black_fraction, whole.black_fraction);
  for (std::size_t c = 0; c < 2; ++c) {
    EXPECT_EQ(part.chains[c].log_posterior_trace, whole.chains[c].log_posterior_trace);
    EXPECT_EQ(part.chains[c].point_traces, whole.chains[c].point_traces);
  }

  // The thinning changed the course of the chains (so the comparison above covers it).
  MappingOptions unthinned = ThinnedRun();
  unthinned.thinned_burn_in.clear();
  const MappingResult full = RunMapping(data, unthinned, {});
  EXPECT_NE(full.chains[0].log_posterior_trace, whole.chains[0].log_posterior_trace);
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

}  // namespace
}  // namespace priormap::prf
