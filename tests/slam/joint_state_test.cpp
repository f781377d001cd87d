// The joint state's Kalman update against batch least squares, marginalisation, augmentation.
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <span>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <priormap/slam/joint_state.hpp>
#include <priormap/slam/pseudo_observation.hpp>

#include "testing/numeric_diff.hpp"

namespace priormap::slam {
namespace {

Eigen::MatrixXd RandomSpd(int n, std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  Eigen::MatrixXd A(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) A(i, j) = normal(rng);
  }
  return A * A.transpose() / n + Eigen::MatrixXd::Identity(n, n) * 0.1;
}

// A state of pose + landmark 0 + segment 5 with a given joint Gaussian, built through the API:
// the landmark is added with J_pose = 0, J_z = I (so its covariance is R), then everything is
// overwritten through an update-free path: we compare against the same prior, so only the
// structure matters. To control the prior exactly, the test uses only the pose block's
// covariance, an independent landmark and an independent segment.
JointState MakeState(const Eigen::VectorXd& mean, const Eigen::MatrixXd& covariance) {
  JointState state(Se2::FromVector(mean.head<3>()), covariance.topLeftCorner<3, 3>());
  state.AddLandmark(0, mean.segment<2>(3), Mat23::Zero(), Mat2::Identity(),
                    covariance.block<2, 2>(3, 3));
  state.AddSegment(5, mean.segment<2>(5), mean.segment<2>(7), covariance.block<4, 4>(5, 5));
  return state;
}

Eigen::MatrixXd BlockDiagonal(const Eigen::MatrixXd& full) {
  Eigen::MatrixXd d = Eigen::MatrixXd::Zero(full.rows(), full.cols());
  d.topLeftCorner<3, 3>() = full.topLeftCorner<3, 3>();
  d.block<2, 2>(3, 3) = full.block<2, 2>(3, 3);
  d.block<4, 4>(5, 5) = full.block<4, 4>(5, 5);
  return d;
}

// A state of a pose, landmarks 0 and 1 and segments 5 and 6 from one vector (19 values in that
// order), for differentiating a measurement by the whole state.
JointState StateOfTwoLandmarksAndTwoSegments(const Eigen::VectorXd& mean) {
  JointState state(Se2::FromVector(mean.head<3>()), Mat3::Identity());
  state.AddLandmark(0, mean.segment<2>(3), Mat23::Zero(), Mat2::Identity(), Mat2::Identity());
  state.AddLandmark(1, mean.segment<2>(5), Mat23::Zero(), Mat2::Identity(), Mat2::Identity());
  state.AddSegment(5, mean.segment<2>(7), mean.segment<2>(9), Mat4::Identity());
  state.AddSegment(6, mean.segment<2>(11), mean.segment<2>(13), Mat4::Identity());
  return state;
}

// The point-on-segment rows, placed in the state vector, against finite differences of the
// signed distances over the whole state: a Jacobian at the wrong offset, or an endpoint's in the
// other's place, fails here (the linear-case test below builds its h from the same matrix).
TEST(JointState, PointOnSegmentRowsAreTheDerivativesOfTheDistancesByTheWholeState) {
  Eigen::VectorXd mean(15);
  mean << 0.5, -0.2, 0.3,    // pose
      3.0, 0.7, -1.0, 4.2,   // landmarks 0 and 1
      0.0, 0.2, 10.0, -0.4,  // segment 5
      -2.0, 3.0, 1.0, 5.5;   // segment 6
  const std::array<std::pair<int, int>, 3> relations = {{{1, 5}, {0, 6}, {0, 5}}};
  const Linearization m =
      PointOnSegmentObservation(StateOfTwoLandmarksAndTwoSegments(mean), relations, 0.05);
  ASSERT_EQ(m.H.cols(), 15);
  const auto distances = [&](const Eigen::VectorXd& x) -> Eigen::VectorXd {
    return -PointOnSegmentObservation(StateOfTwoLandmarksAndTwoSegments(x), relations, 0.05)
                .innovation;
  };
  EXPECT_TRUE(testing::JacobiansMatch(Eigen::MatrixXd(m.H),
                                      testing::NumericJacobian(distances, mean), 1e-7));
}

TEST(JointState, LinearUpdateEqualsBatchLeastSquares) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  Eigen::VectorXd mean(9);
  for (int i = 0; i < 9; ++i) mean[i] = normal(rng);
  mean[2] = 0.3;
  const Eigen::MatrixXd P0 = BlockDiagonal(RandomSpd(9, rng));
  JointState state = MakeState(mean, P0);
  ASSERT_TRUE(state.covariance().isApprox(P0, 1e-12));

  // z = H x + v, v ~ N(0, R), three rows touching every block.
  Eigen::MatrixXd H(3, 9);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 9; ++j) H(i, j) = normal(rng);
  }
  const Eigen::MatrixXd R = RandomSpd(3, rng);
  const Eigen::Vector3d z(0.5, -1.0, 2.0);
  Linearization m;
  m.H = H.sparseView();
  m.innovation = z - H * mean;
  m.R = R;
  ASSERT_TRUE(state.Update(m));

  // Batch: minimise |x - mean|^2_{P0^-1} + |z - H x|^2_{R^-1} via the normal equations.
  const Eigen::MatrixXd information = P0.inverse() + H.transpose() * R.inverse() * H;
  const Eigen::VectorXd x =
      information.ldlt().solve(P0.inverse() * mean + H.transpose() * R.inverse() * z);
  EXPECT_TRUE(state.mean().isApprox(x, 1e-10)) << state.mean().transpose() << "\n" << x.transpose();
  EXPECT_TRUE(state.covariance().isApprox(information.inverse(), 1e-10));
  EXPECT_TRUE(state.covariance().isApprox(state.covariance().transpose(), 0.0));
}

// With the wall along the x axis and uncertainty only in the y coordinates, theta is linear in
// the uncertain variables: theta = y_p - ((L - x_p) y_a + x_p y_b) / L. One pseudo-observation
// update must then equal the batch least-squares answer exactly.
TEST(JointState, PseudoObservationOnALinearCaseEqualsBatchLeastSquares) {
  Eigen::VectorXd mean(9);
  mean << 0.0, 0.0, 0.0,     // pose
      3.0, 0.7,              // landmark (x_p, y_p)
      0.0, 0.2, 10.0, -0.1;  // segment a = (0, y_a), b = (10, y_b)
  Eigen::MatrixXd P0 = Eigen::MatrixXd::Zero(9, 9);
  P0(0, 0) = P0(1, 1) = P0(2, 2) = 1e-3;
  P0(4, 4) = 0.04;  // y_p
  P0(6, 6) = 1.0;   // y_a
  P0(8, 8) = 0.5;   // y_b
  P0(6, 8) = P0(8, 6) = 0.2;
  JointState state = MakeState(mean, P0);
  const double wall_std = 0.05;
  const std::pair<int, int> relation(0, 5);
  const Linearization m = PointOnSegmentObservation(state, std::span(&relation, 1), wall_std);
  ASSERT_TRUE(state.Update(m));

  // The linear problem in u = (y_p, y_a, y_b): h^T u + w = 0, h = (1, -(L - x_p)/L, -x_p/L).
  // But the segment's y's also move theta's normal slightly; at b - a = (10, -0.3) the line is
  // not exactly horizontal, so build h from the same Jacobian and compare with the
  // linear-Gaussian answer on the uncertain variables.
  const Eigen::MatrixXd H = Eigen::MatrixXd(m.H);
  const std::vector<int> u{4, 6, 8};
  Eigen::Vector3d h;
  for (int k = 0; k < 3; ++k) h[k] = H(0, u[k]);
  Eigen::Matrix3d Pu;
  Eigen::Vector3d mu;
  for (int i = 0; i < 3; ++i) {
    mu[i] = mean[u[i]];
    for (int j = 0; j < 3; ++j) Pu(i, j) = P0(u[i], u[j]);
  }
  // Residual r(u) = 0 - theta(mean) - h^T (u - mu) with noise wall_std^2.
  const double theta0 = -m.innovation[0];
  const Eigen::Matrix3d information = Pu.inverse() + h * h.transpose() / (wall_std * wall_std);
  const Eigen::Vector3d target_rhs =
      Pu.inverse() * mu + h * (h.dot(mu) - theta0) / (wall_std * wall_std);
  const Eigen::Vector3d expected = information.ldlt().solve(target_rhs);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(state.mean()[u[k]], expected[k], 1e-12);
  const Eigen::Matrix3d expected_cov = information.inverse();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      EXPECT_NEAR(state.covariance()(u[i], u[j]), expected_cov(i, j), 1e-12);
    }
  }
  // Variables the relation does not involve and that are uncorrelated with it do not move.
  EXPECT_DOUBLE_EQ(state.mean()[3], 3.0);
  EXPECT_DOUBLE_EQ(state.mean()[5], 0.0);
}

// One component: the mixture update is the ordinary Kalman update.
TEST(JointState, MixtureOfOneComponentIsTheKalmanUpdate) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> normal;
  Eigen::VectorXd mean(9);
  for (int i = 0; i < 9; ++i) mean[i] = normal(rng);
  const Eigen::MatrixXd P0 = BlockDiagonal(RandomSpd(9, rng));
  JointState kalman = MakeState(mean, P0);
  JointState mixture = kalman;
  const std::pair<int, int> relation(0, 5);
  const Linearization m = PointOnSegmentObservation(kalman, std::span(&relation, 1), 0.1);
  ASSERT_TRUE(kalman.Update(m));
  const auto weights = mixture.UpdateMixture(std::span(&m, 1), std::vector<double>{0.3});
  ASSERT_TRUE(weights.has_value());
  EXPECT_EQ(*weights, std::vector<double>{1.0});
  EXPECT_TRUE(mixture.mean().isApprox(kalman.mean(), 1e-12));
  EXPECT_TRUE(mixture.covariance().isApprox(kalman.covariance(), 1e-12));
}

// The landmark lies on the line x = 0 or on the line y = 0 (weights 0.3, 0.7), each up to
// sigma: the posterior N(p; mu, P) sum_s w_s N(theta_s(p); 0, sigma^2) is integrated on a fine
// grid, and its mean, covariance and component masses must equal the moment-matched update's.
TEST(JointState, MixtureUpdateMatchesTheMomentsOfTheExactPosterior) {
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(9);
  mean.segment<2>(3) = Vec2(0.4, 0.3);
  mean.segment<4>(5) << -5.0, -5.0, 5.0, 5.0;
  Eigen::MatrixXd P0 = Eigen::MatrixXd::Identity(9, 9) * 0.01;
  const Mat2 P_point{{0.25, 0.08}, {0.08, 0.16}};
  P0.block<2, 2>(3, 3) = P_point;
  JointState state = MakeState(mean, P0);
  const double sigma = 0.2;
  const std::array<double, 2> prior_weights{0.3, 0.7};
  std::vector<Linearization> components;
  for (int axis = 0; axis < 2; ++axis) {
    Linearization m;
    m.H.resize(1, state.dim());
    m.H.insert(0, 3 + axis) = 1.0;
    m.innovation = Eigen::VectorXd::Constant(1, 0.0 - mean[3 + axis]);
    m.R = Eigen::MatrixXd::Constant(1, 1, sigma * sigma);
    components.push_back(std::move(m));
  }
  const auto weights = state.UpdateMixture(components, prior_weights);
  ASSERT_TRUE(weights.has_value());

  // The exact posterior of the point on a grid over +-8 sigma of its prior.
  const Mat2 information = P_point.inverse();
  const Vec2 mu = mean.segment<2>(3);
  const int n = 1601;
  const double half = 8.0 * std::sqrt(P_point.diagonal().maxCoeff());
  const double h = 2.0 * half / (n - 1);
  auto gauss = [](double x, double s) { return std::exp(-0.5 * x * x / (s * s)); };
  std::array<double, 2> mass{0.0, 0.0};
  Vec2 first = Vec2::Zero();
  Mat2 second = Mat2::Zero();
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const Vec2 p = mu + Vec2(-half + i * h, -half + j * h);
      const Vec2 d = p - mu;
      const double prior = std::exp(-0.5 * d.dot(information * d));
      const double a = prior * prior_weights[0] * gauss(p.x(), sigma);
      const double b = prior * prior_weights[1] * gauss(p.y(), sigma);
      mass[0] += a;
      mass[1] += b;
      first += (a + b) * p;
      second += (a + b) * p * p.transpose();
    }
  }
  const double total = mass[0] + mass[1];
  const Vec2 expected_mean = first / total;
  const Mat2 expected_covariance = second / total - expected_mean * expected_mean.transpose();
  EXPECT_NEAR((*weights)[0], mass[0] / total, 1e-9);
  EXPECT_NEAR((*weights)[1], mass[1] / total, 1e-9);
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(state.mean()[3 + i], expected_mean[i], 1e-8);
    for (int j = 0; j < 2; ++j) {
      EXPECT_NEAR(state.covariance()(3 + i, 3 + j), expected_covariance(i, j), 1e-8);
    }
  }
  // Blocks uncorrelated with the point do not move.
  EXPECT_TRUE(state.mean().head<3>().isZero(0.0));
  const Mat3 pose_block = state.covariance().topLeftCorner<3, 3>();
  EXPECT_EQ(pose_block, Mat3(P0.topLeftCorner<3, 3>()));
}

TEST(JointState, MixtureUpdateChangesNothingWhenAComponentCannotBeApplied) {
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(9);
  JointState state = MakeState(mean, Eigen::MatrixXd::Identity(9, 9));
  const JointState before = state;
  Linearization good, bad;
  good.H.resize(1, 9);
  good.H.insert(0, 3) = 1.0;
  good.innovation = Eigen::VectorXd::Ones(1);
  good.R = Eigen::MatrixXd::Identity(1, 1);
  bad.H.resize(1, 9);  // no rows touched and no noise: S = 0
  bad.innovation = Eigen::VectorXd::Zero(1);
  bad.R = Eigen::MatrixXd::Zero(1, 1);
  const std::array<Linearization, 2> both{good, bad};
  EXPECT_FALSE(state.UpdateMixture(both, std::vector<double>{0.5, 0.5}).has_value());
  EXPECT_FALSE(state.UpdateMixture(std::span(&good, 1), std::vector<double>{0.0}).has_value());
  EXPECT_EQ(state.mean(), before.mean());
  EXPECT_EQ(state.covariance(), before.covariance());
}

TEST(JointState, RemovingABlockMarginalisesIt) {
  std::mt19937_64 rng(3);
  JointState state(Se2(1.0, 2.0, 0.5), RandomSpd(3, rng));
  Mat23 J_pose;
  J_pose << 1.0, 0.0, -2.0, 0.0, 1.0, 3.0;
  state.AddLandmark(10, Vec2(4.0, 5.0), J_pose, Mat2::Identity(), Mat2::Identity() * 0.1);
  state.AddSegment(2, Vec2(0.0, 0.0), Vec2(5.0, 0.0), Mat4::Identity());
  state.AddLandmark(11, Vec2(-4.0, 5.0), J_pose, Mat2::Identity(), Mat2::Identity() * 0.2);
  const Eigen::VectorXd mean = state.mean();
  const Eigen::MatrixXd P = state.covariance();
  state.Remove(BlockKind::kSegment, 2);
  ASSERT_EQ(state.dim(), 7);
  EXPECT_EQ(*state.Offset(BlockKind::kLandmark, 11), 5);
  EXPECT_FALSE(state.Contains(BlockKind::kSegment, 2));
  const std::vector<int> kept{0, 1, 2, 3, 4, 9, 10};
  for (int i = 0; i < 7; ++i) {
    EXPECT_EQ(state.mean()[i], mean[kept[i]]);
    for (int j = 0; j < 7; ++j) EXPECT_EQ(state.covariance()(i, j), P(kept[i], kept[j]));
  }
  EXPECT_EQ(state.NumLandmarks(), 2);
  EXPECT_EQ(state.NumSegments(), 0);
}

TEST(JointState, AddedLandmarkHasTheLinearlyPropagatedCovariance) {
  std::mt19937_64 rng(5);
  const Mat3 Pv = RandomSpd(3, rng);
  JointState state(Se2(0.0, 0.0, 0.0), Pv);
  Mat23 J_pose;
  J_pose << 1.0, 0.0, -2.0, 0.0, 1.0, 3.0;
  Mat2 J_z;
  J_z << 0.5, -3.0, 0.8, 2.0;
  const Mat2 R = Eigen::Vector2d(0.01, 0.0004).asDiagonal();
  state.AddLandmark(0, Vec2(1.0, 1.0), J_pose, J_z, R);
  // [pose; landmark] = [I 0; J_pose J_z] [pose; z].
  Eigen::Matrix<double, 5, 5> joint = Eigen::Matrix<double, 5, 5>::Zero();
  joint.topLeftCorner<3, 3>() = Pv;
  joint.bottomRightCorner<2, 2>() = R;
  Eigen::Matrix<double, 5, 5> T = Eigen::Matrix<double, 5, 5>::Zero();
  T.topLeftCorner<3, 3>().setIdentity();
  T.bottomLeftCorner<2, 3>() = J_pose;
  T.bottomRightCorner<2, 2>() = J_z;
  EXPECT_TRUE(state.covariance().isApprox(T * joint * T.transpose(), 1e-12));
}

TEST(JointState, RejectsAnUpdateWhoseInnovationCovarianceIsNotPositiveDefinite) {
  JointState state(Se2(), Mat3::Zero());
  Linearization m;
  m.H.resize(1, 3);
  m.H.insert(0, 0) = 1.0;
  m.innovation = Eigen::VectorXd::Constant(1, 1.0);
  m.R = Eigen::MatrixXd::Zero(1, 1);
  EXPECT_FALSE(state.Update(m));
  EXPECT_EQ(state.mean(), Eigen::Vector3d::Zero());
}

TEST(JointState, RejectsUpdatesThatWouldNotBeFinite) {
  JointState state(Se2(), Mat3::Identity());
  const JointState before = state;
  Linearization m;
  m.H.resize(1, 3);
  m.H.insert(0, 0) = 1.0;
  m.R = Eigen::MatrixXd::Identity(1, 1);
  for (const double innovation : {std::nan(""), std::numeric_limits<double>::infinity()}) {
    m.innovation = Eigen::VectorXd::Constant(1, innovation);
    EXPECT_FALSE(state.Update(m)) << innovation;
    EXPECT_FALSE(state.UpdateMixture(std::span(&m, 1), std::vector<double>{1.0}).has_value());
  }
  m.innovation = Eigen::VectorXd::Ones(1);
  m.R(0, 0) = std::nan("");  // LLT reports success on it
  EXPECT_FALSE(state.Update(m));
  EXPECT_EQ(state.mean(), before.mean());
  EXPECT_EQ(state.covariance(), before.covariance());
}

}  // namespace
}  // namespace priormap::slam
