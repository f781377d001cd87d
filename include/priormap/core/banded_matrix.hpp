#pragma once
/// Symmetric banded matrices and their Cholesky factors: the precision (information) matrix of
/// range noise with correlated neighbours. Everything is O(n * bandwidth^2) time and
/// O(n * bandwidth) memory.

#include <cstddef>
#include <optional>
#include <span>
#include <utility>

#include <Eigen/Core>

namespace priormap {

/// A symmetric n x n matrix A with A(i, j) = 0 for |i - j| > bandwidth; stores the lower band.
class SymmetricBandedMatrix {
 public:
  SymmetricBandedMatrix() = default;
  SymmetricBandedMatrix(std::size_t n, std::size_t bandwidth);

  /// Precision of Gaussian noise with standard deviations `sigma` and correlation
  /// c^|i - j| between beams i and j (a first-order autoregressive process), which is
  /// tridiagonal. Preconditions: sigma > 0, 0 <= c < 1.
  static SymmetricBandedMatrix Ar1Precision(std::span<const double> sigma, double c);

  [[nodiscard]] std::size_t size() const { return static_cast<std::size_t>(band_.cols()); }
  [[nodiscard]] std::size_t bandwidth() const;

  /// A(i, j), zero outside the band. Preconditions: i, j < size().
  [[nodiscard]] double operator()(std::size_t i, std::size_t j) const;
  /// Sets A(i, j) = A(j, i) = value. Precondition: |i - j| <= bandwidth.
  void Set(std::size_t i, std::size_t j, double value);

  /// A(i, j) += value (and A(j, i)). Precondition: |i - j| <= bandwidth.
  void Add(std::size_t i, std::size_t j, double value) {
    if (i < j) std::swap(i, j);
    band_(static_cast<Eigen::Index>(i - j), static_cast<Eigen::Index>(j)) += value;
  }
  /// All entries zero, keeping the size.
  void SetZero() { band_.setZero(); }
  /// A x.
  [[nodiscard]] Eigen::VectorXd Multiply(const Eigen::VectorXd& x) const;
  [[nodiscard]] Eigen::MatrixXd ToDense() const;

  /// Lower band: band()(k, i) = A(i + k, i).
  [[nodiscard]] const Eigen::MatrixXd& band() const { return band_; }

 private:
  Eigen::MatrixXd band_;  ///< (bandwidth + 1) x n
};

/// A = L L^T with L lower triangular and banded like A.
class BandedCholesky {
 public:
  /// nullopt when A is not (numerically) positive definite.
  static std::optional<BandedCholesky> Factor(const SymmetricBandedMatrix& a);

  /// Solves A x = b.
  [[nodiscard]] Eigen::VectorXd Solve(const Eigen::VectorXd& b) const;
  /// Solves L^T x = b: with b standard normal, x has covariance A^-1 (how correlated noise is
  /// sampled from its precision).
  [[nodiscard]] Eigen::VectorXd SolveUpperTransposed(const Eigen::VectorXd& b) const;
  /// log det A.
  [[nodiscard]] double LogDeterminant() const;

 private:
  Eigen::MatrixXd l_band_;  ///< l_band_(k, i) = L(i + k, i)
};

}  // namespace priormap
