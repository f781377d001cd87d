#include <priormap/core/banded_matrix.hpp>
#include <priormap/core/check.hpp>

#include <Eigen/Cholesky>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace priormap {
namespace {

// A random symmetric positive-definite banded matrix (diagonally dominant).
SymmetricBandedMatrix RandomSpd(std::size_t n, std::size_t bandwidth, std::uint64_t seed) {
  std::mt19937_64 engine(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  SymmetricBandedMatrix a(n, bandwidth);
  for (std::size_t j = 0; j < n; ++j) {
    for (std::size_t k = 1; k <= bandwidth && j + k < n; ++k) a.Set(j + k, j, u(engine));
  }
  for (std::size_t i = 0; i < n; ++i) a.Set(i, i, 2.0 * static_cast<double>(bandwidth) + 1.0 + u(engine));
  return a;
}

TEST(SymmetricBandedMatrix, AccessIsSymmetricAndZeroOutsideTheBand) {
  SymmetricBandedMatrix a(5, 1);
  a.Set(2, 1, 3.0);
  EXPECT_DOUBLE_EQ(a(1, 2), 3.0);
  EXPECT_DOUBLE_EQ(a(2, 1), 3.0);
  EXPECT_DOUBLE_EQ(a(4, 0), 0.0);
  EXPECT_THROW(a.Set(3, 0, 1.0), ContractError);
}

TEST(SymmetricBandedMatrix, MultiplyMatchesDense) {
  const SymmetricBandedMatrix a = RandomSpd(40, 3, 1);
  const Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(40, -1.0, 2.0);
  EXPECT_TRUE(a.Multiply(x).isApprox(a.ToDense() * x, 1e-12));
}

TEST(BandedCholesky, SolveAndLogDeterminantMatchDense) {
  for (std::size_t bandwidth : {0u, 1u, 2u, 5u}) {
    const SymmetricBandedMatrix a = RandomSpd(60, bandwidth, 2 + bandwidth);
    const auto chol = BandedCholesky::Factor(a);
    ASSERT_TRUE(chol);
    const Eigen::MatrixXd dense = a.ToDense();
    const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(60, 1.0, -3.0);
    EXPECT_TRUE(chol->Solve(b).isApprox(dense.llt().solve(b), 1e-10));
    const Eigen::LLT<Eigen::MatrixXd> llt(dense);
    const double log_det = 2.0 * llt.matrixL().toDenseMatrix().diagonal().array().log().sum();
    EXPECT_NEAR(chol->LogDeterminant(), log_det, 1e-9);
    // L^T x = b  <=>  x = L^-T b.
    const Eigen::MatrixXd l = llt.matrixL();
    EXPECT_TRUE(chol->SolveUpperTransposed(b).isApprox(l.transpose().triangularView<Eigen::Upper>().solve(b), 1e-10));
  }
}

TEST(BandedCholesky, RejectsIndefiniteMatrices) {
  SymmetricBandedMatrix a(3, 1);
  a.Set(0, 0, 1.0);
  a.Set(1, 1, 1.0);
  a.Set(2, 2, 1.0);
  a.Set(1, 0, 2.0);  // eigenvalues 3 and -1
  EXPECT_FALSE(BandedCholesky::Factor(a));
}

TEST(SymmetricBandedMatrix, Ar1PrecisionIsTheInverseOfTheAr1Covariance) {
  const std::vector<double> sigma = {0.01, 0.02, 0.015, 0.01, 0.03, 0.02};
  const double c = 0.7;
  const SymmetricBandedMatrix w = SymmetricBandedMatrix::Ar1Precision(sigma, c);
  EXPECT_EQ(w.bandwidth(), 1u);
  Eigen::MatrixXd covariance(6, 6);
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) covariance(i, j) = sigma[i] * sigma[j] * std::pow(c, std::abs(i - j));
  }
  EXPECT_TRUE((w.ToDense() * covariance).isApprox(Eigen::MatrixXd::Identity(6, 6), 1e-9));
  EXPECT_THROW((void)SymmetricBandedMatrix::Ar1Precision(sigma, 1.0), ContractError);
}

}  // namespace
}  // namespace priormap
