#include <algorithm>
#include <limits>

#include <priormap/dsl/penalty.hpp>

namespace priormap::dsl {
namespace {

// The residual a term contributes to its squared penalty: f, or max(0, g).
double Residual(const Term& term, double value) {
  return term.kind == TermKind::kInequality ? std::max(0.0, value) : value;
}

// Adds weight * (r^2) derivatives of term t: gradient 2 r grad, Hessian 2 (grad grad^T + r Hess).
void AddSquared(double weight, double r, const double* grad, const double* hess, std::size_t n,
                bool gauss_newton, double* gradient, double* hessian) {
  if (r == 0.0)
    return;  // max(0, g) inactive, or f exactly satisfied: nothing to add (r grad = 0 and,
             // for an inactive inequality, no curvature either)
  if (gradient) {
    for (std::size_t i = 0; i < n; ++i) gradient[i] += 2.0 * weight * r * grad[i];
  }
  if (hessian) {
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t j = 0; j < n; ++j) {
        double h = grad[i] * grad[j];
        if (!gauss_newton) h += r * hess[i * n + j];
        hessian[i * n + j] += 2.0 * weight * h;
      }
    }
  }
}

}  // namespace

PenaltyValue AccumulatePenalty(const CompiledBlock& block, const double* values,
                               const double* gradients, const double* hessians,
                               const PenaltyOptions& options, double* gradient, double* hessian,
                               std::vector<int>* active_branch) {
  const std::size_t n = static_cast<std::size_t>(block.num_variables());
  const std::vector<Term>& terms = block.terms();
  const auto grad_of = [&](std::size_t t) { return gradients ? gradients + t * n : nullptr; };
  const auto hess_of = [&](std::size_t t) { return hessians ? hessians + t * n * n : nullptr; };
  PenaltyValue penalty;

  // The smallest branch of every disjunction.
  const int groups = block.num_disjunctions();
  std::vector<double> best(static_cast<std::size_t>(groups),
                           std::numeric_limits<double>::infinity());
  std::vector<int> best_branch(static_cast<std::size_t>(groups), 0);
  {
    std::vector<std::vector<double>> branch_sums(static_cast<std::size_t>(groups));
    for (std::size_t t = 0; t < terms.size(); ++t) {
      const Term& term = terms[t];
      if (term.disjunction < 0) continue;
      auto& sums = branch_sums[static_cast<std::size_t>(term.disjunction)];
      if (sums.size() <= static_cast<std::size_t>(term.branch))
        sums.resize(static_cast<std::size_t>(term.branch) + 1, 0.0);
      const double r = Residual(term, values[t]);
      sums[static_cast<std::size_t>(term.branch)] += r * r;
    }
    for (std::size_t g = 0; g < branch_sums.size(); ++g) {
      for (std::size_t b = 0; b < branch_sums[g].size(); ++b) {
        if (branch_sums[g][b] < best[g]) {
          best[g] = branch_sums[g][b];
          best_branch[g] = static_cast<int>(b);
        }
      }
      penalty.constraint += best[g];
    }
  }
  if (active_branch) *active_branch = best_branch;

  for (std::size_t t = 0; t < terms.size(); ++t) {
    const Term& term = terms[t];
    if (term.kind == TermKind::kEnergy) {
      penalty.energy += values[t];
      if (gradient && grad_of(t)) {
        for (std::size_t i = 0; i < n; ++i) gradient[i] += grad_of(t)[i];
      }
      if (hessian && hess_of(t)) {
        for (std::size_t i = 0; i < n * n; ++i) hessian[i] += hess_of(t)[i];
      }
      continue;
    }
    if (term.disjunction >= 0 &&
        term.branch != best_branch[static_cast<std::size_t>(term.disjunction)])
      continue;
    const double r = Residual(term, values[t]);
    if (term.disjunction < 0) penalty.constraint += r * r;
    if (grad_of(t)) {
      AddSquared(options.lambda, r, grad_of(t), hess_of(t), n, options.gauss_newton, gradient,
                 hess_of(t) ? hessian : nullptr);
    }
  }
  return penalty;
}

}  // namespace priormap::dsl
