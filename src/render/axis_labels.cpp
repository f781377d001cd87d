#include "axis_labels.hpp"

#include <algorithm>

#include <priormap/render/ticks.hpp>

#include "canvas.hpp"

namespace priormap::render::detail {

double TickLabels::Widest() const {
  return widths.empty() ? 0.0 : *std::max_element(widths.begin(), widths.end());
}

TickLabels LabelTicks(std::vector<double> ticks, double font_size) {
  TickLabels out;
  const double step = ticks.size() > 1 ? ticks[1] - ticks[0] : 1.0;
  for (const double t : ticks) {
    out.labels.push_back(TickLabel(t, step));
    out.widths.push_back(TextWidth(out.labels.back(), font_size));
  }
  out.ticks = std::move(ticks);
  return out;
}

std::pair<double, double> LabelOverhang(const TickLabels& labels, double lo, double hi,
                                        double length_px) {
  double before = 0.0, after = 0.0;
  for (std::size_t i = 0; i < labels.ticks.size(); ++i) {
    // Halves: hi - lo overflows when the range is wider than the largest double.
    const double t = labels.ticks[i];
    const double from_lo = (t / 2 - lo / 2) / (hi / 2 - lo / 2) * length_px;
    const double to_hi = (hi / 2 - t / 2) / (hi / 2 - lo / 2) * length_px;
    before = std::max(before, labels.widths[i] / 2 - from_lo);
    after = std::max(after, labels.widths[i] / 2 - to_hi);
  }
  return {before, after};
}

}  // namespace priormap::render::detail
