#pragma once
/// The penalty forms the inference engine minimises (de la Puente & Censi, Sec. III-A), from the
/// raw terms of one block evaluation:
///   equality f        -> f^2
///   inequality g      -> max(0, g)^2
///   disjunction       -> the smallest branch penalty (a branch's penalty is the sum over its
///                        terms; the derivative is the active branch's, so the form is
///                        piecewise smooth)
///   energy h          -> h as written (a cost to minimise: `model_likelihood` expressions are
///                        negative log-likelihoods up to a constant)
/// A term outside its domain (NaN: the log of a negative number) adds no derivatives and makes
/// its constraint infinitely violated, or its energy an infinite cost.

#include <vector>

#include <priormap/dsl/prior.hpp>

namespace priormap::dsl {

struct PenaltyOptions {
  double lambda = 1.0;  ///< weight of the constraint penalty
  /// Drop the second-derivative parts (2 f Hess f) of the squared forms, keeping the
  /// positive semi-definite Gauss-Newton part 2 grad f grad f^T.
  bool gauss_newton = false;
};

struct PenaltyValue {
  double constraint =
      0.0;  ///< sum of f^2, max(0, g)^2 and the disjunctions' smallest branches (unweighted)
  double energy = 0.0;  ///< sum of h
  /// The largest residual: |f|, max(0, g), and within each disjunction its smallest branch's
  /// largest (the feasibility measure, in the constraints' own units).
  double max_residual = 0.0;
  /// lambda * constraint + energy.
  [[nodiscard]] double Total(double lambda) const { return lambda * constraint + energy; }
};

/// Adds d(lambda * constraint + energy)/dx to `gradient` (num_variables) and its Hessian to
/// `hessian` (num_variables^2, row-major) when they are not null, from the outputs of
/// BlockEvaluator::Evaluate at one point. `active_branch` (optional) receives, per disjunction,
/// the branch that was smallest.
PenaltyValue AccumulatePenalty(const CompiledBlock& block, const double* values,
                               const double* gradients, const double* hessians,
                               const PenaltyOptions& options, double* gradient, double* hessian,
                               std::vector<int>* active_branch = nullptr);

}  // namespace priormap::dsl
