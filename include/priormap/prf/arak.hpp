#pragma once
/// Closed-form statistics of the Arak process (Paskin & Thrun, Sec. 1.3.2; Arak et al. 1993), the
/// yardsticks of the sampler's correctness tests and of `priormap prf prior-stats`.

#include <priormap/prf/window.hpp>

namespace priormap::prf {

/// The sums over a discontinuity graph that the Arak measure depends on (or their changes
/// under an edit: the log density is linear in them).
struct ColoringStats {
  int edges = 0;
  double total_length = 0.0;    // Σ|e|
  double sum_log_length = 0.0;  // Σ log|e|
  double sum_log_sin = 0.0;     // Σ log sin φ_v

  ColoringStats& operator+=(const ColoringStats& d) {
    edges += d.edges;
    total_length += d.total_length;
    sum_log_length += d.sum_log_length;
    sum_log_sin += d.sum_log_sin;
    return *this;
  }
};

/// log of the Arak measure's density against the base measure, with the potential:
/// |E| log p − Σ log|e| + Σ log sin φ_v − 2p Σ|e| (paper eqs. 1–3). Of an edit's statistics,
/// the change of the log density. It is ArakLogMeasure − ArakPotential.
[[nodiscard]] double ArakLogDensity(const ColoringStats& stats, double p);
/// The measure λ's part, |E| log p − Σ log|e| + Σ log sin φ_v (eq. 1): the reference measure,
/// never tempered.
[[nodiscard]] double ArakLogMeasure(const ColoringStats& stats, double p);
/// The potential F₀ = 2p Σ|e| (eq. 3): the prior's energy, tempered with the data's.
[[nodiscard]] double ArakPotential(const ColoringStats& stats, double p);

/// Expected number of edges in a convex window: p·perimeter + 4πp²·area (4p + 4πp² in the unit
/// square). Boundary vertices are the window boundary's crossings, Poisson with mean 2p per unit
/// length, each the end of one edge; interior vertices have intensity 4πp² and two edge ends.
[[nodiscard]] double ExpectedEdges(double p, const Window& window);

/// Mean number of crossings of a fixed segment of length d: the count is Poisson(2pd).
[[nodiscard]] double ExpectedCrossings(double p, double d);

/// P(two points at distance d have the same colour) = P(even crossings) = ½(1 + e^{−4pd}).
[[nodiscard]] double SameColourProbability(double p, double d);

}  // namespace priormap::prf
