// Jacobians of the motion, observation and constraint models against central differences.
#include <random>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/segment.hpp>
#include <priormap/slam/range_bearing.hpp>
#include <priormap/slam/vehicle_model.hpp>

#include "testing/numeric_diff.hpp"

namespace priormap::slam {
namespace {

using priormap::testing::JacobiansMatch;
using priormap::testing::NumericJacobian;
using priormap::testing::WrapComponent;

TEST(BicycleMotion, JacobiansMatchCentralDifferences) {
  const double dt = 0.025, wheelbase = 4.0;
  for (const Vec3& pose : {Vec3(1.0, -2.0, 0.3), Vec3(-5.0, 3.0, 3.1), Vec3(0.0, 0.0, -1.7)}) {
    for (const Vec2& control : {Vec2(14.0, 0.2), Vec2(3.0, -0.5), Vec2(0.5, 0.0)}) {
      const BicycleControl u{control.x(), control.y()};
      Mat3 J_pose;
      Mat32 J_control;
      (void)BicycleMotion(Se2::FromVector(pose), u, dt, wheelbase, &J_pose, &J_control);
      const auto by_pose = [&](const Eigen::VectorXd& p) -> Eigen::VectorXd {
        return BicycleMotion(Se2::FromVector(p), u, dt, wheelbase).vector();
      };
      const auto by_control = [&](const Eigen::VectorXd& c) -> Eigen::VectorXd {
        return BicycleMotion(Se2::FromVector(pose), {c.x(), c.y()}, dt, wheelbase).vector();
      };
      EXPECT_TRUE(JacobiansMatch(J_pose, NumericJacobian(by_pose, pose, 1e-6, WrapComponent(2))));
      EXPECT_TRUE(
          JacobiansMatch(J_control, NumericJacobian(by_control, control, 1e-6, WrapComponent(2))));
    }
  }
}

TEST(BicycleMotion, DrivesAnArcOfTheExpectedRadius) {
  // Held steer g turns the heading at v sin(g) / L; a full turn takes 2 pi L / (v sin g).
  const double v = 2.0, g = 0.3, L = 4.0, dt = 1e-3;
  const double period = 2.0 * std::numbers::pi * L / (v * std::sin(g));
  Se2 pose;
  const int steps = static_cast<int>(std::lround(period / dt));
  for (int k = 0; k < steps; ++k) pose = BicycleMotion(pose, {v, g}, dt, L);
  EXPECT_NEAR(pose.x(), 0.0, 0.05);
  EXPECT_NEAR(pose.y(), 0.0, 0.05);
  EXPECT_NEAR(WrapAngle(pose.theta()), 0.0, 1e-2);
}

TEST(IncrementMotion, JacobiansMatchCentralDifferences) {
  const Vec3 pose(1.0, 2.0, 2.5), increment(0.4, -0.1, 0.2);
  Mat3 J_pose, J_increment;
  (void)IncrementMotion(Se2::FromVector(pose), Se2::FromVector(increment), &J_pose, &J_increment);
  const auto by_pose = [&](const Eigen::VectorXd& p) -> Eigen::VectorXd {
    return IncrementMotion(Se2::FromVector(p), Se2::FromVector(increment)).vector();
  };
  const auto by_increment = [&](const Eigen::VectorXd& d) -> Eigen::VectorXd {
    return IncrementMotion(Se2::FromVector(pose), Se2::FromVector(d)).vector();
  };
  EXPECT_TRUE(JacobiansMatch(J_pose, NumericJacobian(by_pose, pose, 1e-6, WrapComponent(2))));
  EXPECT_TRUE(JacobiansMatch(J_increment,
                             NumericJacobian(by_increment, increment, 1e-6, WrapComponent(2))));
}

TEST(RangeBearing, ObservationJacobiansMatchCentralDifferences) {
  for (const Vec3& pose : {Vec3(1.0, -2.0, 0.3), Vec3(-5.0, 3.0, 3.1)}) {
    for (const Vec2& landmark : {Vec2(10.0, 4.0), Vec2(-7.0, 2.9), Vec2(1.5, -2.5)}) {
      Mat23 J_pose;
      Mat2 J_landmark;
      (void)ObserveRangeBearing(Se2::FromVector(pose), landmark, &J_pose, &J_landmark);
      const auto by_pose = [&](const Eigen::VectorXd& p) -> Eigen::VectorXd {
        return ObserveRangeBearing(Se2::FromVector(p), landmark);
      };
      const auto by_landmark = [&](const Eigen::VectorXd& l) -> Eigen::VectorXd {
        return ObserveRangeBearing(Se2::FromVector(pose), Vec2(l));
      };
      EXPECT_TRUE(JacobiansMatch(J_pose, NumericJacobian(by_pose, pose, 1e-6, WrapComponent(1))));
      EXPECT_TRUE(JacobiansMatch(J_landmark,
                                 NumericJacobian(by_landmark, landmark, 1e-6, WrapComponent(1))));
    }
  }
}

TEST(RangeBearing, InverseModelJacobiansMatchAndInvertTheObservation) {
  const Vec3 pose(3.0, -1.0, -2.2);
  const Vec2 z(12.5, 0.7);
  Mat23 J_pose;
  Mat2 J_z;
  const Vec2 point = RangeBearingToPoint(Se2::FromVector(pose), z, &J_pose, &J_z);
  EXPECT_TRUE(ObserveRangeBearing(Se2::FromVector(pose), point).isApprox(z, 1e-12));
  const auto by_pose = [&](const Eigen::VectorXd& p) -> Eigen::VectorXd {
    return RangeBearingToPoint(Se2::FromVector(p), z);
  };
  const auto by_z = [&](const Eigen::VectorXd& m) -> Eigen::VectorXd {
    return RangeBearingToPoint(Se2::FromVector(pose), Vec2(m));
  };
  EXPECT_TRUE(JacobiansMatch(J_pose, NumericJacobian(by_pose, pose)));
  EXPECT_TRUE(JacobiansMatch(J_z, NumericJacobian(by_z, z)));
}

// The second-order range terms against Monte Carlo: a point 20 m out, 1 cm along the line of
// sight and 0.4 m across it (a landmark after one bearing), rotated off the axes. Higher terms
// are (0.4 / 20)^2 = 4e-4 relative; the Monte Carlo's standard error is about 0.3 %.
TEST(RangeSecondOrder, MatchesMonteCarloMomentsOfTheRange) {
  const double angle = 0.7;
  const Mat2 rotation = Eigen::Rotation2Dd(angle).toRotationMatrix();
  const Vec2 mean = rotation * Vec2(20.0, 0.0);
  const Mat2 C = rotation * Vec2(0.01 * 0.01, 0.4 * 0.4).asDiagonal() * rotation.transpose();
  const RangeCurvature curvature = RangeSecondOrder(mean, C);
  EXPECT_NEAR(curvature.mean_offset, 0.16 / 40.0, 1e-15);
  EXPECT_NEAR(curvature.variance, 0.5 * (0.16 / 20.0) * (0.16 / 20.0), 1e-15);

  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  const Mat2 L = C.llt().matrixL();
  const int n = 400000;
  double sum = 0.0, sum2 = 0.0;
  for (int i = 0; i < n; ++i) {
    const double r = (mean + L * Vec2(normal(rng), normal(rng))).norm();
    sum += r;
    sum2 += r * r;
  }
  const double mc_mean = sum / n;
  const double mc_variance = sum2 / n - mc_mean * mc_mean;
  const double first_order_variance = 0.01 * 0.01;
  EXPECT_NEAR(mc_mean - mean.norm(), curvature.mean_offset, 0.03 * curvature.mean_offset);
  EXPECT_NEAR(mc_variance, first_order_variance + curvature.variance,
              0.02 * (first_order_variance + curvature.variance));
  // The first-order variance alone is 24 % short: what made the plain EKF overconfident.
  EXPECT_GT(mc_variance, 1.2 * first_order_variance);
}

TEST(PointLineConstraint, IsThePapersDeterminantUpToSignAndMatchesDifferences) {
  // theta = det([x2 - x1, x1 - p]) / |x2 - x1| (Parsley & Julier, Sec. V): the same magnitude as
  // core's SignedLineDistance, the opposite sign; theta = 0 is what the pseudo-observation says.
  const Vec2 a(1.0, 2.0), b(7.0, 4.5), p(3.0, 6.0);
  Eigen::Matrix2d paper;
  paper.col(0) = b - a;
  paper.col(1) = a - p;
  EXPECT_NEAR(SignedLineDistance(p, a, b), -paper.determinant() / (b - a).norm(), 1e-12);
  Row2 J_p, J_a, J_b;
  (void)SignedLineDistance(p, a, b, &J_p, &J_a, &J_b);
  Eigen::VectorXd x(6);
  x << p, a, b;
  const auto f = [](const Eigen::VectorXd& v) -> Eigen::VectorXd {
    return Eigen::VectorXd::Constant(
        1, SignedLineDistance(v.segment<2>(0), v.segment<2>(2), v.segment<2>(4)));
  };
  Eigen::MatrixXd analytic(1, 6);
  analytic << J_p, J_a, J_b;
  EXPECT_TRUE(JacobiansMatch(analytic, NumericJacobian(f, x)));
}

}  // namespace
}  // namespace priormap::slam
