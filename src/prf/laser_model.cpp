#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include <priormap/prf/laser_model.hpp>

namespace priormap::prf {
namespace {

// Φ(x); exactly 1 in double precision beyond x = 8.5, where the erfc call is skipped.
double NormalCdf(double x) {
  if (x > 8.5) return 1.0;
  return 0.5 * std::erfc(-x * std::numbers::sqrt2 / 2.0);
}

// 1 - Φ(x), without the cancellation of computing it so.
double NormalTail(double x) {
  return 0.5 * std::erfc(x * std::numbers::sqrt2 / 2.0);
}

}  // namespace

std::string LaserModel::Problem() const {
  if (!(sigma > 0.0)) return fmt::format("sigma {} is not positive", sigma);
  if (!(hit_weight > 0.0 && outlier_weight > 0.0 && max_weight > 0.0))
    return fmt::format("the weights (hit {}, outlier {}, max {}) must all be positive", hit_weight,
                       outlier_weight, max_weight);
  const double total = hit_weight + outlier_weight + max_weight;
  if (std::abs(total - 1.0) > 1e-9)
    return fmt::format("the weights (hit {}, outlier {}, max {}) sum to {}, not 1", hit_weight,
                       outlier_weight, max_weight, total);
  return {};
}

double LaserModel::LogLikelihood(double reading, bool max_reading, double d,
                                 double max_range) const {
  const bool hit = std::isfinite(d);
  // The Gaussian truncated to r >= 0: its mass on [0, ∞).
  const double kept = hit ? NormalCdf(d / sigma) : 1.0;
  if (max_reading) {
    const double beyond = hit ? NormalTail((max_range - d) / sigma) / kept : 1.0;
    return std::log(max_weight + hit_weight * beyond);
  }
  double density = outlier_weight / max_range;
  if (hit) {
    const double z = (reading - d) / sigma;
    density +=
        hit_weight * std::exp(-0.5 * z * z) / (sigma * std::sqrt(2.0 * std::numbers::pi) * kept);
  }
  return std::log(density);
}

}  // namespace priormap::prf
