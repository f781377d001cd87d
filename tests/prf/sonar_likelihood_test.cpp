// The PRF sonar likelihood: readings are selected from a log's rings as documented; an edit in
// front of a cone changes what it sees and its likelihood as the model says; a sensor is never
// put in black; and the dynamic cone index answers what a recomputation from scratch answers,
// bit for bit, after long chains of random moves on simulated and real sonar logs.
#include <cmath>
#include <cstdint>
#include <memory>
#include <numbers>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <priormap/core/robond_sonar_io.hpp>
#include <priormap/core/scene.hpp>
#include <priormap/core/simulate.hpp>
#include <priormap/core/sonar_simulate.hpp>
#include <priormap/prf/sampler.hpp>
#include <priormap/prf/sonar_likelihood.hpp>

#include "testing/temp_dir.hpp"

namespace priormap::prf {
namespace {

// A ring of two transducers offset from the robot, a laser scan, and a ring with an invalid
// and a max-range reading.
Log MixedLog() {
  Log log;
  Scan laser;
  laser.pose = Se2(0, 0, 0);
  laser.angles = {0.0};
  laser.ranges = {1.0};
  laser.sigma = {0.01};
  laser.max_range = 8.0;
  laser.ClassifyAll();
  log.scans.push_back(laser);
  for (int k = 0; k < 2; ++k) {
    Scan ring;
    ring.channel = "SONAR";
    ring.pose = Se2(k, 1.0, std::numbers::pi / 2);
    ring.angles = {0.5, -0.5};
    ring.ranges = {std::nan(""), 6.0};
    ring.sigma = {0.01, 0.01};
    ring.min_range = 0.1;
    ring.max_range = 5.0;
    ring.ClassifyAll();
    ring.sonar.emplace().spread = 0.4;
    ring.sonar->origins = {Vec2(0.2, 0.1), Vec2(0.2, -0.1)};
    log.scans.push_back(ring);
  }
  log.scans.back().ranges[0] = 2.0;
  log.scans.back().ClassifyAll();
  return log;
}

TEST(SelectSonarReadings, TakesTheRingsConesAndSkipsLaserScansAndInvalidReadings) {
  const auto selected = SelectSonarReadings(
      MixedLog(), {.first_scan = 0, .end_scan = std::nullopt, .max_range = 3.5});
  ASSERT_TRUE(selected.ok()) << selected.error();
  const SonarData& data = selected.value();
  EXPECT_EQ(data.max_range, 3.5);
  ASSERT_EQ(data.readings.size(), 3u);  // the first ring's NaN is left out
  const SonarReading& first = data.readings[0];
  EXPECT_TRUE(first.max_reading);  // 6 m is beyond the ring's 5 m
  // The transducer at (0.2, -0.1) of a robot at (0, 1) facing +y is at (0.1, 1.2).
  EXPECT_NEAR((first.cone.origin - Vec2(0.1, 1.2)).norm(), 0.0, 1e-15);
  EXPECT_NEAR(first.cone.axis.dot(UnitVector(std::numbers::pi / 2 - 0.5)), 1.0, 1e-15);
  EXPECT_EQ(first.cone.half_spread, 0.2);
  EXPECT_EQ(first.cone.max_range, 3.5);
  const SonarReading& valid = data.readings[1];
  EXPECT_FALSE(valid.max_reading);
  EXPECT_EQ(valid.range, 2.0);
  EXPECT_EQ(data.sensors.size(), 3u);  // one apex in the first ring, two in the second

  Log laser_only = MixedLog();
  laser_only.scans.resize(1);
  const auto none = SelectSonarReadings(laser_only, {});
  ASSERT_FALSE(none.ok());
  ASSERT_EQ(none.diagnostics().size(), 1u);
  EXPECT_EQ(none.diagnostics().front().Location(), "") << "a selection is not a file";
  EXPECT_THAT(none.diagnostics().front().message, ::testing::HasSubstr("no sonar ring"));
}

// One cone from (0.2, 0.5) along +x, 30 deg wide, in the unit square.
std::shared_ptr<const SonarData> OneCone(double reading) {
  auto data = std::make_shared<SonarData>();
  data->sensors = {Vec2(0.2, 0.5)};
  data->max_range = 5.0;
  data->readings = {{.cone = {.origin = Vec2(0.2, 0.5),
                              .axis = Vec2::UnitX(),
                              .half_spread = std::numbers::pi / 12,
                              .max_range = 5.0},
                     .range = reading,
                     .max_reading = false,
                     .sensor = 0}};
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

TEST(SonarLikelihood, AnEditInTheConeChangesWhatItSeesAndItsLikelihood) {
  const Window window{Vec2::Zero(), Vec2::Ones()};
  Coloring coloring(window, 0.1);
  const auto data = OneCone(0.5);
  SonarLikelihood likelihood(data, SonarModel{});
  ASSERT_FALSE(likelihood.Reset(coloring));
  EXPECT_EQ(likelihood.extent(0), 5.0);  // sees nothing
  const SonarModel model;
  EXPECT_EQ(likelihood.log_likelihood(), ToFixed(model.LogLikelihood(0.5, false, {}, 5.0)));
  const FixedLogLik before = likelihood.log_likelihood();

  // A triangle whose left side, at x = 0.7, faces the sensor across the whole cone.
  const Edit edit = Triangle({0.7, 0.2}, {0.9, 0.5}, {0.7, 0.8});
  EditEffect effect;
  ASSERT_TRUE(coloring.Evaluate(edit, &effect));
  const auto delta = likelihood.Evaluate(coloring, edit);
  ASSERT_TRUE(delta);
  const auto added = coloring.Apply(edit, effect);
  likelihood.Commit({added.begin(), added.size()});
  EXPECT_EQ(likelihood.log_likelihood() - before, *delta);
  EXPECT_EQ(likelihood.FindInconsistency(coloring), std::nullopt);

  const SonarView view = likelihood.View(coloring, 0);
  ASSERT_EQ(view.features.size(), 1u);  // the face at normal incidence; its corners are outside
  EXPECT_NEAR(view.features[0].distance, 0.5, 1e-15);
  EXPECT_NEAR(view.features[0].projection, std::numbers::pi / 2, 1e-15);
  EXPECT_NEAR(likelihood.extent(0), 0.5 / std::cos(std::numbers::pi / 12), 1e-12);
  EXPECT_EQ(likelihood.log_likelihood(),
            ToFixed(model.LogLikelihood(0.5, false, view.features, 5.0)));
  // The reading at the face's distance is now much likelier than with nothing there.
  EXPECT_GT(FromFixed(*delta), 2.0);
}

TEST(SonarLikelihood, ASensorIsNeverPutInOccupiedSpace) {
  const Window window{Vec2::Zero(), Vec2::Ones()};
  Coloring coloring(window, 0.1);
  SonarLikelihood likelihood(OneCone(0.5), SonarModel{});
  ASSERT_FALSE(likelihood.Reset(coloring));
  const Edit around_sensor = Triangle({0.1, 0.4}, {0.3, 0.4}, {0.2, 0.6});
  EditEffect effect;
  ASSERT_TRUE(coloring.Evaluate(around_sensor, &effect));
  EXPECT_FALSE(likelihood.Evaluate(coloring, around_sensor));
  coloring.Apply(around_sensor, effect);
  const auto problem = likelihood.Reset(coloring);
  ASSERT_TRUE(problem);
  EXPECT_NE(problem->find("occupied"), std::string::npos);
}

// Runs `steps` sampler steps on `data`, checking the incremental state against a recomputation
// every `check_every` steps and at the end.
void ExpectIncrementalEqualsRecomputed(std::shared_ptr<const SonarData> data, double p,
                                       double temperature, int steps, int check_every,
                                       std::uint64_t seed, const SonarModel& model = {}) {
  const Window window = WindowAround(*data, 1.0);
  SamplerOptions options;
  options.p = p;
  options.temperature = temperature;
  options.birth_scale = 1.0;
  options.step_scales = {0.05, 0.2, 1.0};
  auto likelihood = std::make_unique<SonarLikelihood>(data, model);
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

std::shared_ptr<const SonarData> Selected(const Log& log, double max_range) {
  const auto selected =
      SelectSonarReadings(log, {.first_scan = 0, .end_scan = std::nullopt, .max_range = max_range});
  if (!selected) {
    ADD_FAILURE() << selected.error();
    return nullptr;
  }
  return std::make_shared<const SonarData>(selected.value());
}

// Simulated pioneer16 rings along the office's trajectory (0.5 m/s, 2 rings/s), R = 5 m.
std::shared_ptr<const SonarData> OfficeRings(std::uint64_t seed) {
  const Scene scene = *BuiltinScene("office");
  const SonarSensor sensor = *SonarSensor::Preset("pioneer16");
  const auto trajectory = TrajectoryFromWaypoints(scene.waypoints, 0.5, 2.0);
  return Selected(SimulateSonarLog(scene, sensor, trajectory, seed), 5.0);
}

TEST(SonarLikelihood, IncrementalEqualsRecomputedAfter100kMovesOnASimulatedLog) {
  const auto data = OfficeRings(7);
  ASSERT_TRUE(data);
  EXPECT_GT(data->readings.size(), 1000u);
  ExpectIncrementalEqualsRecomputed(data, 0.3, 1.0, 100000, 10000, 1);
  // Hot: many more moves accepted, much more structure.
  ExpectIncrementalEqualsRecomputed(data, 0.3, 20.0, 100000, 10000, 2);
}

// With the model's default parameters a corner's concavity and the share of the cone seen
// change nothing: a model that weighs them shows whether the incremental views keep them as a
// recomputation does.
TEST(SonarLikelihood, IncrementalEqualsRecomputedWithConcaveCornersAndTheClearMixture) {
  const auto data = OfficeRings(8);
  ASSERT_TRUE(data);
  SonarModel model;
  model.concave_corner_bias = 2.0;
  model.clear_uniform_weight = 0.05;
  model.clear_exponential_weight = 0.05;
  model.clear_max_weight = 0.9;
  ExpectIncrementalEqualsRecomputed(data, 0.3, 1.0, 30000, 5000, 5, model);
  ExpectIncrementalEqualsRecomputed(data, 0.3, 20.0, 30000, 5000, 6, model);
}

// With multipath, a reading also hangs on the leg of its axis's path beyond the mirror: the
// incremental state must follow edits there too (edges removed from or added across the leg).
TEST(SonarLikelihood, IncrementalEqualsRecomputedWithMultipath) {
  const auto data = OfficeRings(9);
  ASSERT_TRUE(data);
  SonarModel model;
  model.multipath_weight = 0.4;
  model.multipath_sigma_relative = 0.02;
  model.clear_uniform_weight = 0.05;
  model.clear_exponential_weight = 0.05;
  model.clear_max_weight = 0.9;
  ExpectIncrementalEqualsRecomputed(data, 0.3, 1.0, 50000, 5000, 7, model);
  ExpectIncrementalEqualsRecomputed(data, 0.3, 20.0, 50000, 5000, 8, model);
}

TEST(SonarLikelihood, IncrementalEqualsRecomputedAfter100kMovesOnTheRealSonarLog) {
  const auto shared = testing::SharedDataDir();
  if (!shared) GTEST_SKIP() << "../shared/data is absent: no real sonar log to test on";
  const auto log =
      ReadRoboNdSonar(*shared / "sonar-roboND/measurement.txt", *shared / "sonar-roboND/poses.txt");
  ASSERT_TRUE(log.ok()) << log.error();
  const auto data = Selected(log.value(), 5.0);
  ASSERT_TRUE(data);
  ExpectIncrementalEqualsRecomputed(data, 0.1, 1.0, 100000, 10000, 3);
  ExpectIncrementalEqualsRecomputed(data, 0.1, 10.0, 100000, 10000, 4);
}

}  // namespace
}  // namespace priormap::prf
