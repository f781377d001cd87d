#pragma once
/// Monte Carlo standard errors of a Markov chain's averages by batch means: the chain's record
/// is cut into B consecutive batches, whose means are nearly independent when batches are much
/// longer than the autocorrelation time; the standard error is their standard deviation / √B.

#include <cstddef>
#include <span>

namespace priormap::prf {

struct Estimate {
  double mean = 0.0;
  double standard_error = 0.0;
};

/// Mean of `record` and its batch-means standard error with `batches` batches (the last
/// record.size() mod batches values are left out of the error, not of the mean).
/// Precondition: record.size() >= 2 * batches, batches >= 2.
[[nodiscard]] Estimate BatchMeans(std::span<const double> record, std::size_t batches);

}  // namespace priormap::prf
