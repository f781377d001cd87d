#include <priormap/core/angles.hpp>
#include <priormap/core/se2.hpp>

#include <gtest/gtest.h>

#include <random>

#include "testing/numeric_diff.hpp"

namespace priormap {
namespace {

using testing::NumericJacobian;
using testing::WrapComponent;

constexpr double kTolerance = 1e-7;

// Special poses (identity, angles at and near the wrap-around, large translations) and random ones,
// as manif's tests exercise every regime.
std::vector<Se2> TestPoses() {
  std::vector<Se2> poses = {Se2(), Se2(1.0, -2.0, 0.0), Se2(0.3, 0.4, kPi), Se2(-5.0, 2.0, kPi - 1e-3),
                            Se2(2.0, 1.0, -kPi + 1e-3), Se2(100.0, -50.0, 1.0)};
  std::mt19937_64 engine(7);
  std::uniform_real_distribution<double> coordinate(-10.0, 10.0), angle(-kPi, kPi);
  for (int i = 0; i < 20; ++i) poses.emplace_back(coordinate(engine), coordinate(engine), angle(engine));
  return poses;
}

TEST(Se2, ConstructorWrapsTheAngle) {
  EXPECT_NEAR(Se2(0, 0, 3 * kPi).theta(), kPi, 1e-12);
  EXPECT_NEAR(Se2(0, 0, -kPi).theta(), kPi, 1e-12);
}

TEST(Se2, ComposeWithInverseIsIdentity) {
  for (const Se2& a : TestPoses()) {
    EXPECT_TRUE(IsApprox(a.Compose(a.Inverse()), Se2(), 1e-12));
    EXPECT_TRUE(IsApprox(a.Inverse().Compose(a), Se2(), 1e-12));
  }
}

TEST(Se2, ComposeIsAssociative) {
  const std::vector<Se2> poses = TestPoses();
  for (std::size_t i = 0; i + 2 < poses.size(); ++i) {
    const Se2 left = (poses[i] * poses[i + 1]) * poses[i + 2];
    const Se2 right = poses[i] * (poses[i + 1] * poses[i + 2]);
    EXPECT_TRUE(IsApprox(left, right, 1e-9));
  }
}

TEST(Se2, TransformThenInverseTransformIsIdentity) {
  const Vec2 p(0.7, -1.3);
  for (const Se2& a : TestPoses()) {
    EXPECT_TRUE(a.InverseTransform(a.Transform(p)).isApprox(p, 1e-12));
    EXPECT_TRUE(a.Transform(p).isApprox(a.rotation() * p + a.translation(), 1e-12));
  }
}

TEST(Se2, BetweenIsInverseCompose) {
  const std::vector<Se2> poses = TestPoses();
  for (std::size_t i = 0; i + 1 < poses.size(); ++i) {
    EXPECT_TRUE(IsApprox(poses[i].Between(poses[i + 1]), poses[i].Inverse() * poses[i + 1], 1e-12));
    EXPECT_TRUE(IsApprox(poses[i] * poses[i].Between(poses[i + 1]), poses[i + 1], 1e-9));
  }
}

TEST(Se2, ComposeJacobiansMatchNumeric) {
  const std::vector<Se2> poses = TestPoses();
  for (std::size_t i = 0; i + 1 < poses.size(); ++i) {
    const Se2 a = poses[i], b = poses[i + 1];
    Mat3 J_a, J_b;
    (void)a.Compose(b, &J_a, &J_b);
    const Eigen::MatrixXd numeric_a = NumericJacobian(
        [&](const Eigen::VectorXd& v) -> Eigen::VectorXd { return Se2::FromVector(v).Compose(b).vector(); },
        a.vector(), 1e-6, WrapComponent(2));
    const Eigen::MatrixXd numeric_b = NumericJacobian(
        [&](const Eigen::VectorXd& v) -> Eigen::VectorXd { return a.Compose(Se2::FromVector(v)).vector(); },
        b.vector(), 1e-6, WrapComponent(2));
    EXPECT_TRUE(testing::JacobiansMatch(J_a, numeric_a));
    EXPECT_TRUE(testing::JacobiansMatch(J_b, numeric_b));
  }
}

TEST(Se2, InverseJacobianMatchesNumeric) {
  for (const Se2& a : TestPoses()) {
    Mat3 J;
    (void)a.Inverse(&J);
    const Eigen::MatrixXd numeric = NumericJacobian(
        [](const Eigen::VectorXd& v) -> Eigen::VectorXd { return Se2::FromVector(v).Inverse().vector(); },
        a.vector(), 1e-6, WrapComponent(2));
    EXPECT_TRUE(testing::JacobiansMatch(J, numeric));
  }
}

TEST(Se2, BetweenJacobiansMatchNumeric) {
  const std::vector<Se2> poses = TestPoses();
  for (std::size_t i = 0; i + 1 < poses.size(); ++i) {
    const Se2 a = poses[i], b = poses[i + 1];
    Mat3 J_a, J_b;
    (void)a.Between(b, &J_a, &J_b);
    const Eigen::MatrixXd numeric_a = NumericJacobian(
        [&](const Eigen::VectorXd& v) -> Eigen::VectorXd { return Se2::FromVector(v).Between(b).vector(); },
        a.vector(), 1e-6, WrapComponent(2));
    const Eigen::MatrixXd numeric_b = NumericJacobian(
        [&](const Eigen::VectorXd& v) -> Eigen::VectorXd { return a.Between(Se2::FromVector(v)).vector(); },
        b.vector(), 1e-6, WrapComponent(2));
    EXPECT_TRUE(testing::JacobiansMatch(J_a, numeric_a));
    EXPECT_TRUE(testing::JacobiansMatch(J_b, numeric_b));
  }
}

TEST(Se2, TransformJacobiansMatchNumeric) {
  const Vec2 p(1.5, -0.25);
  for (const Se2& a : TestPoses()) {
    Mat23 J_pose;
    Mat2 J_point;
    (void)a.Transform(p, &J_pose, &J_point);
    const Eigen::MatrixXd numeric_pose = NumericJacobian(
        [&](const Eigen::VectorXd& v) -> Eigen::VectorXd { return Se2::FromVector(v).Transform(p); }, a.vector());
    const Eigen::MatrixXd numeric_point = NumericJacobian(
        [&](const Eigen::VectorXd& v) -> Eigen::VectorXd { return a.Transform(v); }, p);
    EXPECT_TRUE(testing::JacobiansMatch(J_pose, numeric_pose));
    EXPECT_TRUE(testing::JacobiansMatch(J_point, numeric_point));
  }
}

TEST(Se2, InverseTransformJacobiansMatchNumeric) {
  const Vec2 p(-3.0, 2.0);
  for (const Se2& a : TestPoses()) {
    Mat23 J_pose;
    Mat2 J_point;
    (void)a.InverseTransform(p, &J_pose, &J_point);
    const Eigen::MatrixXd numeric_pose = NumericJacobian(
        [&](const Eigen::VectorXd& v) -> Eigen::VectorXd { return Se2::FromVector(v).InverseTransform(p); },
        a.vector());
    const Eigen::MatrixXd numeric_point = NumericJacobian(
        [&](const Eigen::VectorXd& v) -> Eigen::VectorXd { return a.InverseTransform(v); }, p);
    EXPECT_TRUE(testing::JacobiansMatch(J_pose, numeric_pose));
    EXPECT_TRUE(testing::JacobiansMatch(J_point, numeric_point));
  }
}

TEST(Se2, NonFinitePoseIsReported) {
  EXPECT_TRUE(Se2(1, 2, 3).IsFinite());
  EXPECT_FALSE(Se2(std::nan(""), 2, 3).IsFinite());
}

}  // namespace
}  // namespace priormap
