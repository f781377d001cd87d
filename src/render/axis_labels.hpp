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

/// Grows the margins `left` and `right` until the labels at the ends of an axis fit.
/// `lay_out(left, right)` lays the figure out with those margins and returns by how much the end
/// labels overrun them, {left, right} (<= 0 where they fit). A margin grows by its shortfall and
/// a little more, so that the rounds end; the layout may change its ticks as the plot narrows, so
/// this is repeated, at most kMaxMarginRounds times. The layout of the last call stands.
inline constexpr int kMaxMarginRounds = 24;
template <typename LayOut>
void GrowMarginsForEndLabels(double& left, double& right, LayOut lay_out) {
  for (int round = 0;; ++round) {
    const auto [short_left, short_right] = lay_out(left, right);
    if ((short_left <= 0.0 && short_right <= 0.0) || round == kMaxMarginRounds) return;
    if (short_left > 0.0) left += short_left + 0.25;
    if (short_right > 0.0) right += short_right + 0.25;
  }
}

}  // namespace priormap::render::detail
