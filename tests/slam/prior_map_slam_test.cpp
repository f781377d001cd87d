// The filter on small worlds whose answers are known, and on the urban study's data.
#include <limits>
#include <map>
#include <set>

#include <Eigen/Eigenvalues>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/check.hpp>
#include <priormap/core/rng.hpp>
#include <priormap/slam/prior_map_slam.hpp>
#include <priormap/slam/range_bearing.hpp>
#include <priormap/slam/study.hpp>
#include <priormap/slam/urban_scenario.hpp>

namespace priormap::slam {
namespace {

// A vehicle standing still at the origin facing +x, a wall ahead: five beacons on the wall
// x = 10 (y = -6 .. 6), and the prior map's segment for that wall 0.8 m off.
struct WallWorld {
  std::vector<Vec2> beacons{{10.0, -6.0}, {10.0, -3.0}, {10.0, 0.0}, {10.0, 3.0}, {10.0, 6.0}};
  PriorMap map;
  WallWorld() {
    map.segments.push_back({Vec2(10.8, -10.0), Vec2(10.8, 10.0), 1.0, 0});
    map.buildings.push_back("building 0");
  }
};

ObservationFrame Observe(const std::vector<Vec2>& beacons, double time, Rng& rng,
                         const SensorNoise& noise) {
  ObservationFrame frame;
  frame.time = time;
  for (std::size_t i = 0; i < beacons.size(); ++i) {
    const Vec2 z = ObserveRangeBearing(Se2(), beacons[i]);
    frame.observations.push_back({static_cast<int>(i), z.x() + rng.Normal(0.0, noise.range_std),
                                  WrapAngle(z.y() + rng.Normal(0.0, noise.bearing_std))});
  }
  return frame;
}

MotionStep StandStill(double time, double dt) {
  return {time, dt, BicycleControl{0.0, 0.0}};
}

// Options and prior maps that would give non-finite numbers are refused when the filter is made,
// not frames later (or never, when no pair is ever gated).
TEST(PriorMapSlam, PriorsOutOfRangeAndUnboundedSegmentStdsAreRefusedAtTheStart) {
  const WallWorld world;
  SlamOptions options;
  options.priors.p_point_on_line = 1.0;
  EXPECT_THROW(PriorMapSlam(Se2(), 0.0, MotionNoise{}, SensorNoise{}, &world.map, options),
               ContractError);
  PriorMap map = world.map;
  map.segments[0].std = 1e200;  // its variance, 1e400, is infinite
  EXPECT_THROW(PriorMapSlam(Se2(), 0.0, MotionNoise{}, SensorNoise{}, &map, SlamOptions{}),
               ContractError);
}

// The largest std a prior map may give keeps the filter finite.
TEST(PriorMapSlam, ASegmentAsUncertainAsTheWorldKeepsEstimatesFinite) {
  WallWorld world;
  world.map.segments[0].std = kMaxPriorStd;
  const SensorNoise sensor;
  // A null density uniform over the gate scales with the segment's uncertainty as the related
  // pairs' likelihood does, so relations are still accepted and the segment enters the state.
  SlamOptions options;
  options.null_density = NullDensity::kUniformOverGate;
  PriorMapSlam slam(Se2(), 0.0, MotionNoise{}, sensor, &world.map, options);
  Rng rng(4);
  for (int f = 1; f <= 10; ++f) {
    slam.Predict(StandStill(0.2 * f, 0.2));
    const FrameRecord frame = slam.Observe(Observe(world.beacons, 0.2 * f, rng, sensor));
    ASSERT_TRUE(frame.covariance.allFinite()) << f;
  }
  const SlamResult result = slam.Finish();
  EXPECT_GT(result.relations.size(), 0u);  // the segment was used, not left out
  for (const SegmentEstimate& s : result.segments) {
    EXPECT_TRUE(s.a.allFinite() && s.b.allFinite() && s.covariance.allFinite());
  }
  for (const LandmarkEstimate& l : result.landmarks) {
    EXPECT_TRUE(l.position.allFinite() && l.covariance.allFinite());
  }
}

TEST(PriorMapSlam, PointsOnAWallPullTheNoisyPriorSegmentOntoIt) {
  const WallWorld world;
  MotionNoise motion;
  motion.speed_std = 1e-3;
  motion.steer_std = 1e-3;
  const SensorNoise sensor;
  PriorMapSlam slam(Se2(), 0.0, motion, sensor, &world.map, SlamOptions{});
  Rng rng(4);
  int accepted = 0;
  for (int f = 1; f <= 20; ++f) {
    slam.Predict(StandStill(0.2 * f, 0.2));
    accepted += slam.Observe(Observe(world.beacons, 0.2 * f, rng, sensor)).accepted;
  }
  const SlamResult result = slam.Finish();
  EXPECT_EQ(accepted, 5);
  ASSERT_EQ(result.relations.size(), 5u);
  ASSERT_EQ(result.segments.size(), 1u);
  // The segment now lies on the points' line, x = 10, within their uncertainty, far inside its
  // prior error of 0.8 m.
  EXPECT_NEAR(result.segments[0].a.x(), 10.0, 0.05);
  EXPECT_NEAR(result.segments[0].b.x(), 10.0, 0.05);
  for (const RelationRecord& r : result.relations) EXPECT_FALSE(r.flagged);
}

TEST(PriorMapSlam, FlagsARelationWhoseLandmarkTurnsOutOffTheWall) {
  WallWorld world;
  MotionNoise motion;
  motion.speed_std = 1e-3;
  motion.steer_std = 1e-3;
  const SensorNoise sensor;
  PriorMapSlam slam(Se2(), 0.0, motion, sensor, &world.map, SlamOptions{});
  Rng rng(5);
  int f = 1;
  for (; f <= 10; ++f) {
    slam.Predict(StandStill(0.2 * f, 0.2));
    (void)slam.Observe(Observe(world.beacons, 0.2 * f, rng, sensor));
  }
  ASSERT_EQ(slam.Finish().relations.size(), 5u);
  // Beacon 2 was a sign 1.5 m in front of the wall all along, wrongly related; its range now
  // says so (as if it had been misread before).
  world.beacons[2].x() = 8.5;
  for (; f <= 40; ++f) {
    slam.Predict(StandStill(0.2 * f, 0.2));
    (void)slam.Observe(Observe(world.beacons, 0.2 * f, rng, sensor));
  }
  const SlamResult result = slam.Finish();
  int flagged = 0;
  for (const RelationRecord& r : result.relations) {
    if (r.flagged) {
      ++flagged;
      EXPECT_EQ(r.landmark, 2);
    }
  }
  EXPECT_EQ(flagged, 1);
}

// Building 0's corner: wall A (x = 10) and wall B (y = 5), three beacons on each and one at the
// corner, which lies on both lines, so no single wall can ever be chosen for it. With relations
// to buildings it is related to "some wall of building 0" (the eq. 3 mixture); without, never.
TEST(PriorMapSlam, ACornerBeaconIsRelatedToSomeWallOfItsBuilding) {
  const std::vector<Vec2> beacons{{10.0, -6.0}, {10.0, -3.0}, {10.0, 0.0}, {13.0, 5.0},
                                  {16.0, 5.0},  {19.0, 5.0},  {10.0, 5.0}};
  PriorMap map;
  map.buildings = {"building 0"};
  map.segments = {{Vec2(10.4, -10.0), Vec2(10.4, 5.3), 0.5, 0},
                  {Vec2(10.4, 5.3), Vec2(20.0, 5.3), 0.5, 0}};
  MotionNoise motion;
  motion.speed_std = 1e-3;
  motion.steer_std = 1e-3;
  const SensorNoise sensor;
  auto run = [&](bool building_relations) {
    SlamOptions options;
    options.building_relations = building_relations;
    PriorMapSlam slam(Se2(), 0.0, motion, sensor, &map, options);
    Rng rng(6);
    for (int f = 1; f <= 30; ++f) {
      slam.Predict(StandStill(0.2 * f, 0.2));
      (void)slam.Observe(Observe(beacons, 0.2 * f, rng, sensor));
    }
    return slam.Finish();
  };
  auto corner_of = [](const SlamResult& result) {
    for (const LandmarkEstimate& l : result.landmarks) {
      if (l.id == 6) return l;
    }
    ADD_FAILURE() << "the corner beacon is not in the map";
    return LandmarkEstimate{.id = 6, .position = Vec2::Zero(), .covariance = Mat2::Identity()};
  };

  const SlamResult with = run(true);
  const SlamResult without = run(false);
  EXPECT_EQ(with.building_relations, 1u);
  EXPECT_EQ(without.building_relations, 0u);
  std::vector<std::pair<int, int>> with_walls, without_walls;
  for (const RelationRecord& r : with.relations) {
    if (r.building < 0) {
      with_walls.emplace_back(r.landmark, r.segment);
      continue;
    }
    EXPECT_EQ(r.landmark, 6);
    EXPECT_EQ(r.building, 0);
    EXPECT_EQ(r.walls, (std::vector<int>{0, 1}));
  }
  for (const RelationRecord& r : without.relations) {
    EXPECT_EQ(r.building, -1);
    EXPECT_NE(r.landmark, 6);
    without_walls.emplace_back(r.landmark, r.segment);
  }
  // Beacons on the walls are related to their own walls, alike in both runs.
  EXPECT_GE(without_walls.size(), 3u);
  EXPECT_EQ(with_walls, without_walls);
  for (const auto& [landmark, segment] : with_walls) EXPECT_EQ(segment, landmark < 3 ? 0 : 1);
  // A mixture of "on A" and "on B" is a weak constraint on a point that lies on both; the
  // estimate stays consistent with the truth (squared Mahalanobis error within chi2(2, 99.9 %)).
  const LandmarkEstimate corner = corner_of(with);
  const Vec2 error = corner.position - Vec2(10.0, 5.0);
  EXPECT_LT(error.dot(corner.covariance.inverse() * error), 13.8);
}

TEST(PriorMapSlam, WithoutAPriorMapItIsPlainEkfSlam) {
  const WallWorld world;
  const SensorNoise sensor;
  PriorMapSlam slam(Se2(), 0.0, MotionNoise{}, sensor, nullptr, SlamOptions{});
  Rng rng(6);
  for (int f = 1; f <= 5; ++f) {
    slam.Predict(StandStill(0.2 * f, 0.2));
    const FrameRecord record = slam.Observe(Observe(world.beacons, 0.2 * f, rng, sensor));
    EXPECT_EQ(record.accepted, 0);
    EXPECT_EQ(record.segments, 0);
    EXPECT_EQ(record.landmarks, 5);
  }
}

class UrbanRunTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    world_ = new UrbanWorld(MakeUrbanWorld(options_, 1));
    run_ = new UrbanRun(SimulateUrbanRun(*world_, options_, 1, 0));
  }
  static void TearDownTestSuite() {
    delete run_;
    delete world_;
  }
  static inline UrbanScenarioOptions options_{};
  static inline UrbanWorld* world_ = nullptr;
  static inline UrbanRun* run_ = nullptr;
};

TEST_F(UrbanRunTest, CovarianceStaysSymmetricPositiveSemiDefiniteOverAWholeRun) {
  const SlamInput& input = run_->input;
  PriorMapSlam slam(input.initial_pose, input.start_time, input.motion_noise, input.sensor_noise,
                    &run_->prior_map, SlamOptions{});
  std::size_t f = 0, checked = 0;
  double worst = 0.0;
  for (const MotionStep& step : input.motion) {
    slam.Predict(step);
    while (f < input.frames.size() && input.frames[f].time <= step.time + 1e-9) {
      (void)slam.Observe(input.frames[f++]);
      const Eigen::MatrixXd& P = slam.state().covariance();
      ASSERT_TRUE(P.isApprox(P.transpose(), 0.0)) << "asymmetric at frame " << f;
      if (f % 10 == 0) {
        const double smallest = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(P).eigenvalues()(0);
        worst = std::min(worst, smallest / P.diagonal().maxCoeff());
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 40u);
  EXPECT_GT(worst, -1e-12) << "most negative eigenvalue relative to the largest variance";
  EXPECT_GT(slam.Finish().relations.size(), 30u);  // pseudo-observations were exercised
}

TEST_F(UrbanRunTest, NearestNeighbourAssociationFindsTheSameMapAsKnownIds) {
  SlamInput blind = run_->input;
  for (ObservationFrame& frame : blind.frames) {
    for (RangeBearing& z : frame.observations) z.id = -1;
  }
  SlamOptions nn;
  nn.association = AssociationMode::kNearestNeighbour;
  nn.use_prior_map = false;
  SlamOptions known;
  known.use_prior_map = false;
  const RunTrace a = ScoreRun(RunSlam(run_->input, nullptr, known), run_->frame_truth);
  const RunTrace b = ScoreRun(RunSlam(blind, nullptr, nn), run_->frame_truth);
  const double known_rms = Summarise({a}, 0.0, 1e9).rms_position_m;
  const double nn_rms = Summarise({b}, 0.0, 1e9).rms_position_m;
  EXPECT_LT(nn_rms, 1.5 * known_rms + 0.5) << "known ids " << known_rms << " m";
  // About as many landmarks as beacons were initialised (a few extra from ambiguous starts).
  EXPECT_NEAR(static_cast<double>(b.result.landmarks_created),
              static_cast<double>(a.result.landmarks_created),
              0.1 * static_cast<double>(a.result.landmarks_created));
}

TEST_F(UrbanRunTest, SlidingWindowDropsLandmarksUnseenForItsLength) {
  SlamOptions keep_all;
  keep_all.use_prior_map = false;
  keep_all.window_s = 0.0;
  SlamOptions window;
  window.use_prior_map = false;
  const SlamResult all = RunSlam(run_->input, nullptr, keep_all);
  const SlamResult windowed = RunSlam(run_->input, nullptr, window);
  std::vector<int> seen;
  for (const ObservationFrame& frame : run_->input.frames) {
    for (const RangeBearing& z : frame.observations) seen.push_back(z.id);
  }
  std::sort(seen.begin(), seen.end());
  seen.erase(std::unique(seen.begin(), seen.end()), seen.end());
  EXPECT_EQ(all.landmarks.size(), seen.size());
  EXPECT_LT(windowed.landmarks.size(), all.landmarks.size() / 4);
  EXPECT_GT(windowed.landmarks_created, seen.size());  // re-initialised when seen again
}

TEST_F(UrbanRunTest, EveryLandmarkIsMappedAtItsEstimateInTheLastFrameThatKeptIt) {
  const SlamInput& input = run_->input;
  PriorMapSlam slam(input.initial_pose, input.start_time, input.motion_noise, input.sensor_noise,
                    &run_->prior_map, SlamOptions{});
  // What a user could read off the state after each frame, by landmark id.
  std::map<int, MappedLandmark> expected;
  std::size_t f = 0;
  for (const MotionStep& step : input.motion) {
    slam.Predict(step);
    while (f < input.frames.size() && input.frames[f].time <= step.time + 1e-9) {
      const double time = slam.Observe(input.frames[f++]).time;
      for (const LandmarkEstimate& l : slam.Finish().landmarks)
        expected[l.id] = {.estimate = l, .last_time = time};
    }
  }
  const SlamResult result = slam.Finish();
  for (const LandmarkEstimate& l : result.landmarks) expected.at(l.id).in_state = true;

  ASSERT_EQ(result.all_landmarks.size(), expected.size());
  std::size_t dropped = 0;
  auto want = expected.begin();
  for (const MappedLandmark& got : result.all_landmarks) {
    const int id = want->first;
    EXPECT_EQ(got.estimate.id, id);
    EXPECT_EQ(got.estimate.position, want->second.estimate.position) << "landmark " << id;
    EXPECT_EQ(got.estimate.covariance, want->second.estimate.covariance) << "landmark " << id;
    EXPECT_EQ(got.last_time, want->second.last_time) << "landmark " << id;
    EXPECT_EQ(got.in_state, want->second.in_state) << "landmark " << id;
    if (!got.in_state) {
      ++dropped;
      EXPECT_LT(got.last_time, result.frames.back().time) << "landmark " << id;
    }
    ++want;
  }
  // Most were dropped by the window (so the comparison above is mostly about them), and every
  // beacon the drive saw is mapped.
  EXPECT_GT(dropped, 3 * result.landmarks.size());
  std::set<int> seen;
  for (const ObservationFrame& frame : input.frames) {
    for (const RangeBearing& z : frame.observations) seen.insert(z.id);
  }
  EXPECT_EQ(expected.size(), seen.size());
}

TEST(RunSlam, AFrameAtAnIncrementsStartIsObservedBeforeIt) {
  SlamInput input;
  input.initial_pose = Se2(0.0, 0.0, 0.0);
  input.frames.push_back({0.0, {{0, 5.0, 0.0}}});  // a landmark 5 m ahead, seen at the start
  input.frames.push_back({1.0, {}});
  input.motion.push_back({1.0, 1.0, Se2(1.0, 0.0, 0.0)});  // then 1 m forward
  SlamOptions options;
  options.use_prior_map = false;
  const SlamResult r = RunSlam(input, nullptr, options);
  ASSERT_EQ(r.frames.size(), 2u);
  EXPECT_NEAR(r.frames[0].time, 0.0, 1e-12);
  EXPECT_NEAR(r.frames[0].estimate.x(), 0.0, 1e-12);
  EXPECT_NEAR(r.frames[1].estimate.x(), 1.0, 1e-12);
  ASSERT_EQ(r.landmarks.size(), 1u);
  EXPECT_TRUE(r.landmarks[0].position.isApprox(Vec2(5.0, 0.0), 1e-12));
}

TEST(RunSlam, AFilterWhosePoseIsNoLongerFiniteStopsSayingWhen) {
  SlamInput input;
  input.frames.push_back({2.0, {{0, 5.0, 0.0}}});
  input.motion.push_back({1.0, 1.0, Se2(1.0, 0.0, 0.0)});
  input.motion.push_back({2.0, 1.0, Se2(1.0, 0.0, 0.0)});
  input.motion_noise.increment_std = Vec3(std::numeric_limits<double>::infinity(), 0.05, 0.005);
  SlamOptions options;
  options.use_prior_map = false;
  try {
    (void)RunSlam(input, nullptr, options);
    ADD_FAILURE() << "no SlamDiverged";
  } catch (const SlamDiverged& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("after a motion step at t = 1 s"));
  }
}

TEST(RunSlam, FramesInsideABicycleStepSplitIt) {
  SlamInput split, whole;
  for (SlamInput* input : {&split, &whole}) {
    input->initial_pose = Se2(0.0, 0.0, 0.0);
    input->frames.push_back({0.3, {{0, 10.0, 0.1}}});
  }
  whole.motion.push_back({0.5, 0.5, BicycleControl{2.0, 0.1}});
  split.motion.push_back({0.3, 0.3, BicycleControl{2.0, 0.1}});
  split.motion.push_back({0.5, 0.2, BicycleControl{2.0, 0.1}});
  SlamOptions options;
  options.use_prior_map = false;
  const SlamResult a = RunSlam(split, nullptr, options);
  const SlamResult b = RunSlam(whole, nullptr, options);
  ASSERT_EQ(a.frames.size(), 1u);
  ASSERT_EQ(b.frames.size(), 1u);
  EXPECT_TRUE(IsApprox(a.frames[0].estimate, b.frames[0].estimate, 1e-12));
  EXPECT_NEAR(a.frames[0].time, 0.3, 1e-12);
  ASSERT_EQ(a.landmarks.size(), 1u);
  EXPECT_TRUE(a.landmarks[0].position.isApprox(b.landmarks[0].position, 1e-12));
}

}  // namespace
}  // namespace priormap::slam
