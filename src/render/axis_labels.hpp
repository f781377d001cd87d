#pragma once
// Tick labels as the figures lay them out: each centred under (or beside) its tick, so that the
// margins can make room for the labels at the ends of an axis.

#include <string>
#include <utility>
#include <vector>

namespace priormap::render::detail {

/// Ticks with their labels (TickLabel, as many decimals as their step needs) and the labels'
/// widths at a font size.
struct TickLabels {
  std::vector<double> ticks;
  std::vector<std::string> labels;
  std::vector<double> widths;

  [[nodiscard]] double Widest() const;
};

/// The labels of `ticks` (in increasing order) at `font_size`.
[[nodiscard]] TickLabels LabelTicks(std::vector<double> ticks, double font_size);

/// How far labels centred on their ticks reach beyond the ends of an axis `length_px` long that
/// shows [lo, hi]: {before lo, after hi}, in pixels, 0 where they stay inside. Ranges wider than
/// the largest double are fine.
[[nodiscard]] std::pair<double, double> LabelOverhang(const TickLabels& labels, double lo,
                                                      double hi, double length_px);

}  // namespace priormap::render::detail
