#pragma once
/// "Nice" axis ticks (1, 2, 5 times a power of ten), as plotting libraries choose them.

#include <string>
#include <vector>

namespace priormap::render {

/// Tick positions covering [lo, hi] with a step of 1, 2 or 5 times a power of ten, about
/// `target_count` of them, all inside [lo, hi]. Precondition: lo < hi, both finite.
[[nodiscard]] std::vector<double> NiceTicks(double lo, double hi, int target_count = 6);

/// The label of tick `value` when ticks are `step` apart: as many decimals as the step needs.
[[nodiscard]] std::string TickLabel(double value, double step);

}  // namespace priormap::render
