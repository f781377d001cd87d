#include <cmath>
#include <numbers>

#include <priormap/prf/arak.hpp>

namespace priormap::prf {

double ArakLogMeasure(const ColoringStats& stats, double p) {
  return stats.edges * std::log(p) - stats.sum_log_length + stats.sum_log_sin;
}

double ArakPotential(const ColoringStats& stats, double p) {
  return 2.0 * p * stats.total_length;
}

double ArakLogDensity(const ColoringStats& stats, double p) {
  return ArakLogMeasure(stats, p) - ArakPotential(stats, p);
}

double OrientationPotential(const ColoringStats& stats, const OrientationPrior& prior) {
  if (prior.weight == 0.0) return 0.0;
  // sin²(2(θ − θ₀)) = (1 − cos 4θ cos 4θ₀ − sin 4θ sin 4θ₀) / 2, weighted by |e| and summed.
  const double c = std::cos(4.0 * prior.angle), s = std::sin(4.0 * prior.angle);
  return 0.5 * prior.weight * (stats.total_length - c * stats.sum_cos4 - s * stats.sum_sin4);
}

double ExpectedEdges(double p, const Window& window) {
  return p * window.Perimeter() + 4.0 * std::numbers::pi * p * p * window.Area();
}

double ExpectedCrossings(double p, double d) {
  return 2.0 * p * d;
}

double SameColourProbability(double p, double d) {
  return 0.5 * (1.0 + std::exp(-4.0 * p * d));
}

}  // namespace priormap::prf
