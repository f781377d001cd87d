#include <algorithm>
#include <cmath>

#include <priormap/core/banded_matrix.hpp>
#include <priormap/core/check.hpp>

namespace priormap {

SymmetricBandedMatrix::SymmetricBandedMatrix(std::size_t n, std::size_t bandwidth)
    : band_(Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(bandwidth + 1),
                                  static_cast<Eigen::Index>(n))) {}

SymmetricBandedMatrix SymmetricBandedMatrix::Ar1Precision(std::span<const double> sigma, double c) {
  PRIORMAP_CHECK(c >= 0.0 && c < 1.0, "AR(1) correlation must be in [0, 1)");
  const std::size_t n = sigma.size();
  SymmetricBandedMatrix w(n, n > 1 ? 1 : 0);
  // The correlation matrix C_ij = c^|i-j| has the tridiagonal inverse
  // (1 / (1 - c^2)) * tridiag(-c, [1, 1 + c^2, ..., 1 + c^2, 1], -c); W = D^-1 C^-1 D^-1.
  const double scale = 1.0 / (1.0 - c * c);
  for (std::size_t i = 0; i < n; ++i) {
    PRIORMAP_CHECK(sigma[i] > 0.0, "noise standard deviations must be positive");
    const bool end = i == 0 || i + 1 == n;
    w.Set(i, i, scale * (end ? 1.0 : 1.0 + c * c) / (sigma[i] * sigma[i]));
    if (i + 1 < n) w.Set(i + 1, i, -scale * c / (sigma[i] * sigma[i + 1]));
  }
  return w;
}

std::size_t SymmetricBandedMatrix::bandwidth() const {
  return band_.rows() == 0 ? 0 : static_cast<std::size_t>(band_.rows() - 1);
}

double SymmetricBandedMatrix::operator()(std::size_t i, std::size_t j) const {
  PRIORMAP_DCHECK(i < size() && j < size(), "banded matrix index out of range");
  if (i < j) std::swap(i, j);
  const std::size_t k = i - j;
  if (k > bandwidth()) return 0.0;
  return band_(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(j));
}

void SymmetricBandedMatrix::Set(std::size_t i, std::size_t j, double value) {
  if (i < j) std::swap(i, j);
  PRIORMAP_CHECK(i < size() && i - j <= bandwidth(), "entry outside the band");
  band_(static_cast<Eigen::Index>(i - j), static_cast<Eigen::Index>(j)) = value;
}

Eigen::VectorXd SymmetricBandedMatrix::Multiply(const Eigen::VectorXd& x) const {
  const auto n = static_cast<Eigen::Index>(size());
  PRIORMAP_CHECK(x.size() == n, "size mismatch in banded multiply");
  const auto b = static_cast<Eigen::Index>(bandwidth());
  Eigen::VectorXd y = Eigen::VectorXd::Zero(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    y[j] += band_(0, j) * x[j];
    for (Eigen::Index k = 1; k <= b && j + k < n; ++k) {
      y[j + k] += band_(k, j) * x[j];
      y[j] += band_(k, j) * x[j + k];
    }
  }
  return y;
}

Eigen::MatrixXd SymmetricBandedMatrix::ToDense() const {
  const std::size_t n = size();
  Eigen::MatrixXd dense(n, n);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < n; ++j) {
      dense(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = (*this)(i, j);
    }
  }
  return dense;
}

std::optional<BandedCholesky> BandedCholesky::Factor(const SymmetricBandedMatrix& a) {
  const Eigen::Index n = static_cast<Eigen::Index>(a.size());
  const Eigen::Index b = static_cast<Eigen::Index>(a.bandwidth());
  BandedCholesky chol;
  chol.l_band_ = a.band();
  Eigen::MatrixXd& l = chol.l_band_;  // l(k, j) = L(j + k, j)
  for (Eigen::Index j = 0; j < n; ++j) {
    // L(j, j)^2 = A(j, j) - sum_p L(j, p)^2 over p in [j - b, j).
    double d = l(0, j);
    for (Eigen::Index p = std::max<Eigen::Index>(0, j - b); p < j; ++p) {
      const double ljp = l(j - p, p);
      d -= ljp * ljp;
    }
    if (!(d > 0.0) || !std::isfinite(d)) return std::nullopt;
    const double ljj = std::sqrt(d);
    l(0, j) = ljj;
    for (Eigen::Index i = j + 1; i <= std::min(n - 1, j + b); ++i) {
      double s = l(i - j, j);
      for (Eigen::Index p = std::max<Eigen::Index>(0, i - b); p < j; ++p) {
        s -= l(i - p, p) * l(j - p, p);
      }
      l(i - j, j) = s / ljj;
    }
  }
  return chol;
}

Eigen::VectorXd BandedCholesky::Solve(const Eigen::VectorXd& rhs) const {
  const Eigen::Index n = l_band_.cols();
  const Eigen::Index b = l_band_.rows() - 1;
  PRIORMAP_CHECK(rhs.size() == n, "size mismatch in banded solve");
  Eigen::VectorXd y = rhs;
  for (Eigen::Index i = 0; i < n; ++i) {  // L y = rhs
    for (Eigen::Index p = std::max<Eigen::Index>(0, i - b); p < i; ++p)
      y[i] -= l_band_(i - p, p) * y[p];
    y[i] /= l_band_(0, i);
  }
  return SolveUpperTransposed(y);
}

Eigen::VectorXd BandedCholesky::SolveUpperTransposed(const Eigen::VectorXd& rhs) const {
  const Eigen::Index n = l_band_.cols();
  const Eigen::Index b = l_band_.rows() - 1;
  PRIORMAP_CHECK(rhs.size() == n, "size mismatch in banded solve");
  Eigen::VectorXd x = rhs;
  for (Eigen::Index i = n - 1; i >= 0; --i) {  // L^T x = rhs
    for (Eigen::Index k = 1; k <= b && i + k < n; ++k) x[i] -= l_band_(k, i) * x[i + k];
    x[i] /= l_band_(0, i);
  }
  return x;
}

double BandedCholesky::LogDeterminant() const {
  return 2.0 * l_band_.row(0).array().log().sum();
}

}  // namespace priormap
