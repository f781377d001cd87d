// The Jacobians the filter itself applies, against central differences of the measurement and
// motion functions over the whole joint state (pose + landmarks). models_test.cpp checks the
// models' Jacobians one at a time; these tests check that PriorMapSlam places them at the right
// offsets of the state, pairs each observation's rows with its innovation, leaves the columns of
// landmarks that are not observed at zero, wraps bearings and headings at +-pi, and linearises
// where it documents (SlamOptions::first_estimates_jacobians): a landmark's measurement Jacobian
// at its first estimate, the motion Jacobian's heading column from the pose predicted before the
// last update.
//
// The filter builds H and F privately, so they are read back from what it does to the state:
//  - an update with H, R and innovation nu satisfies, for any H (Woodbury),
//      P+^-1 - P^-1 = H^T R^-1 H   and   P+^-1 (x+ - x) = H^T R^-1 nu;
//  - a prediction with F (3x3, on the pose) maps the pose-landmark cross-covariance to
//    P+_vm = F P_vm, which gives F when P_vm has rank 3, and P+_vv = F P_vv F^T + Q.
// The expectations are built from NumericJacobian of ObserveRangeBearing, IncrementMotion and
// BicycleMotion (the nonlinear functions), never from an analytic Jacobian.
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <priormap/core/angles.hpp>
#include <priormap/slam/prior_map_slam.hpp>
#include <priormap/slam/range_bearing.hpp>
#include <priormap/slam/vehicle_model.hpp>

#include "testing/numeric_diff.hpp"

namespace priormap::slam {
namespace {

using priormap::testing::JacobiansMatch;
using priormap::testing::NumericJacobian;
using priormap::testing::WrapComponent;

constexpr double kPi = std::numbers::pi;

// Large enough noise that the state's covariance is well conditioned (its inverse is formed).
MotionNoise TestMotionNoise() {
  MotionNoise noise;
  noise.wheelbase = 2.5;
  noise.speed_std = 0.4;
  noise.steer_std = 0.06;
  noise.increment_std = Vec3(0.3, 0.2, 0.08);
  return noise;
}

SensorNoise TestSensorNoise() {
  return {.range_std = 0.2, .bearing_std = 0.04};
}

SlamOptions Options(bool first_estimates, bool second_order) {
  SlamOptions options;
  options.window_s = 0.0;  // keep every landmark
  options.first_estimates_jacobians = first_estimates;
  options.second_order_range = second_order;
  return options;
}

MotionStep Increment(double time, double dt, const Se2& increment, const Vec3& std) {
  MotionStep step{time, dt, increment};
  step.increment_std = std;
  return step;
}

struct Snapshot {
  Eigen::VectorXd mean;
  Eigen::MatrixXd covariance;
};

Snapshot Take(const PriorMapSlam& slam) {
  return {slam.state().mean(), slam.state().covariance()};
}

// External landmark id -> offset of its block in the state: Finish() names each landmark by its
// external id with its position, which is found among the state's blocks.
std::map<int, int> OffsetsByExternalId(const PriorMapSlam& slam) {
  std::map<int, int> offsets;
  const JointState& state = slam.state();
  for (const LandmarkEstimate& landmark : slam.Finish().landmarks) {
    for (const StateBlock& block : state.blocks()) {
      if (block.kind == BlockKind::kLandmark &&
          state.mean().segment<2>(block.offset) == landmark.position) {
        offsets[landmark.id] = block.offset;
      }
    }
  }
  return offsets;
}

// The stacked (range, bearing) of landmarks `ids` (external ids, in this order) from the pose,
// as a function of the whole state vector.
Eigen::VectorXd Measurements(const Eigen::VectorXd& x, const std::vector<int>& ids,
                             const std::map<int, int>& offsets) {
  Eigen::VectorXd z(2 * static_cast<Eigen::Index>(ids.size()));
  const Se2 pose = Se2::FromVector(x.head<3>());
  for (std::size_t k = 0; k < ids.size(); ++k) {
    z.segment<2>(2 * static_cast<Eigen::Index>(k)) =
        ObserveRangeBearing(pose, x.segment<2>(offsets.at(ids[k])));
  }
  return z;
}

Eigen::VectorXd WrapOddComponents(Eigen::VectorXd v) {
  for (Eigen::Index i = 1; i < v.size(); i += 2) v[i] = WrapAngle(v[i]);
  return v;
}

// A frame re-observing landmarks `ids` at h(current mean) + offsets[k].
ObservationFrame Reobserve(const PriorMapSlam& slam, double time, const std::vector<int>& ids,
                           const std::vector<Vec2>& offsets) {
  const Eigen::VectorXd predicted =
      Measurements(slam.state().mean(), ids, OffsetsByExternalId(slam));
  ObservationFrame frame;
  frame.time = time;
  for (std::size_t k = 0; k < ids.size(); ++k) {
    const Vec2 z = predicted.segment<2>(2 * static_cast<Eigen::Index>(k)) + offsets[k];
    frame.observations.push_back({ids[k], z.x(), WrapAngle(z.y())});
  }
  return frame;
}

// Heading pi - 0.03, an increment that turns it across +pi, four landmarks (one straight behind
// the vehicle, bearing ~ +-pi), another increment, then a frame that re-observes all four with
// large innovations, so that the pose and the landmarks move away from their first estimates and
// become correlated. Returns the pose the last prediction produced (FEJ's "pose predicted before
// the last update"); `first_estimates`: the landmarks' positions when they were added.
Se2 BuildFourLandmarkState(PriorMapSlam& slam, std::map<int, Vec2>* first_estimates = nullptr) {
  slam.Predict(Increment(1.0, 1.0, Se2(0.5, 0.1, 0.04), Vec3(0.3, 0.2, 0.08)));
  EXPECT_LT(slam.state().pose().theta(), -kPi + 0.05);  // wrapped across +pi
  ObservationFrame first;
  first.time = 1.0;
  first.observations = {{7, 6.0, 0.4}, {3, 4.0, -1.2}, {9, 5.0, kPi - 0.004}, {5, 8.0, 2.0}};
  slam.Observe(first);
  if (first_estimates) {
    const std::map<int, int> offsets = OffsetsByExternalId(slam);
    for (const auto& [id, offset] : offsets) {
      (*first_estimates)[id] = slam.state().mean().segment<2>(offset);
    }
  }
  slam.Predict(Increment(2.0, 1.0, Se2(0.4, -0.05, 0.02), Vec3(0.3, 0.2, 0.08)));
  const Se2 predicted = slam.state().pose();
  slam.Observe(
      Reobserve(slam, 2.0, {5, 9, 3, 7},
                {Vec2(0.35, 0.06), Vec2(-0.3, -0.05), Vec2(0.25, 0.07), Vec2(-0.2, 0.05)}));
  return predicted;
}

// --- the measurement Jacobian ------------------------------------------------------------------

struct UpdateCheck {
  Eigen::MatrixXd information_gain;           // P+^-1 - P^-1, from the filter
  Eigen::VectorXd weighted_innovation;        // P+^-1 (x+ - x), from the filter
  Eigen::MatrixXd expected_information_gain;  // H^T R^-1 H, H by central differences
  Eigen::VectorXd expected_weighted_innovation;
  Eigen::MatrixXd numeric_H;
};

// Observes landmarks 9 and 7 (in that order; 3 and 5 unobserved) with innovations that wrap at
// +-pi, and compares the update's information with that of H = central differences of h over the
// whole state at `linearization` (built from the state before the update).
UpdateCheck CheckUpdate(PriorMapSlam& slam, const SensorNoise& sensor, bool second_order,
                        const std::map<int, Vec2>* first_estimates) {
  const std::vector<int> ids = {9, 7};
  const std::map<int, int> offsets = OffsetsByExternalId(slam);
  const Snapshot before = Take(slam);
  const Se2 pose = Se2::FromVector(before.mean.head<3>());
  EXPECT_GT(std::abs(pose.theta()), kPi - 0.1) << "the heading should be near +-pi";
  const Eigen::VectorXd predicted = Measurements(before.mean, ids, offsets);
  EXPECT_GT(std::abs(predicted[1]), kPi - 0.1) << "landmark 9 should be behind the vehicle";

  // Landmark 9's measured bearing lies 0.02 rad across +-pi from its predicted one.
  const double across = std::copysign(kPi - std::abs(predicted[1]) + 0.02, predicted[1]);
  const std::vector<Vec2> offsets_z = {Vec2(0.12, across), Vec2(-0.1, 0.02)};
  const ObservationFrame frame = Reobserve(slam, 3.0, ids, offsets_z);
  EXPECT_GT(std::abs(frame.observations[0].bearing - predicted[1]), kPi);
  slam.Observe(frame);
  EXPECT_EQ(slam.Finish().rejected_updates, 0u);
  const Snapshot after = Take(slam);

  Eigen::VectorXd linearization = before.mean;
  if (first_estimates) {
    for (const auto& [id, offset] : offsets) {
      linearization.segment<2>(offset) = first_estimates->at(id);
    }
  }
  const auto h = [&](const Eigen::VectorXd& x) -> Eigen::VectorXd {
    return Measurements(x, ids, offsets);
  };
  UpdateCheck check;
  check.numeric_H = NumericJacobian(h, linearization, 1e-6, WrapOddComponents);

  Eigen::VectorXd z(4);
  z << frame.observations[0].range, frame.observations[0].bearing, frame.observations[1].range,
      frame.observations[1].bearing;
  Eigen::VectorXd innovation = WrapOddComponents(z - predicted);
  Eigen::VectorXd R(4);
  for (int k = 0; k < 2; ++k) {
    R[2 * k] = sensor.range_std * sensor.range_std;
    R[2 * k + 1] = sensor.bearing_std * sensor.bearing_std;
    if (second_order) {
      // SlamOptions::second_order_range: the range's mean and variance gain RangeSecondOrder's
      // terms for the landmark's position relative to the vehicle.
      const int o = offsets.at(ids[static_cast<std::size_t>(k)]);
      const Eigen::MatrixXd& P = before.covariance;
      const Mat2 relative =
          P.block<2, 2>(o, o) + P.topLeftCorner<2, 2>() - P.block<2, 2>(o, 0) - P.block<2, 2>(0, o);
      const RangeCurvature curvature =
          RangeSecondOrder(before.mean.segment<2>(o) - pose.translation(), relative);
      innovation[2 * k] -= curvature.mean_offset;
      R[2 * k] += curvature.variance;
    }
  }
  const Eigen::MatrixXd R_inverse = R.cwiseInverse().asDiagonal();
  check.expected_information_gain = check.numeric_H.transpose() * R_inverse * check.numeric_H;
  check.expected_weighted_innovation = check.numeric_H.transpose() * R_inverse * innovation;

  const int n = static_cast<int>(before.mean.size());
  const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(n, n);
  const Eigen::MatrixXd P_inverse = before.covariance.llt().solve(I);
  const Eigen::MatrixXd P_after_inverse = after.covariance.llt().solve(I);
  check.information_gain = P_after_inverse - P_inverse;
  Eigen::VectorXd step = after.mean - before.mean;
  step[2] = WrapAngle(step[2]);
  check.weighted_innovation = P_after_inverse * step;
  return check;
}

void ExpectUnobservedBlocksZero(const UpdateCheck& check, const std::map<int, int>& offsets) {
  const double scale = check.expected_information_gain.cwiseAbs().maxCoeff();
  for (int id : {3, 5}) {
    const int o = offsets.at(id);
    EXPECT_LT(check.information_gain.middleCols(o, 2).cwiseAbs().maxCoeff(), 1e-9 * scale)
        << "landmark " << id << " is not observed";
    EXPECT_LT(check.weighted_innovation.segment<2>(o).cwiseAbs().maxCoeff(), 1e-9 * scale)
        << "landmark " << id;
    EXPECT_EQ(check.numeric_H.middleCols(o, 2).cwiseAbs().maxCoeff(), 0.0);
  }
}

// The textbook EKF: H at the current mean.
TEST(FilterJacobians, UpdateAppliesTheCentralDifferencesOfTheObservationsOverTheWholeState) {
  const SensorNoise sensor = TestSensorNoise();
  PriorMapSlam slam(Se2(2.0, -1.0, kPi - 0.03), 0.0, TestMotionNoise(), sensor, nullptr,
                    Options(false, false));
  BuildFourLandmarkState(slam);
  slam.Predict(Increment(3.0, 1.0, Se2(0.3, 0.05, 0.01), Vec3(0.3, 0.2, 0.08)));
  const std::map<int, int> offsets = OffsetsByExternalId(slam);
  ASSERT_EQ(offsets.size(), 4u);
  ASSERT_EQ(slam.state().dim(), 11);
  const UpdateCheck check = CheckUpdate(slam, sensor, false, nullptr);
  EXPECT_TRUE(JacobiansMatch(check.information_gain, check.expected_information_gain, 1e-7));
  EXPECT_TRUE(JacobiansMatch(check.weighted_innovation, check.expected_weighted_innovation, 1e-7));
  ExpectUnobservedBlocksZero(check, offsets);
}

// The default filter: FEJ (each landmark's rows at its first estimate, with the current pose)
// and the range's second-order terms.
TEST(FilterJacobians, FirstEstimatesUpdateAppliesTheDifferencesAtTheLandmarksFirstEstimates) {
  const SensorNoise sensor = TestSensorNoise();
  PriorMapSlam slam(Se2(2.0, -1.0, kPi - 0.03), 0.0, TestMotionNoise(), sensor, nullptr,
                    Options(true, true));
  std::map<int, Vec2> first_estimates;
  BuildFourLandmarkState(slam, &first_estimates);
  slam.Predict(Increment(3.0, 1.0, Se2(0.3, 0.05, 0.01), Vec3(0.3, 0.2, 0.08)));
  const std::map<int, int> offsets = OffsetsByExternalId(slam);
  ASSERT_EQ(offsets.size(), 4u);
  // The update of the second frame moved the landmarks well away from their first estimates.
  for (const auto& [id, offset] : offsets) {
    EXPECT_GT((slam.state().mean().segment<2>(offset) - first_estimates.at(id)).norm(), 0.03)
        << "landmark " << id;
  }
  const UpdateCheck check = CheckUpdate(slam, sensor, true, &first_estimates);
  EXPECT_TRUE(JacobiansMatch(check.information_gain, check.expected_information_gain, 1e-7));
  EXPECT_TRUE(JacobiansMatch(check.weighted_innovation, check.expected_weighted_innovation, 1e-7));
  ExpectUnobservedBlocksZero(check, offsets);
}

// The same state with FEJ off is linearised at the current mean: the first estimates' check above
// is discriminating (it does not hold for the textbook filter's H).
TEST(FilterJacobians, FirstEstimatesCheckRejectsTheCurrentMeansJacobian) {
  const SensorNoise sensor = TestSensorNoise();
  PriorMapSlam slam(Se2(2.0, -1.0, kPi - 0.03), 0.0, TestMotionNoise(), sensor, nullptr,
                    Options(false, false));
  std::map<int, Vec2> first_estimates;
  BuildFourLandmarkState(slam, &first_estimates);
  slam.Predict(Increment(3.0, 1.0, Se2(0.3, 0.05, 0.01), Vec3(0.3, 0.2, 0.08)));
  const UpdateCheck check = CheckUpdate(slam, sensor, false, &first_estimates);
  EXPECT_FALSE(JacobiansMatch(check.information_gain, check.expected_information_gain, 1e-7));
}

// --- the motion Jacobian -----------------------------------------------------------------------

struct PredictionCheck {
  Mat3 F;                           // from P+_vm = F P_vm
  Mat3 Q;                           // P+_vv - F P_vv F^T
  Eigen::MatrixXd full_transition;  // diag(F, I): what the prediction does to the whole state
  Eigen::VectorXd mean_after;
  Snapshot before;
};

PredictionCheck Predict(PriorMapSlam& slam, const MotionStep& step) {
  PredictionCheck check;
  check.before = Take(slam);
  slam.Predict(step);
  const Snapshot after = Take(slam);
  const int n = static_cast<int>(check.before.mean.size());
  const Eigen::MatrixXd P_vm = check.before.covariance.topRightCorner(3, n - 3);
  const Eigen::MatrixXd P_vm_after = after.covariance.topRightCorner(3, n - 3);
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(P_vm);
  EXPECT_GT(svd.singularValues()[2], 1e-3 * svd.singularValues()[0])
      << "the pose-landmark cross-covariance must have rank 3 to recover F";
  check.F = (P_vm * P_vm.transpose()).ldlt().solve(P_vm * P_vm_after.transpose()).transpose();
  check.Q = after.covariance.topLeftCorner<3, 3>() -
            check.F * check.before.covariance.topLeftCorner<3, 3>() * check.F.transpose();
  // The landmarks and their covariance are untouched: the rest of the transition is the identity.
  EXPECT_EQ(after.mean.tail(n - 3), check.before.mean.tail(n - 3));
  EXPECT_EQ(after.covariance.bottomRightCorner(n - 3, n - 3),
            check.before.covariance.bottomRightCorner(n - 3, n - 3));
  check.full_transition = Eigen::MatrixXd::Identity(n, n);
  check.full_transition.topLeftCorner<3, 3>() = check.F;
  check.mean_after = after.mean;
  return check;
}

// The whole state after the motion g: the pose moves, the landmarks stay.
Eigen::VectorXd MoveWholeState(const Eigen::VectorXd& x, const MotionStep& step, double wheelbase) {
  Eigen::VectorXd out = x;
  const Se2 pose = Se2::FromVector(x.head<3>());
  if (const auto* control = std::get_if<BicycleControl>(&step.motion)) {
    out.head<3>() = BicycleMotion(pose, *control, step.dt, wheelbase).vector();
  } else {
    out.head<3>() = IncrementMotion(pose, std::get<Se2>(step.motion)).vector();
  }
  return out;
}

// Q = G diag(sigma^2) G^T with G the central differences of the motion by its noisy inputs.
Mat3 ExpectedProcessNoise(const Se2& pose, const MotionStep& step, const MotionNoise& noise) {
  if (const auto* control = std::get_if<BicycleControl>(&step.motion)) {
    const auto by_control = [&](const Eigen::VectorXd& u) -> Eigen::VectorXd {
      return BicycleMotion(pose, {u[0], u[1]}, step.dt, noise.wheelbase).vector();
    };
    const Eigen::MatrixXd G =
        NumericJacobian(by_control, Vec2(control->speed, control->steer), 1e-6, WrapComponent(2));
    return G *
           Vec2(noise.speed_std * noise.speed_std, noise.steer_std * noise.steer_std).asDiagonal() *
           G.transpose();
  }
  const Se2& increment = std::get<Se2>(step.motion);
  const auto by_increment = [&](const Eigen::VectorXd& d) -> Eigen::VectorXd {
    return IncrementMotion(pose, Se2::FromVector(d)).vector();
  };
  const Eigen::MatrixXd G =
      NumericJacobian(by_increment, increment.vector(), 1e-6, WrapComponent(2));
  Vec3 std = step.increment_std;
  for (int k = 0; k < 3; ++k) {
    if (std::isnan(std[k])) std[k] = noise.increment_std[k];
  }
  return G * std.cwiseAbs2().asDiagonal() * G.transpose();
}

enum class MotionKind { kIncrement, kBicycle };

// The step whose F is checked, turning `heading` (near +-pi) 0.04 rad across +-pi: an odometry
// increment with its own standard deviations except for y (NaN: MotionNoise's), or bicycle
// controls held for 0.5 s.
MotionStep StepAcrossPi(MotionKind kind, double heading, const MotionNoise& noise) {
  const double turn = heading < 0.0 ? -(kPi + heading) - 0.04 : (kPi - heading) + 0.04;
  if (kind == MotionKind::kIncrement) {
    MotionStep step = Increment(3.0, 1.0, Se2(0.6, -0.15, turn), Vec3(0.25, 0.0, 0.03));
    step.increment_std[1] = std::numeric_limits<double>::quiet_NaN();
    return step;
  }
  const double speed = 2.0, dt = 0.5;  // turn = speed dt sin(steer) / wheelbase
  return {3.0, dt, BicycleControl{speed, std::asin(turn * noise.wheelbase / (speed * dt))}};
}

void ExpectPredictionMatchesDifferences(const PredictionCheck& check, const MotionStep& step,
                                        const MotionNoise& noise, const Vec2& fej_from) {
  const Eigen::VectorXd& x = check.before.mean;
  const auto g = [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
    return MoveWholeState(v, step, noise.wheelbase);
  };
  // The new mean is the motion function's value (the heading wrapped to (-pi, pi]).
  const Eigen::VectorXd moved = g(x);
  EXPECT_LT((check.mean_after.head<2>() - moved.head<2>()).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_NEAR(AngleDifference(check.mean_after[2], moved[2]), 0.0, 1e-12);
  Eigen::MatrixXd expected = NumericJacobian(g, x, 1e-6, WrapComponent(2));
  // FEJ: d(position)/d(heading) = J (next - pose) is taken with the pose predicted before the
  // last update in place of the current one: J (next - from) = J (next - pose) + J (pose - from).
  const Vec2 moved_by_update = x.head<2>() - fej_from;
  expected(0, 2) += -moved_by_update.y();
  expected(1, 2) += moved_by_update.x();
  EXPECT_TRUE(JacobiansMatch(check.full_transition, expected, 1e-8));
  const Se2 pose = Se2::FromVector(x.head<3>());
  EXPECT_TRUE(JacobiansMatch(check.Q, ExpectedProcessNoise(pose, step, noise), 1e-8));
}

void ExpectHeadingCrossesPi(const PredictionCheck& check) {
  EXPECT_GT(std::abs(check.before.mean[2]), kPi - 0.2);
  EXPECT_LT(check.before.mean[2] * check.mean_after[2], 0.0) << "the step turns across +-pi";
}

TEST(FilterJacobians, PredictionAppliesTheCentralDifferencesOfTheMotionOverTheWholeState) {
  const MotionNoise noise = TestMotionNoise();
  for (const MotionKind kind : {MotionKind::kIncrement, MotionKind::kBicycle}) {
    SCOPED_TRACE(kind == MotionKind::kBicycle ? "bicycle" : "increment");
    PriorMapSlam slam(Se2(2.0, -1.0, kPi - 0.03), 0.0, noise, TestSensorNoise(), nullptr,
                      Options(false, false));
    BuildFourLandmarkState(slam);
    const MotionStep step = StepAcrossPi(kind, slam.state().pose().theta(), noise);
    const PredictionCheck check = Predict(slam, step);
    ExpectHeadingCrossesPi(check);
    // The textbook filter: F at the current mean (no correction).
    ExpectPredictionMatchesDifferences(check, step, noise, check.before.mean.head<2>());
  }
}

TEST(FilterJacobians, FirstEstimatesPredictionTakesTheHeadingColumnFromThePredictedPose) {
  const MotionNoise noise = TestMotionNoise();
  for (const MotionKind kind : {MotionKind::kIncrement, MotionKind::kBicycle}) {
    SCOPED_TRACE(kind == MotionKind::kBicycle ? "bicycle" : "increment");
    PriorMapSlam slam(Se2(2.0, -1.0, kPi - 0.03), 0.0, noise, TestSensorNoise(), nullptr,
                      Options(true, false));
    const Se2 predicted = BuildFourLandmarkState(slam);
    // The second frame's update moved the pose away from the one predicted before it.
    const Vec2 from = slam.state().pose().translation();
    ASSERT_GT((from - predicted.translation()).norm(), 0.02);
    const MotionStep step = StepAcrossPi(kind, slam.state().pose().theta(), noise);
    const PredictionCheck check = Predict(slam, step);
    ExpectHeadingCrossesPi(check);
    ExpectPredictionMatchesDifferences(check, step, noise, predicted.translation());
    // Without an update in between, the pose predicted last is the current one: F is the
    // derivative at the current mean.
    MotionStep again = step;
    again.time += step.dt;
    const PredictionCheck next = Predict(slam, again);
    ExpectPredictionMatchesDifferences(next, again, noise, next.before.mean.head<2>());
  }
}

}  // namespace
}  // namespace priormap::slam
