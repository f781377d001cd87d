// The filter on inputs at the edge of what it accepts: observations at (or next to) the sensor,
// clusters larger than the enumeration can take, landmarks at a segment's endpoint or on its
// extension.
#include <cmath>
#include <limits>
#include <numbers>

#include <gtest/gtest.h>

#include <priormap/core/segment.hpp>
#include <priormap/slam/association_hypotheses.hpp>
#include <priormap/slam/prior_map_slam.hpp>
#include <priormap/slam/pseudo_observation.hpp>
#include <priormap/slam/range_bearing.hpp>

#include "testing/numeric_diff.hpp"

namespace priormap::slam {
namespace {

SlamOptions WithoutPrior() {
  SlamOptions options;
  options.use_prior_map = false;
  return options;
}

TEST(RangeSecondOrder, StaysFiniteAndBoundedAtAndNextToTheSensor) {
  const Mat2 C = Vec2(0.04, 0.09).asDiagonal();
  // The exact moments of sqrt(r^2 + t^2), t ~ N(0, var_t), are bounded as r -> 0: the mean
  // offset by E|t| = sqrt(2 var_t / pi), the variance by var_t.
  for (const Vec2& relative : {Vec2(1e-300, 0.0), Vec2(1e-3, 0.0), Vec2(0.0, 0.0)}) {
    const RangeCurvature c = RangeSecondOrder(relative, C);
    const double var_t = 0.09;  // across +x is y; at the sensor, the largest variance
    EXPECT_NEAR(c.mean_offset, std::sqrt(2.0 * var_t / std::numbers::pi), 1e-12) << relative;
    EXPECT_NEAR(c.variance, var_t, 1e-12) << relative;
  }
  // Far from the sensor the second-order terms themselves: var_t / (2 r), (var_t / r)^2 / 2.
  const RangeCurvature far = RangeSecondOrder(Vec2(30.0, 0.0), C);
  EXPECT_NEAR(far.mean_offset, 0.09 / 60.0, 1e-15);
  EXPECT_NEAR(far.variance, 0.5 * (0.09 / 30.0) * (0.09 / 30.0), 1e-15);
}

// A landmark first seen at a vanishing range sits at the sensor. It must not leave a non-finite
// covariance in the state, nor make every later update that observes it with others refused.
TEST(PriorMapSlam, ALandmarkFirstSeenAtAVanishingRangeDoesNotStopTheOthersUpdates) {
  SlamInput input;
  input.initial_pose = Se2(0.0, 0.0, 0.0);
  input.motion.push_back({1.0, 1.0, Se2(1.0, 0.0, 0.0)});
  input.motion.push_back({2.0, 1.0, Se2(1.0, 0.0, 0.0)});
  input.frames.push_back({0.0, {{1, 1e-300, 0.5}, {2, 5.0, 0.5}}});
  input.frames.push_back({1.0, {{1, 1.0, 3.0}, {2, 4.0, 0.6}}});
  input.frames.push_back({2.0, {{1, 2.0, 3.0}, {2, 3.0, 0.7}}});
  const SlamResult r = RunSlam(input, nullptr, WithoutPrior());
  EXPECT_EQ(r.rejected_updates, 0u);
  ASSERT_EQ(r.landmarks.size(), 2u);
  for (const LandmarkEstimate& landmark : r.landmarks) {
    EXPECT_TRUE(landmark.position.allFinite()) << "landmark " << landmark.id;
    EXPECT_TRUE(landmark.covariance.allFinite()) << "landmark " << landmark.id;
  }
  // The odometry says (2, 0); landmark 2's ranges, shorter than it predicts, moved the pose.
  EXPECT_GT(r.frames.back().estimate.x(), 2.05);
}

// The vehicle drives exactly onto a landmark's estimate: that observation has no Jacobian, and
// only it is left out; the other landmark of the frame still updates the pose.
TEST(PriorMapSlam, AnObservationOfALandmarkAtTheSensorIsLeftOutAlone) {
  SlamInput input;
  input.initial_pose = Se2(0.0, 0.0, 0.0);
  input.motion.push_back({1.0, 1.0, Se2(1.0, 0.0, 0.0)});
  input.frames.push_back({0.0, {{1, 1.0, 0.0}, {2, 5.0, 0.5}}});
  input.frames.push_back({1.0, {{1, 0.01, 0.0}, {2, 4.0, 0.6}}});
  const SlamResult r = RunSlam(input, nullptr, WithoutPrior());
  EXPECT_EQ(r.rejected_updates, 1u);
  EXPECT_TRUE(r.frames.back().covariance.allFinite());
  EXPECT_NE(r.frames.back().estimate.x(), 1.0);  // landmark 2 updated the pose
}

// Two more beacons on one wall than the enumeration can take, its prior segment 0.3 m off: every
// beacon gates with it, one cluster of kMaxEnumeratedPairs + 2 pairs.
TEST(PriorMapSlam, AClusterCapAboveWhatCanBeEnumeratedActsAsTheLargestThatCan) {
  PriorMap map;
  map.segments.push_back({Vec2(10.3, -30.0), Vec2(10.3, 30.0), 1.0, 0});
  map.buildings.push_back("building 0");
  ObservationFrame frame;
  for (int i = 0; i < kMaxEnumeratedPairs + 2; ++i) {
    const Vec2 beacon(10.0, -11.0 + i);
    frame.observations.push_back({i, beacon.norm(), std::atan2(beacon.y(), beacon.x())});
  }
  SlamOptions options;
  options.max_cluster_pairs = kMaxEnumeratedPairs + 10;
  PriorMapSlam slam(Se2(), 0.0, MotionNoise{}, SensorNoise{}, &map, options);
  ASSERT_NO_THROW((void)slam.Observe(frame));
  const SlamResult r = slam.Finish();
  EXPECT_EQ(r.inference.largest_cluster, static_cast<std::size_t>(kMaxEnumeratedPairs + 2));
  EXPECT_EQ(r.inference.deferred_points, 2u);
  EXPECT_EQ(r.inference.hypotheses, std::size_t{1} << kMaxEnumeratedPairs);
}

// The pseudo-observation's rows at degenerate geometry: the point at an endpoint, beyond one on
// the line's extension, and far along it, against central differences over the whole state.
TEST(PointOnSegmentObservation, RowsMatchDifferencesAtEndpointsAndOnTheExtension) {
  const Vec2 a(1.0, 2.0), b(7.0, 4.5);
  const Vec2 along = (b - a).normalized();
  const Vec2 normal(-along.y(), along.x());
  for (const Vec2& point : {a, b, Vec2(b + 3.0 * along), Vec2(a - 2.0 * along + 0.4 * normal),
                            Vec2(a + 1e4 * along + 0.1 * normal)}) {
    const auto state_of = [](const Eigen::VectorXd& x) {
      JointState state(Se2::FromVector(x.head<3>()), Mat3::Identity());
      state.AddLandmark(0, x.segment<2>(3), Mat23::Zero(), Mat2::Identity(), Mat2::Identity());
      state.AddSegment(4, x.segment<2>(5), x.segment<2>(7), Mat4::Identity());
      return state;
    };
    Eigen::VectorXd x(9);
    x << 0.1, -0.2, 0.3, point, a, b;
    const std::pair<int, int> relation(0, 4);
    const Linearization m = PointOnSegmentObservation(state_of(x), std::span(&relation, 1), 0.05);
    const auto theta = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
      return -PointOnSegmentObservation(state_of(v), std::span(&relation, 1), 0.05).innovation;
    };
    EXPECT_TRUE(
        testing::JacobiansMatch(Eigen::MatrixXd(m.H), testing::NumericJacobian(theta, x), 1e-6))
        << "point " << point.transpose() << "\n"
        << Eigen::MatrixXd(m.H);
  }
}

}  // namespace
}  // namespace priormap::slam
