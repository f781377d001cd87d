#pragma once
// Algorithm 2 of the paper: the continuous optimisation of x for a fixed INMODEL and topology,
// by a penalty homotopy for the prior's constraints and a log-barrier homotopy for the bounds,
// with damped Newton steps on a banded Hessian.
#include <functional>
#include <vector>

#include <Eigen/Core>

#include "inner_problem.hpp"

namespace priormap::priorlets {

struct InnerResult {
  Eigen::VectorXd x;
  bool feasible = false;
  Violation violation;
  int newton_steps = 0;
  double lambda = 0.0;  // the penalty weight reached
  // Link penalties at the end of the first stage, where x is still close to the data: there the
  // penalty of a wrong link stays at that link, while at large lambda the solution bends the
  // surfaces within the range bounds and spreads it over the links around.
  std::vector<double> early_link_penalties;
  bool abandoned = false;  // stopped by InnerControl::abandon
};

struct InnerControl {
  // > 0: start the penalty homotopy there (a warm start from a solution that was already
  // squeezed towards the constraints); otherwise where the penalties begin to matter.
  double lambda_start = 0.0;
  // Take the first stage's Newton steps even when the start is feasible: a warm start from a
  // larger problem's solution then reaches this problem's own minimum, so that its cost
  // compares with that of other problems solved from the same start.
  bool settle = false;
  // Asked after every stage that ends infeasible; true stops the solve (e.g. a border move
  // whose fit is already worse than the current one: along the homotopy the fit only worsens).
  std::function<bool(const Eigen::VectorXd& x)> abandon;
};

// Starts from x0 when it is strictly inside the bounds (a warm start), else from the problem's
// initial point.
[[nodiscard]] InnerResult SolveInner(InnerProblem& problem, const Eigen::VectorXd* x0,
                                     const EngineOptions& options,
                                     const InnerControl& control = {});

// A few Newton steps on data + energies + lambda penalty at large lambda (no barrier: the
// bounds play no part), from `start`: feasibility ~1e-12 near the same optimum. The degrees of
// freedom are decided on the constraints' Jacobian; at a point feasible to ~1e-7 constraints
// that are redundant only on the constraint manifold (three per window of a circle, rank
// 2n - 3) show singular values of that order, as large as those of weakly constrained
// directions; here they are orders of magnitude apart. Returns the point of smallest violation
// seen (`start` when nothing lowered it) and that violation.
[[nodiscard]] Eigen::VectorXd TightenFeasibility(InnerProblem& problem,
                                                 const Eigen::VectorXd& start, double* violation);

}  // namespace priormap::priorlets
