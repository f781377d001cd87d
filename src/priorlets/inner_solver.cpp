#include "inner_solver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <tuple>
#include <utility>
#include <vector>

namespace priormap::priorlets {
namespace {

// Armijo constant and step halvings of the backtracking line search.
constexpr double kArmijo = 1e-4;
constexpr int kMaxHalvings = 40;
// A feasible problem's violation falls about as 1 / lambda once the penalty dominates the
// data; one that stays above this factor of the last stage's, with the stage's Newton
// iteration converged, is taken to be infeasible.
constexpr double kStallRatio = 0.3;
// A stage that looks stalled after its steps takes up to this many more while a Newton step
// still promises to lower the objective by more than kConvergedFraction of the weighted
// penalty: a stall is judged at a minimum of the stage's objective, not on the way there (a
// hard but feasible topology otherwise looks infeasible and is broken apart).
constexpr int kMaxExtraSteps = 8;
constexpr double kConvergedFraction = 0.01;
// The violation falls as 1 / lambda when the last stage cut it by at least lambda_factor /
// kAsymptoticRatio; the next weight then aims at kTargetFraction of the tolerance.
constexpr double kAsymptoticRatio = 2.0;
constexpr double kTargetFraction = 0.3;

// A Newton step cut short by the bounds is cut for every unknown alike, so that one range
// near its bound (a reading 4 sigma off) stalls the whole solve. Below this fraction of the
// step, the unknowns that would leave their bounds move to kToBoundary of the way there and
// the others take the Newton step of the problem with those fixed (up to kMaxBlockRounds
// times, as freeing the rest may block others).
constexpr double kBlockedStep = 0.5;
constexpr double kToBoundary = 0.9;
constexpr int kMaxBlockRounds = 3;

// The barrier of a feasible point to compare with, per unknown: slacks down to e^-15 of the
// bounds' width.
constexpr double kBarrierAllowance = 30.0;

// The largest data term inside the bounds: 1/2 sum |I_ij| D_i D_j with D_i the largest
// distance of unknown i from its target (measurement or initial normal) within its bounds.
double DataCostBound(const InnerProblem& problem) {
  const std::size_t n = problem.num_unknowns();
  std::vector<double> d(n);
  for (std::size_t p = 0; p < problem.num_points(); ++p) {
    const ProblemPoint& pt = problem.points()[p];
    d[2 * p] = std::max(pt.rho_upper - pt.rho_measured, pt.rho_measured - pt.rho_lower);
    d[2 * p + 1] = std::max(pt.alpha_upper - pt.alpha_initial, pt.alpha_initial - pt.alpha_lower);
  }
  const SymmetricBandedMatrix& info = problem.data_information();
  const std::size_t band = info.bandwidth();
  double bound = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    bound += 0.5 * std::abs(info(i, i)) * d[i] * d[i];
    for (std::size_t j = i + 1; j <= std::min(n - 1, i + band); ++j)
      bound += std::abs(info(i, j)) * d[i] * d[j];
  }
  return bound;
}

// Solves H d = -g for the Newton direction, H (a Cholesky factor of it) in the problem's
// Hessian order, g and d in the unknowns' order.
Eigen::VectorXd NewtonDirection(const InnerProblem& problem, const BandedCholesky& chol,
                                const Eigen::VectorXd& gradient) {
  return -problem.FromHessianOrder(chol.Solve(problem.ToHessianOrder(gradient)));
}

// Replaces `direction` by the blocked Newton direction when that goes further and descends.
// `hessian` is in the problem's Hessian order, the vectors in the unknowns' order.
void BlockAtBounds(const InnerProblem& problem, const Eigen::VectorXd& x,
                   const Eigen::VectorXd& gradient, const SymmetricBandedMatrix& hessian,
                   Eigen::VectorXd& direction) {
  double t = problem.MaxStep(x, direction, 1.0);
  if (t >= kBlockedStep) return;
  const std::size_t n = problem.num_unknowns(), band = hessian.bandwidth();
  std::vector<char> fixed(n, 0);  // in the Hessian's order, as `delta`
  Eigen::VectorXd delta = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n));
  Eigen::VectorXd candidate = direction;
  for (int round = 0; round < kMaxBlockRounds; ++round) {
    bool added = false;
    for (std::size_t p = 0; p < problem.num_points(); ++p) {
      const ProblemPoint& pt = problem.points()[p];
      for (std::size_t which = 0; which < 2; ++which) {
        const std::size_t u = 2 * p + which, i = problem.HessianIndex(u);
        const auto e = static_cast<Eigen::Index>(u);
        const double lo = which == 0 ? pt.rho_lower : pt.alpha_lower;
        const double hi = which == 0 ? pt.rho_upper : pt.alpha_upper;
        const double to = x[e] + candidate[e];
        if (fixed[i] || (to > lo && to < hi)) continue;
        fixed[i] = 1;
        delta[static_cast<Eigen::Index>(i)] = kToBoundary * ((to >= hi ? hi : lo) - x[e]);
        added = true;
      }
    }
    if (!added) break;
    // The Newton system with the fixed unknowns eliminated: their rows and columns become
    // identity rows with their steps on the right.
    SymmetricBandedMatrix reduced = hessian;
    Eigen::VectorXd rhs = -problem.ToHessianOrder(gradient);
    for (std::size_t i = 0; i < n; ++i) {
      if (!fixed[i]) continue;
      const std::size_t lo = i >= band ? i - band : 0, hi = std::min(n - 1, i + band);
      for (std::size_t j = lo; j <= hi; ++j) {
        if (!fixed[j])
          rhs[static_cast<Eigen::Index>(j)] -= hessian(j, i) * delta[static_cast<Eigen::Index>(i)];
      }
    }
    for (std::size_t i = 0; i < n; ++i) {
      if (!fixed[i]) continue;
      const std::size_t lo = i >= band ? i - band : 0, hi = std::min(n - 1, i + band);
      for (std::size_t j = lo; j <= hi; ++j) reduced.Set(i, j, i == j ? 1.0 : 0.0);
      rhs[static_cast<Eigen::Index>(i)] = delta[static_cast<Eigen::Index>(i)];
    }
    const std::optional<BandedCholesky> chol = BandedCholesky::Factor(reduced);
    if (!chol) return;
    candidate = problem.FromHessianOrder(chol->Solve(rhs));
  }
  const double candidate_t = problem.MaxStep(x, candidate, 1.0);
  if (candidate_t > t && gradient.dot(candidate) < 0.0) direction = candidate;
}

}  // namespace

InnerResult SolveInner(InnerProblem& problem, const Eigen::VectorXd* x0,
                       const EngineOptions& options, const InnerControl& control) {
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
  const double data_weight = problem.data_weight();
  const double lambda_judged = 100.0 * data_weight;

  Eigen::VectorXd gradient, trial;
  SymmetricBandedMatrix hessian;
  // Below about 1/100 of the data's weight the penalties do not move x: start there at the
  // earliest.
  double lambda = std::max(options.lambda_initial, 1e-2 * data_weight);
  double mu = options.mu_initial;
  if (control.lambda_start > 0.0) {
    // Keep lambda and the barrier in step as if the homotopy had run up to here.
    for (double l = lambda; l < control.lambda_start; l *= options.lambda_factor)
      mu = std::min(mu * options.mu_factor, options.mu_max);
    lambda = std::max(lambda, control.lambda_start);
  }

  // What the data costs at most inside the bounds; a feasible point exists there when the
  // topology is right, so the objective at the minimum of any stage is at most this (plus the
  // barrier). Energies have no such bound.
  const double price_bound =
      problem.HasEnergyTerms() ? std::numeric_limits<double>::infinity() : DataCostBound(problem);
  const double n = static_cast<double>(problem.num_unknowns());
  int certain_infeasible = 0;
  // The derivatives at result.x for (lambda, barrier weight) when the line search already
  // computed them there (the accepted trial of a step that another step of the stage follows).
  bool have_derivatives = false;
  double derivatives_lambda = 0.0, derivatives_barrier_weight = 0.0;
  ObjectiveValue derivatives_value;
  Eigen::VectorXd trial_gradient;
  SymmetricBandedMatrix trial_hessian;
  // One damped Newton step on the stage's objective. Returns the Newton decrement g^T H^-1 g
  // at the starting point when a step was taken, nullopt when none was (converged, no descent
  // direction, or certainly infeasible). `step_follows`: another step of this stage follows.
  const auto newton_step = [&](double barrier_weight, bool step_follows) -> std::optional<double> {
    if (!(have_derivatives && derivatives_lambda == lambda &&
          derivatives_barrier_weight == barrier_weight)) {
      derivatives_value = problem.Evaluate(result.x, lambda, barrier_weight, &gradient, &hessian);
    }
    have_derivatives = false;
    const ObjectiveValue& value = derivatives_value;
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
    if (!chol) return std::nullopt;
    Eigen::VectorXd direction = NewtonDirection(problem, *chol, gradient);
    BlockAtBounds(problem, result.x, gradient, hessian, direction);
    const double slope = gradient.dot(direction);
    if (!(slope < 0.0)) return std::nullopt;
    // Converged for this stage when the model predicts next to no gain.
    if (-slope < 1e-9 * (1.0 + std::abs(current))) return std::nullopt;
    // A certificate of infeasibility: the stage's objective cannot fall below what its
    // quadratic model reaches, current - decrement / 2, while a feasible point costs at most
    // `price_bound` (plus its barrier). Two such evaluations in a row (a Newton step between
    // them) stop the solve.
    if (current + 0.5 * slope > price_bound + barrier_weight * kBarrierAllowance * n) {
      if (++certain_infeasible >= 2) return std::nullopt;
    } else {
      certain_infeasible = 0;
    }
    ++result.newton_steps;
    double t = problem.MaxStep(result.x, direction, 0.99);
    for (int halving = 0; halving < kMaxHalvings; ++halving, t *= 0.5) {
      trial = result.x + t * direction;
      if (!problem.StrictlyInside(trial)) continue;
      // The first trial is usually taken: with another step to follow, its derivatives are
      // computed along (the cost of an evaluation is mostly independent of them).
      const bool with_derivatives = step_follows && halving == 0;
      const ObjectiveValue next = problem.Evaluate(trial, lambda, barrier_weight,
                                                   with_derivatives ? &trial_gradient : nullptr,
                                                   with_derivatives ? &trial_hessian : nullptr);
      if (next.Total(lambda, barrier_weight) <= current + kArmijo * t * slope) {
        result.x = trial;
        result.violation = {next.max_residual, next.penalty};
        if (with_derivatives) {
          std::swap(gradient, trial_gradient);
          std::swap(hessian, trial_hessian);
          derivatives_value = next;
          derivatives_lambda = lambda;
          derivatives_barrier_weight = barrier_weight;
          have_derivatives = true;
        }
        return -slope;
      }
    }
    return std::nullopt;
  };

  const auto given_up = [&] { return certain_infeasible >= 2; };
  const auto feasible = [&] {
    return result.violation.max_residual <= options.feasibility_tolerance;
  };
  result.violation = problem.Violations(result.x);
  // A settling solve that loses the feasibility of its start and does not regain it returns
  // the start.
  std::optional<std::pair<Eigen::VectorXd, Violation>> feasible_start;
  if (control.settle && feasible()) feasible_start.emplace(result.x, result.violation);
  // An infeasible end, also before the first stage is complete.
  const auto infeasible = [&] {
    if (feasible_start) {
      std::tie(result.x, result.violation) = *feasible_start;
      result.feasible = true;
      return result;
    }
    if (result.early_link_penalties.empty()) {
      result.early_link_penalties = problem.LinkPenalties(result.x);
    }
    return result;
  };

  double previous_violation = result.violation.max_residual;
  int stalled_stages = 0;
  for (int stage = 0;; ++stage) {
    result.lambda = lambda;
    const double barrier_weight = 1.0 / mu;
    for (int step = 0; step < options.max_newton_steps_per_stage &&
                       (!feasible() || (control.settle && stage == 0));
         ++step) {
      if (!newton_step(barrier_weight, step + 1 < options.max_newton_steps_per_stage)) break;
    }
    if (given_up()) return infeasible();
    if (stage == 0) {
      result.early_link_penalties = feasible() ? std::vector<double>(problem.links().size(), 0.0)
                                               : problem.LinkPenalties(result.x);
    }
    if (feasible()) {
      result.feasible = true;
      return result;
    }
    if (control.abandon && control.abandon(result.x)) {
      result.abandoned = true;
      return infeasible();
    }
    if (lambda >= lambda_judged &&
        result.violation.max_residual > kStallRatio * previous_violation) {
      // It looks stalled: make sure the stage has converged before judging.
      for (int extra = 0; extra < kMaxExtraSteps && !feasible(); ++extra) {
        const double weighted_penalty = lambda * result.violation.penalty;
        const std::optional<double> decrement = newton_step(barrier_weight, true);
        if (!decrement || 0.5 * *decrement < kConvergedFraction * weighted_penalty) break;
      }
      if (given_up()) return infeasible();
      if (feasible()) {
        result.feasible = true;
        return result;
      }
      stalled_stages =
          result.violation.max_residual > kStallRatio * previous_violation ? stalled_stages + 1 : 0;
      if (stalled_stages >= 2) return infeasible();
    } else {
      stalled_stages = 0;
    }
    if (lambda >= options.lambda_max) return infeasible();
    // Once the violation falls as 1 / lambda (the penalty dominates), the weight that makes it
    // feasible can be predicted: go there directly, up to lambda_factor^2 at once.
    double factor = options.lambda_factor;
    if (lambda >= lambda_judged && result.violation.max_residual <= kAsymptoticRatio /
                                                                        options.lambda_factor *
                                                                        previous_violation) {
      const double needed =
          result.violation.max_residual / (kTargetFraction * options.feasibility_tolerance);
      factor = std::clamp(needed, factor, factor * factor);
    }
    previous_violation = result.violation.max_residual;
    for (double f = 1.0; f < factor; f *= options.lambda_factor)
      mu = std::min(mu * options.mu_factor, options.mu_max);
    lambda = std::min(lambda * factor, options.lambda_max);
  }
}

Eigen::VectorXd TightenFeasibility(InnerProblem& problem, const Eigen::VectorXd& start,
                                   double* violation) {
  const double data_weight = problem.data_weight();
  Eigen::VectorXd x = start, gradient;
  SymmetricBandedMatrix hessian;
  double best = problem.Violations(x).max_residual;
  Eigen::VectorXd best_x = x;
  for (double scale : {1e6, 1e8, 1e10}) {
    const double lambda = scale * data_weight;
    for (int step = 0; step < 2; ++step) {
      const double current =
          problem.Evaluate(x, lambda, 0.0, &gradient, &hessian).Total(lambda, 0.0);
      const std::optional<BandedCholesky> chol = BandedCholesky::Factor(hessian);
      if (!chol) break;
      const Eigen::VectorXd direction = NewtonDirection(problem, *chol, gradient);
      const double slope = gradient.dot(direction);
      if (!(slope < 0.0)) break;
      bool accepted = false;
      double t = 1.0;
      for (int halving = 0; halving < kMaxHalvings && !accepted; ++halving, t *= 0.5) {
        const Eigen::VectorXd trial = x + t * direction;
        const ObjectiveValue next = problem.Evaluate(trial, lambda, 0.0, nullptr, nullptr);
        if (next.Total(lambda, 0.0) <= current + kArmijo * t * slope) {
          x = trial;
          accepted = true;
        }
      }
      if (!accepted) break;
    }
    const double v = problem.Violations(x).max_residual;
    if (v < best) {
      best = v;
      best_x = x;
    }
  }
  *violation = best;
  return best_x;
}

}  // namespace priormap::priorlets
