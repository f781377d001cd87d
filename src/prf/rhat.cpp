#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <span>

#include <priormap/core/check.hpp>
#include <priormap/prf/rhat.hpp>

namespace priormap::prf {
namespace {

// The first and the second ⌊length/2⌋ values of a trace; the second ends at the trace's end, so
// an odd middle value is left out. SplitRhat and SecondHalfMean cut alike through this.
std::array<std::span<const double>, 2> Halves(std::span<const double> trace, std::size_t length) {
  const std::size_t n = length / 2;
  return {trace.subspan(0, n), trace.subspan(length - n, n)};
}

double Mean(std::span<const double> values) {
  double sum = 0.0;
  for (double v : values) sum += v;
  return sum / static_cast<double>(values.size());
}

}  // namespace

double SplitRhat(std::span<const std::vector<double>> traces) {
  PRIORMAP_CHECK(!traces.empty(), "R-hat needs at least one trace");
  std::size_t length = traces[0].size();
  for (const auto& trace : traces) length = std::min(length, trace.size());
  PRIORMAP_CHECK(length >= 4, "R-hat needs traces of at least 4 values");
  const std::size_t n = length / 2;
  std::vector<double> means, variances;
  for (const auto& trace : traces) {
    for (std::span<const double> half : Halves(trace, length)) {
      const double mean = Mean(half);
      double variance = 0.0;
      for (double v : half) variance += (v - mean) * (v - mean);
      means.push_back(mean);
      variances.push_back(variance / static_cast<double>(n - 1));
    }
  }
  const auto m = static_cast<double>(means.size());
  const double grand = Mean(means);
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
  return Mean(Halves(trace, trace.size())[1]);
}

}  // namespace priormap::prf
