#include "testing/numeric_diff.hpp"

#include <priormap/core/angles.hpp>

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

std::function<Eigen::VectorXd(Eigen::VectorXd)> WrapComponent(int index) {
  return [index](Eigen::VectorXd v) {
    v[index] = WrapAngle(v[index]);
    return v;
  };
}

}  // namespace priormap::testing
