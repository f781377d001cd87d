#pragma once
/// Closed-form statistics of the Arak process (Paskin & Thrun, Sec. 1.3.2; Arak et al. 1993), the
/// yardsticks of the sampler's correctness tests and of `priormap prf prior-stats`.

#include <cmath>

#include <priormap/core/types.hpp>
#include <priormap/prf/window.hpp>

namespace priormap::prf {

/// The sums over a discontinuity graph that the Arak measure depends on (or their changes
/// under an edit: the log density is linear in them).
struct ColoringStats {
  int edges = 0;
  double total_length = 0.0;    ///< Σ|e|
  double sum_log_length = 0.0;  ///< Σ log|e|
  double sum_log_sin = 0.0;     ///< Σ log sin φ_v
  // Σ|e| cos 4θ_e and Σ|e| sin 4θ_e (θ_e the edge's direction): what an orientation
  // preference needs, whatever its preferred direction.
  double sum_cos4 = 0.0;
  double sum_sin4 = 0.0;

  ColoringStats& operator+=(const ColoringStats& d) {
    edges += d.edges;
    total_length += d.total_length;
    sum_log_length += d.sum_log_length;
    sum_log_sin += d.sum_log_sin;
    sum_cos4 += d.sum_cos4;
    sum_sin4 += d.sum_sin4;
    return *this;
  }
  /// Adds (sign +1) or removes (-1) an edge running along `d` (its length is |d|).
  void AddEdge(const Vec2& d, double sign) {
    const double length = d.norm();
    edges += sign > 0.0 ? 1 : -1;
    total_length += sign * length;
    sum_log_length += sign * std::log(length);
    // |e| cos 4θ and |e| sin 4θ from the direction's components, without trigonometry.
    const double xx = d.x() * d.x(), yy = d.y() * d.y(), xy = d.x() * d.y();
    const double cubed = length * length * length;
    sum_cos4 += sign * ((xx - yy) * (xx - yy) - 4.0 * xy * xy) / cubed;
    sum_sin4 += sign * 4.0 * xy * (xx - yy) / cubed;
  }
};

/// A preference for edges along two perpendicular directions (Paskin & Thrun, Sec. 4: "the
/// prior potential can be augmented with cost functions that prefer discontinuities at certain
/// orientations"): the potential κ Σ|e| sin²(2(θ_e − θ₀)), nothing for an edge along θ₀ or
/// across it, κ per metre at 45° to them. κ = 0 is the Arak process.
struct OrientationPrior {
  double weight = 0.0;  ///< κ, 1/m
  double angle = 0.0;   ///< θ₀, rad
};
/// The orientation potential of a coloring's statistics (or its change under an edit).
[[nodiscard]] double OrientationPotential(const ColoringStats& stats,
                                          const OrientationPrior& prior);

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
