#pragma once
// Central finite differences, the one helper every analytic-derivative test goes through
// (as Ceres' gradient_checker and manif's common_tester do).

#include <Eigen/Core>
#include <gtest/gtest.h>

#include <functional>

namespace priormap::testing {

/// d f / d x at x by central differences with step h: column j is (f(x + h e_j) - f(x - h e_j)) / 2h.
/// `wrap` (optional) post-processes each difference f(x+) - f(x-) before dividing, e.g. to wrap an
/// angle component to (-pi, pi].
Eigen::MatrixXd NumericJacobian(const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& f,
                                const Eigen::VectorXd& x, double h = 1e-6,
                                const std::function<Eigen::VectorXd(Eigen::VectorXd)>& wrap = nullptr);

/// Success when every entry of `analytic` is within `tolerance * max(1, largest |numeric| entry)`
/// of `numeric`: relative for large Jacobians, absolute near zero (where finite differences
/// only reach ~1e-10). The failure message shows both matrices.
::testing::AssertionResult JacobiansMatch(const Eigen::MatrixXd& analytic, const Eigen::MatrixXd& numeric,
                                          double tolerance = 1e-6);

/// Wraps component `index` of a difference vector to (-pi, pi].
std::function<Eigen::VectorXd(Eigen::VectorXd)> WrapComponent(int index);

}  // namespace priormap::testing
