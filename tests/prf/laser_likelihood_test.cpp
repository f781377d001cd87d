// The PRF laser likelihood: the beam model is a probability distribution for every first-hit
// distance; beams are selected from a log as documented; the dynamic beam index answers what a
// recomputation from scratch answers, after long chains of random moves on simulated and real
// logs (bit for bit, the log-likelihoods being fixed point).
#include <cmath>
#include <limits>
#include <memory>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <priormap/core/log_io.hpp>
#include <priormap/core/range_sensor.hpp>
#include <priormap/core/scene.hpp>
#include <priormap/core/scene_ray_caster.hpp>
#include <priormap/core/simulate.hpp>
#include <priormap/prf/laser_likelihood.hpp>
#include <priormap/prf/sampler.hpp>

#include "testing/temp_dir.hpp"

namespace priormap::prf {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// ∫_0^R p(r | d) dr + P(max | d), by Simpson's rule on a grid fine against σ.
double TotalProbability(const LaserModel& model, double d, double max_range) {
  const int n = 200000;  // even
  const double h = max_range / n;
  double sum = 0.0;
  for (int i = 0; i <= n; ++i) {
    const double weight = (i == 0 || i == n) ? 1.0 : (i % 2 == 1 ? 4.0 : 2.0);
    // The open end: the density just below R.
    const double r = std::min(i * h, max_range * (1.0 - 1e-15));
    sum += weight * std::exp(model.LogLikelihood(r, false, d, max_range));
  }
  return sum * h / 3.0 + std::exp(model.LogLikelihood(max_range, true, d, max_range));
}

TEST(LaserModel, IsAProbabilityDistributionForEveryDistance) {
  const LaserModel model;
  ASSERT_EQ(model.Problem(), "");
  for (double d : {0.01, 0.05, 0.2, 3.0, 7.9, 8.0, 8.1, kInf})
    EXPECT_NEAR(TotalProbability(model, d, 8.0), 1.0, 1e-6) << "d = " << d;
  const LaserModel wide{.sigma = 0.5, .hit_weight = 0.6, .outlier_weight = 0.3, .max_weight = 0.1};
  for (double d : {0.1, 1.0, 4.0, 7.8, kInf})
    EXPECT_NEAR(TotalProbability(wide, d, 8.0), 1.0, 1e-6) << "d = " << d;
}

TEST(LaserModel, PeaksAtTheFirstHitAndCallsMissingReturnsLikelyWithoutAHit) {
  const LaserModel model;
  EXPECT_GT(model.LogLikelihood(3.0, false, 3.0, 8.0), model.LogLikelihood(3.2, false, 3.0, 8.0));
  EXPECT_GT(model.LogLikelihood(8.0, true, kInf, 8.0), model.LogLikelihood(8.0, true, 3.0, 8.0));
  EXPECT_NEAR(std::exp(model.LogLikelihood(8.0, true, kInf, 8.0)),
              model.hit_weight + model.max_weight, 1e-12);
}

TEST(LaserModel, ReportsBadParameters) {
  EXPECT_NE(LaserModel{.sigma = 0.0}.Problem(), "");
  EXPECT_NE((LaserModel{.sigma = 0.1, .hit_weight = 0.9, .outlier_weight = 0.1, .max_weight = 0.0})
                .Problem(),
            "");
  EXPECT_NE((LaserModel{.sigma = 0.1, .hit_weight = 0.5, .outlier_weight = 0.1, .max_weight = 0.1})
                .Problem(),
            "");
}

Log TwoScanLog() {
  Log log;
  for (int k = 0; k < 2; ++k) {
    Scan scan;
    scan.pose = Se2(k, 0.0, 0.0);
    scan.angles = {-0.5, 0.0, 0.5, 1.0};
    scan.ranges = {2.0, std::nan(""), 30.0, 9.0};
    scan.status = {BeamStatus::kValid, BeamStatus::kInvalid, BeamStatus::kMaxRange,
                   BeamStatus::kValid};
    scan.sigma.assign(4, 0.01);
    scan.max_range = 30.0;
    log.scans.push_back(scan);
  }
  return log;
}

TEST(SelectBeams, DropsInvalidReadingsAndCapsTheMaxRange) {
  const auto selected = SelectBeams(
      TwoScanLog(), {.first_scan = 1, .end_scan = std::nullopt, .beam_step = 1, .max_range = 8.0});
  ASSERT_TRUE(selected.ok()) << selected.error();
  const LaserData& data = selected.value();
  EXPECT_EQ(data.max_range, 8.0);
  ASSERT_EQ(data.sensors.size(), 1u);
  EXPECT_EQ(data.sensors[0], Vec2(1.0, 0.0));
  ASSERT_EQ(data.beams.size(), 3u);  // the NaN is left out
  EXPECT_FALSE(data.beams[0].max_reading);
  EXPECT_TRUE(data.beams[1].max_reading);  // the sensor's own max reading
  EXPECT_TRUE(data.beams[2].max_reading);  // 9 m is beyond R = 8 m
  EXPECT_NEAR(data.beams[2].direction.dot(UnitVector(1.0)), 1.0, 1e-15);
}

TEST(SelectBeams, ExplainsAnEmptySelection) {
  const auto selected = SelectBeams(
      TwoScanLog(), {.first_scan = 2, .end_scan = std::nullopt, .beam_step = 1, .max_range = 8.0});
  ASSERT_FALSE(selected.ok());
  ASSERT_EQ(selected.diagnostics().size(), 1u);
  const Diagnostic& why = selected.diagnostics().front();
  EXPECT_EQ(why.Location(), "") << "a selection is not a file: no position to give";
  EXPECT_THAT(why.message, ::testing::HasSubstr("the scan range 2:2 selects no scan"));
}

// One beam from (0.2, 0.5) along +x in the unit square.
std::shared_ptr<const LaserData> OneBeam(double reading) {
  auto data = std::make_shared<LaserData>();
  data->sensors = {Vec2(0.2, 0.5)};
  data->beams = {{.origin = Vec2(0.2, 0.5),
                  .direction = Vec2::UnitX(),
                  .range = reading,
                  .max_reading = false,
                  .sensor = 0}};
  data->max_range = 5.0;
  return data;
}

Edit Triangle(Vec2 a, Vec2 b, Vec2 c) {
  Edit edit;
  for (const Vec2& v : {a, b, c}) {
    edit.new_vertices.push_back({v, kInterior});
    edit.flipped_region.push_back(v);
  }
  for (int i = 0; i < 3; ++i)
    edit.added_edges.push_back({VertexRef::New(i), VertexRef::New((i + 1) % 3)});
  return edit;
}

TEST(LaserLikelihood, AnEditInFrontOfTheBeamChangesItsDistanceAndLikelihood) {
  const Window window{Vec2::Zero(), Vec2::Ones()};
  Coloring coloring(window, 0.1);
  LaserLikelihood likelihood(OneBeam(0.5), LaserModel{}, 0.1);
  ASSERT_FALSE(likelihood.Reset(coloring));
  EXPECT_EQ(likelihood.distance(0), kInf);  // the window's side is 0.8 m away
  const FixedLogLik before = likelihood.log_likelihood();

  const Edit edit = Triangle({0.7, 0.3}, {0.9, 0.4}, {0.7, 0.7});  // its left side at x = 0.7
  EditEffect effect;
  ASSERT_TRUE(coloring.Evaluate(edit, &effect));
  const auto delta = likelihood.Evaluate(coloring, edit);
  ASSERT_TRUE(delta);
  const auto added = coloring.Apply(edit, effect);
  likelihood.Commit({added.begin(), added.size()});
  EXPECT_NEAR(likelihood.distance(0), 0.5, 1e-15);
  const LaserModel model;
  EXPECT_EQ(likelihood.log_likelihood() - before, *delta);
  EXPECT_NEAR(FromFixed(likelihood.log_likelihood()), model.LogLikelihood(0.5, false, 0.5, 5.0),
              1e-9);
  EXPECT_EQ(likelihood.FindInconsistency(coloring), std::nullopt);
}

TEST(LaserLikelihood, ASensorIsNeverPutInOccupiedSpace) {
  const Window window{Vec2::Zero(), Vec2::Ones()};
  Coloring coloring(window, 0.1);
  LaserLikelihood likelihood(OneBeam(0.5), LaserModel{}, 0.1);
  ASSERT_FALSE(likelihood.Reset(coloring));
  const Edit around_sensor = Triangle({0.1, 0.4}, {0.3, 0.4}, {0.2, 0.6});
  EditEffect effect;
  ASSERT_TRUE(coloring.Evaluate(around_sensor, &effect));
  EXPECT_FALSE(likelihood.Evaluate(coloring, around_sensor));
  // A reset on a coloring with the sensor in black says so.
  coloring.Apply(around_sensor, effect);
  const auto problem = likelihood.Reset(coloring);
  ASSERT_TRUE(problem);
  EXPECT_NE(problem->find("occupied"), std::string::npos);
}

// Runs `steps` sampler steps on `data`, checking the incremental state against a recomputation
// every `check_every` steps and at the end.
void ExpectIncrementalEqualsRecomputed(std::shared_ptr<const LaserData> data, double p,
                                       double temperature, int steps, int check_every,
                                       std::uint64_t seed) {
  const Window window = WindowAround(*data, 1.0);
  SamplerOptions options;
  options.p = p;
  options.temperature = temperature;
  options.birth_scale = 1.0;
  options.step_scales = {0.05, 0.2, 1.0};
  auto likelihood = std::make_unique<LaserLikelihood>(data, LaserModel{}, 0.5);
  PrfSampler sampler(Coloring(window, 0.5), options, seed, std::move(likelihood));
  for (int done = 0; done < steps; done += check_every) {
    sampler.Run(static_cast<std::uint64_t>(check_every));
    const auto problem = sampler.data()->FindInconsistency(sampler.coloring());
    ASSERT_FALSE(problem) << "after " << done + check_every << " steps: " << *problem;
  }
  EXPECT_EQ(sampler.data()->log_likelihood(),
            sampler.data()->RecomputeLogLikelihood(sampler.coloring()));
  // The chain moved and built structure, so the check compared something.
  EXPECT_GT(Total(sampler.counters()).accepted, static_cast<std::uint64_t>(steps) / 50);
  EXPECT_GT(sampler.coloring().stats().edges, 10);
}

TEST(LaserLikelihood, IncrementalEqualsRecomputedOnASimulatedLog) {
  const Scene scene = *BuiltinScene("l-room");
  const RangeSensor sensor = *RangeSensor::Preset("lms200");
  const auto trajectory = TrajectoryFromWaypoints(scene.waypoints, 0.5, 1.0);
  const Log log = SimulateLog(scene, sensor, trajectory, 7);
  const auto selected = SelectBeams(
      log, {.first_scan = 0, .end_scan = std::nullopt, .beam_step = 4, .max_range = 8.0});
  ASSERT_TRUE(selected.ok()) << selected.error();
  auto data = std::make_shared<const LaserData>(selected.value());
  ExpectIncrementalEqualsRecomputed(data, 0.5, 1.0, 20000, 2000, 1);
  // Hot: many more moves accepted, much more structure.
  ExpectIncrementalEqualsRecomputed(data, 0.5, 20.0, 20000, 2000, 2);
}

TEST(LaserLikelihood, IncrementalEqualsRecomputedAfter100kMovesOnARealLog) {
  const auto shared = testing::SharedDataDir();
  if (!shared) GTEST_SKIP() << "../shared/data is absent: no real log to test on";
  const auto log = ReadLog(*shared / "laser-corrected/intel-corrected.log.gz");
  ASSERT_TRUE(log.ok()) << log.error();
  // About the paper's 5,550 measurements: 185 scans, every 6th beam.
  const auto selected = SelectBeams(
      log.value(), {.first_scan = 0, .end_scan = 185, .beam_step = 6, .max_range = 20.0});
  ASSERT_TRUE(selected.ok()) << selected.error();
  auto data = std::make_shared<const LaserData>(selected.value());
  EXPECT_NEAR(static_cast<double>(data->beams.size()), 5550.0, 100.0);
  ExpectIncrementalEqualsRecomputed(data, 0.1, 1.0, 100000, 10000, 3);
  ExpectIncrementalEqualsRecomputed(data, 0.1, 10.0, 100000, 10000, 4);
}

}  // namespace
}  // namespace priormap::prf
