#include <cmath>
#include <numeric>
#include <vector>

#include <priormap/core/check.hpp>
#include <priormap/prf/batch_means.hpp>

namespace priormap::prf {

Estimate BatchMeans(std::span<const double> record, std::size_t batches) {
  PRIORMAP_CHECK(batches >= 2 && record.size() >= 2 * batches,
                 "batch means need at least two batches of two values");
  Estimate estimate;
  estimate.mean =
      std::accumulate(record.begin(), record.end(), 0.0) / static_cast<double>(record.size());
  const std::size_t length = record.size() / batches;
  double grand = 0.0;
  std::vector<double> means(batches);
  for (std::size_t b = 0; b < batches; ++b) {
    const auto first = record.begin() + static_cast<std::ptrdiff_t>(b * length);
    means[b] = std::accumulate(first, first + static_cast<std::ptrdiff_t>(length), 0.0) /
               static_cast<double>(length);
    grand += means[b];
  }
  grand /= static_cast<double>(batches);
  double sum_squares = 0.0;
  for (double m : means) sum_squares += (m - grand) * (m - grand);
  const double variance_of_mean =
      sum_squares / static_cast<double>(batches - 1) / static_cast<double>(batches);
  estimate.standard_error = std::sqrt(variance_of_mean);
  return estimate;
}

}  // namespace priormap::prf
