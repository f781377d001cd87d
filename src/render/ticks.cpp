#include <priormap/core/check.hpp>
#include <priormap/render/ticks.hpp>

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace priormap::render {

std::vector<double> NiceTicks(double lo, double hi, int target_count) {
  PRIORMAP_CHECK(std::isfinite(lo) && std::isfinite(hi) && lo < hi, "NiceTicks needs lo < hi");
  const double raw_step = (hi - lo) / std::max(target_count, 1);
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw_step)));
  double step = magnitude;
  for (double factor : {1.0, 2.0, 5.0, 10.0}) {
    step = factor * magnitude;
    if (step >= raw_step) break;
  }
  std::vector<double> ticks;
  const double first = std::ceil(lo / step - 1e-9) * step;
  for (double t = first; t <= hi + step * 1e-9; t += step) {
    ticks.push_back(std::abs(t) < step * 1e-9 ? 0.0 : t);  // no "-0"
  }
  return ticks;
}

std::string TickLabel(double value, double step) {
  const int decimals = std::max(0, static_cast<int>(std::ceil(-std::log10(step) - 1e-9)));
  return fmt::format("{:.{}f}", value, decimals);
}

}  // namespace priormap::render
