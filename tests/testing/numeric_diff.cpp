#include "testing/numeric_diff.hpp"

#include <priormap/core/angles.hpp>

#include <algorithm>

namespace priormap::testing {

Eigen::MatrixXd NumericJacobian(const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& f,
                                const Eigen::VectorXd& x, double h,
                                const std::function<Eigen::VectorXd(Eigen::VectorXd)>& wrap) {
  const Eigen::VectorXd f0 = f(x);
  Eigen::MatrixXd jacobian(f0.size(), x.size());
  for (Eigen::Index j = 0; j < x.size(); ++j) {
    Eigen::VectorXd plus = x, minus = x;
    plus[j] += h;
    minus[j] -= h;
    Eigen::VectorXd difference = f(plus) - f(minus);
    if (wrap) difference = wrap(std::move(difference));
    jacobian.col(j) = difference / (2 * h);
  }
  return jacobian;
}

::testing::AssertionResult JacobiansMatch(const Eigen::MatrixXd& analytic, const Eigen::MatrixXd& numeric,
                                          double tolerance) {
  if (analytic.rows() != numeric.rows() || analytic.cols() != numeric.cols()) {
    return ::testing::AssertionFailure() << "size " << analytic.rows() << "x" << analytic.cols() << " vs "
                                         << numeric.rows() << "x" << numeric.cols();
  }
  const double scale = std::max(1.0, numeric.cwiseAbs().maxCoeff());
  const double error = (analytic - numeric).cwiseAbs().maxCoeff();
  if (error <= tolerance * scale) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "max error " << error << " > " << tolerance * scale << "\nanalytic:\n"
                                       << analytic << "\nnumeric:\n" << numeric;
}

std::function<Eigen::VectorXd(Eigen::VectorXd)> WrapComponent(int index) {
  return [index](Eigen::VectorXd v) {
    v[index] = WrapAngle(v[index]);
    return v;
  };
}

}  // namespace priormap::testing
