#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include <priormap/core/check.hpp>
#include <priormap/render/figure_size.hpp>
#include <priormap/render/ticks.hpp>

namespace priormap::render {

std::vector<double> NiceTicks(double lo, double hi, int target_count) {
  PRIORMAP_CHECK(std::isfinite(lo) && std::isfinite(hi) && lo < hi,
                 fmt::format("NiceTicks needs finite lo < hi (got [{}, {}])", lo, hi));
  // As many ticks are made as asked for: 2^31 of them took gigabytes, then the index overflowed.
  // One a pixel along the largest figure's side is more than any axis can show.
  PRIORMAP_CHECK(target_count <= kMaxFigureSidePx,
                 fmt::format("NiceTicks' target_count must be at most {} (got {})",
                             kMaxFigureSidePx, target_count));
  const double count = std::max(target_count, 1);
  // Not (hi - lo) / count: hi - lo overflows when the range is wider than the largest double.
  const double raw_step = hi / count - lo / count;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw_step)));
  double step = magnitude;
  for (double factor : {1.0, 2.0, 5.0, 10.0}) {
    step = factor * magnitude;
    if (step >= raw_step) break;
  }
  // Each tick is computed from its index: adding up steps drifts, and never gets past lo when
  // the step is below the spacing of doubles there (a range only a few doubles wide).
  const double tolerance = step * 1e-9;
  const double first = std::ceil(lo / step - 1e-9);
  const double last = std::floor(hi / step + 1e-9);
  std::vector<double> ticks;
  // step >= raw_step, so last - first <= count; the cap only matters when a denormal range
  // gives a zero step and infinite indices.
  for (int i = 0; i <= last - first && i <= count + 1; ++i) {
    const double t = (first + i) * step;
    // Skip ticks that rounding put outside the range (or NaN), and repeats where the step is
    // below the resolution of doubles; write 0 rather than "-0".
    if (!(t >= lo - tolerance && t <= hi + tolerance)) continue;
    if (!ticks.empty() && t <= ticks.back()) continue;
    ticks.push_back(std::abs(t) < tolerance ? 0.0 : t);
  }
  return ticks;
}

std::vector<double> SpacedNiceTicks(double lo, double hi, int target_count, double length_px,
                                    double min_spacing_px) {
  std::vector<double> ticks;
  for (int target = std::max(target_count, 1); target >= 1; --target) {
    ticks = NiceTicks(lo, hi, target);
    if (ticks.size() < 2) break;
    // hi / length - lo / length: the range may be wider than the largest double.
    const double spacing_px = (ticks[1] - ticks[0]) / (hi / length_px - lo / length_px);
    if (spacing_px >= min_spacing_px) break;
  }
  return ticks;
}

std::string TickLabel(double value, double step) {
  // Longer labels run off a plot's margin (a range of 1e13, or of 1e-12).
  constexpr std::size_t kLongestFixed = 8;
  const int decimals = std::max(0, static_cast<int>(std::ceil(-std::log10(step) - 1e-9)));
  std::string fixed = fmt::format("{:.{}f}", value, decimals);
  if (fixed.size() <= kLongestFixed) return fixed;
  if (value == 0.0) return "0";
  // The mantissa's digits down to the step's leading one, so that neighbours differ.
  const int digits = std::max(0, static_cast<int>(std::floor(std::log10(std::abs(value))) -
                                                  std::floor(std::log10(step) + 1e-9)));
  std::string scientific = fmt::format("{:.{}e}", value, digits);
  return scientific.size() < fixed.size() ? scientific : fixed;
}

}  // namespace priormap::render
