#include <algorithm>
#include <cmath>
#include <limits>

#include <priormap/core/check.hpp>
#include <priormap/prf/rhat.hpp>

namespace priormap::prf {

double SplitRhat(std::span<const std::vector<double>> traces) {
  PRIORMAP_CHECK(!traces.empty(), "R-hat needs at least one trace");
  std::size_t length = traces[0].size();
  for (const auto& trace : traces) length = std::min(length, trace.size());
  PRIORMAP_CHECK(length >= 4, "R-hat needs traces of at least 4 values");
  const std::size_t n = length / 2;
  std::vector<double> means, variances;
  for (const auto& trace : traces) {
    for (std::size_t half = 0; half < 2; ++half) {
      // The second half ends at the trace's end (an odd middle value is left out).
      const std::size_t begin = half == 0 ? 0 : length - n;
      double mean = 0.0;
      for (std::size_t i = begin; i < begin + n; ++i) mean += trace[i];
      mean /= static_cast<double>(n);
      double variance = 0.0;
      for (std::size_t i = begin; i < begin + n; ++i)
        variance += (trace[i] - mean) * (trace[i] - mean);
      means.push_back(mean);
      variances.push_back(variance / static_cast<double>(n - 1));
    }
  }
  const auto m = static_cast<double>(means.size());
  double grand = 0.0;
  for (double mean : means) grand += mean;
  grand /= m;
  double between = 0.0;  // B / n
  for (double mean : means) between += (mean - grand) * (mean - grand);
  between /= m - 1.0;
  double within = 0.0;
  for (double variance : variances) within += variance;
  within /= m;
  if (within == 0.0) return between == 0.0 ? 1.0 : std::numeric_limits<double>::infinity();
  const double nn = static_cast<double>(n);
  return std::sqrt(((nn - 1.0) / nn * within + between) / within);
}

double SecondHalfMean(std::span<const double> trace) {
  PRIORMAP_CHECK(trace.size() >= 2, "a second half needs at least 2 values");
  const std::size_t n = trace.size() / 2;
  double sum = 0.0;
  for (std::size_t i = trace.size() - n; i < trace.size(); ++i) sum += trace[i];
  return sum / static_cast<double>(n);
}

}  // namespace priormap::prf
