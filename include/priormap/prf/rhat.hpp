#pragma once
/// The Gelman–Rubin potential scale reduction R̂, split form (Gelman et al., Bayesian Data
/// Analysis, 3rd ed., Sec. 11.4): each chain's trace is cut in halves, so that one chain that
/// drifts is caught too. R̂ = sqrt(((n-1)/n · W + B/n) / W) with W the mean within-half
/// variance and B/n the variance of the half means. Near 1 when the chains agree.

#include <span>
#include <vector>

namespace priormap::prf {

/// Below this R̂ the chains are taken to agree: BDA3 (Sec. 11.4) runs chains until every
/// estimand's R̂ is below 1.1.
inline constexpr double kConvergedRhat = 1.1;

/// Split-R̂ of equally long traces (the shortest length is used). 1 when every half is constant
/// at the same value; +inf when halves are constant at different values. Precondition: at
/// least one trace of length >= 4.
[[nodiscard]] double SplitRhat(std::span<const std::vector<double>> traces);

/// The mean of the second half of a trace as SplitRhat cuts it (its last ⌊n/2⌋ values): where a
/// chain settled, which tells the chain of a run that sits apart from the others. Precondition:
/// at least 2 values.
[[nodiscard]] double SecondHalfMean(std::span<const double> trace);

}  // namespace priormap::prf
