#include "inner_solver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace priormap::priorlets {
namespace {

// Armijo constant and step halvings of the backtracking line search.
constexpr double kArmijo = 1e-4;
constexpr int kMaxHalvings = 40;
// A feasible problem's violation falls about as 1 / lambda once the penalty dominates the
// data; one that stays within this factor over two stages is taken to be infeasible.
constexpr double kStallRatio = 0.3;

}  // namespace

InnerResult SolveInner(InnerProblem& problem, const Eigen::VectorXd* x0,
                       const EngineOptions& options, double lambda_start) {
  InnerResult result;
  result.x = x0 && x0->size() == static_cast<Eigen::Index>(problem.num_unknowns()) &&
                     problem.StrictlyInside(*x0)
                 ? *x0
                 : problem.InitialPoint();
  if (problem.num_points() == 0) {
    result.feasible = true;
    return result;
  }
  // Penalties only matter once they outweigh the data; judge stalling from there on.
  double data_weight = 0.0;
  const SymmetricBandedMatrix& info = problem.data_information();
  for (std::size_t i = 0; i < info.size(); ++i) data_weight = std::max(data_weight, info(i, i));
  const double lambda_judged = 100.0 * data_weight;

  Eigen::VectorXd gradient, trial;
  SymmetricBandedMatrix hessian;
  // Below about 1/100 of the data's weight the penalties do not move x: start there at the
  // earliest.
  double lambda = std::max(options.lambda_initial, 1e-2 * data_weight);
  double mu = options.mu_initial;
  if (lambda_start > 0.0) {
    // Keep lambda and the barrier in step as if the homotopy had run up to here.
    for (double l = lambda; l < lambda_start; l *= options.lambda_factor)
      mu = std::min(mu * options.mu_factor, options.mu_max);
    lambda = std::max(lambda, lambda_start);
  }
  double previous_violation = std::numeric_limits<double>::infinity();
  int stalled_stages = 0;
  result.violation = problem.Violations(result.x);
  for (int stage = 0;; ++stage) {
    const double barrier_weight = 1.0 / mu;
    for (int step = 0; step < options.max_newton_steps_per_stage; ++step) {
      if (result.violation.max_residual <= options.feasibility_tolerance) {
        result.feasible = true;
        result.lambda = lambda;
        if (stage == 0) result.early_link_penalties.assign(problem.links().size(), 0.0);
        return result;
      }
      const ObjectiveValue value =
          problem.Evaluate(result.x, lambda, barrier_weight, &gradient, &hessian);
      const double current = value.Total(lambda, barrier_weight);
      std::optional<BandedCholesky> chol = BandedCholesky::Factor(hessian);
      // The Hessian is positive definite by construction; rounding at huge lambda may still
      // break that, so damp the diagonal until it factors.
      for (double damping = 1e-8; !chol && damping < 1e8; damping *= 100.0) {
        SymmetricBandedMatrix damped = hessian;
        for (std::size_t i = 0; i < damped.size(); ++i)
          damped.Add(i, i, damping * (1.0 + hessian(i, i)));
        chol = BandedCholesky::Factor(damped);
      }
      if (!chol) break;
      const Eigen::VectorXd direction = -chol->Solve(gradient);
      const double slope = gradient.dot(direction);
      if (!(slope < 0.0)) break;
      ++result.newton_steps;
      double t = problem.MaxStep(result.x, direction, 0.99);
      bool accepted = false;
      ObjectiveValue next;
      for (int halving = 0; halving < kMaxHalvings; ++halving, t *= 0.5) {
        trial = result.x + t * direction;
        if (!problem.StrictlyInside(trial)) continue;
        next = problem.Evaluate(trial, lambda, barrier_weight, nullptr, nullptr);
        if (next.Total(lambda, barrier_weight) <= current + kArmijo * t * slope) {
          accepted = true;
          break;
        }
      }
      if (!accepted) break;
      result.x = trial;
      result.violation = {next.max_residual, next.penalty};
      // The Newton decrement: converged for this stage when the model predicts little gain.
      if (-slope < 1e-9 * (1.0 + std::abs(current))) break;
    }
    result.lambda = lambda;
    if (stage == 0) result.early_link_penalties = problem.LinkPenalties(result.x);
    if (result.violation.max_residual <= options.feasibility_tolerance) {
      result.feasible = true;
      return result;
    }
    if (lambda >= lambda_judged) {
      stalled_stages =
          result.violation.max_residual > kStallRatio * previous_violation ? stalled_stages + 1 : 0;
      if (stalled_stages >= 2) return result;
    }
    previous_violation = result.violation.max_residual;
    if (lambda >= options.lambda_max) return result;
    lambda *= options.lambda_factor;
    mu = std::min(mu * options.mu_factor, options.mu_max);
  }
}

}  // namespace priormap::priorlets
