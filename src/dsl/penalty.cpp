#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <priormap/dsl/penalty.hpp>

namespace priormap::dsl {
namespace {

// The residual a term contributes to its squared penalty: f, or max(0, g); NaN outside the
// term's domain, which std::max(0, NaN) would have made 0 (satisfied).
double Residual(const Term& term, double value) {
  if (std::isnan(value)) return value;
  return term.kind == TermKind::kInequality ? std::max(0.0, value) : value;
}

// Adds weight * (r^2) derivatives of term t: gradient 2 r grad, Hessian 2 (grad grad^T + r Hess).
void AddSquared(double weight, double r, const double* grad, const double* hess, std::size_t n,
                bool gauss_newton, double* gradient, double* hessian) {
  if (gradient) {
    for (std::size_t i = 0; i < n; ++i) gradient[i] += 2.0 * weight * r * grad[i];
  }
  if (hessian) {
    // Symmetric (term Hessians are mirrored from one triangle): compute one triangle.
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t j = 0; j <= i; ++j) {
        double h = grad[i] * grad[j];
        if (!gauss_newton) h += r * hess[i * n + j];
        hessian[i * n + j] += 2.0 * weight * h;
        if (j != i) hessian[j * n + i] += 2.0 * weight * h;
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

  // The smallest branch of every disjunction. The engine calls this for every window in every
  // Newton step, so nothing is allocated for the few disjunctions real priors have: branch
  // sums are recomputed per branch instead of stored.
  constexpr int kInlineDisjunctions = 16;
  const int groups = block.num_disjunctions();
  std::array<int, kInlineDisjunctions> inline_best;
  std::vector<int> heap_best;
  int* best_branch = inline_best.data();
  if (groups > kInlineDisjunctions) {
    heap_best.resize(static_cast<std::size_t>(groups));
    best_branch = heap_best.data();
  }
  for (int g = 0; g < groups; ++g) {
    int branches = 0;
    for (const Term& term : terms) {
      if (term.disjunction == g) branches = std::max(branches, term.branch + 1);
    }
    double best_sum = std::numeric_limits<double>::infinity(), best_worst = 0.0;
    best_branch[g] = 0;
    for (int b = 0; b < branches; ++b) {
      double sum = 0.0, worst = 0.0;
      for (std::size_t t = 0; t < terms.size(); ++t) {
        if (terms[t].disjunction != g || terms[t].branch != b) continue;
        const double r = Residual(terms[t], values[t]);
        sum += r * r;
        worst = std::max(worst, std::abs(r));
      }
      // A branch outside its terms' domain (NaN) is infinitely violated, never the best.
      if (sum < best_sum) {
        best_sum = sum;
        best_worst = worst;
        best_branch[g] = b;
      }
    }
    if (std::isinf(best_sum)) best_worst = best_sum;  // every branch undefined (or infinite)
    penalty.constraint += best_sum;
    penalty.max_residual = std::max(penalty.max_residual, best_worst);
  }
  if (active_branch) active_branch->assign(best_branch, best_branch + groups);

  bool undefined_energy = false;
  for (std::size_t t = 0; t < terms.size(); ++t) {
    const Term& term = terms[t];
    if (term.kind == TermKind::kEnergy) {
      // Outside its domain (log of a negative number) an energy is an infinite cost, as a
      // constraint there is infinitely violated. A NaN cost compares false with every other
      // (with it, a scan's links all fell out of the model); no NaN into the derivatives.
      if (std::isnan(values[t])) {
        undefined_energy = true;
        continue;
      }
      penalty.energy += values[t];
      if (gradient && grad_of(t)) {
        for (std::size_t i = 0; i < n; ++i) gradient[i] += grad_of(t)[i];
      }
      if (hessian && hess_of(t)) {
        for (std::size_t i = 0; i < n * n; ++i) hessian[i] += hess_of(t)[i];
      }
      continue;
    }
    if (term.disjunction >= 0 && term.branch != best_branch[term.disjunction]) continue;
    const double r = Residual(term, values[t]);
    if (std::isnan(r)) {
      // Outside the term's domain (sqrt or log of a negative number): infinitely violated (a
      // disjunction's was counted above); no NaN into the derivatives.
      if (term.disjunction < 0) {
        penalty.constraint = std::numeric_limits<double>::infinity();
        penalty.max_residual = std::numeric_limits<double>::infinity();
      }
      continue;
    }
    if (term.disjunction < 0) {
      penalty.constraint += r * r;
      penalty.max_residual = std::max(penalty.max_residual, std::abs(r));
    }
    // An inactive inequality (g < 0) adds nothing; a satisfied equality (f = 0) still adds its
    // curvature 2 grad f grad f^T.
    const bool inactive = term.kind == TermKind::kInequality && values[t] <= 0.0;
    if (grad_of(t) && !inactive) {
      AddSquared(options.lambda, r, grad_of(t), hess_of(t), n, options.gauss_newton, gradient,
                 hess_of(t) ? hessian : nullptr);
    }
  }
  if (undefined_energy) penalty.energy = std::numeric_limits<double>::infinity();
  return penalty;
}

}  // namespace priormap::dsl
