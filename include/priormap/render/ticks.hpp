#pragma once
/// "Nice" axis ticks (1, 2, 5 times a power of ten), as plotting libraries choose them.

#include <string>
#include <vector>

namespace priormap::render {

/// Tick positions covering [lo, hi] with a step of 1, 2 or 5 times a power of ten, about
/// `target_count` of them, all inside [lo, hi]. Preconditions: lo < hi, both finite;
/// target_count at most kMaxFigureSidePx (figure_size.hpp; below 1 counts as 1).
[[nodiscard]] std::vector<double> NiceTicks(double lo, double hi, int target_count = 6);

/// NiceTicks on an axis `length_px` long, with a smaller target where ticks would be closer than
/// `min_spacing_px` (their labels would overlap): a thin plot gets one or two ticks, not eight on
/// top of each other. Preconditions as NiceTicks'.
[[nodiscard]] std::vector<double> SpacedNiceTicks(double lo, double hi, int target_count,
                                                  double length_px, double min_spacing_px);

/// The label of tick `value` when ticks are `step` apart: as many decimals as the step needs, or,
/// when that is longer than 8 characters, the shorter of it and the same value in scientific
/// notation with as many digits as the step needs ("5.5e+12", "2e-13").
[[nodiscard]] std::string TickLabel(double value, double step);

}  // namespace priormap::render
