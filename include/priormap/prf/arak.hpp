#pragma once
/// Closed-form statistics of the Arak process (Paskin & Thrun, Sec. 1.3.2; Arak et al. 1993), the
/// yardsticks of the sampler's correctness tests and of `priormap prf prior-stats`.

#include <priormap/prf/window.hpp>

namespace priormap::prf {

/// Expected number of edges in a convex window: p·perimeter + 4πp²·area (4p + 4πp² in the unit
/// square). Boundary vertices are the window boundary's crossings, Poisson with mean 2p per unit
/// length, each the end of one edge; interior vertices have intensity 4πp² and two edge ends.
[[nodiscard]] double ExpectedEdges(double p, const Window& window);

/// Mean number of crossings of a fixed segment of length d: the count is Poisson(2pd).
[[nodiscard]] double ExpectedCrossings(double p, double d);

/// P(two points at distance d have the same colour) = P(even crossings) = ½(1 + e^{−4pd}).
[[nodiscard]] double SameColourProbability(double p, double d);

}  // namespace priormap::prf
