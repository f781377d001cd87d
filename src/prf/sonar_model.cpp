#include <algorithm>
#include <cmath>
#include <numbers>
#include <tuple>

#include <fmt/format.h>

#include <priormap/prf/sonar_model.hpp>

namespace priormap::prf {
namespace {

double Logistic(double x) {
  return 1.0 / (1.0 + std::exp(-x));
}

// Φ(x); exactly 1 in double precision beyond x = 8.5, where the erfc call is skipped.
double NormalCdf(double x) {
  if (x > 8.5) return 1.0;
  return 0.5 * std::erfc(-x * std::numbers::sqrt2 / 2.0);
}

// 1 - Φ(x), without the cancellation of computing it so.
double NormalTail(double x) {
  return 0.5 * std::erfc(x * std::numbers::sqrt2 / 2.0);
}

bool Finite(std::initializer_list<double> values) {
  return std::all_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); });
}

}  // namespace

std::string SonarModel::Problem() const {
  if (!Finite({corner_bias, corner_per_m, concave_corner_bias, face_bias, face_per_m,
               face_per_rad_projection, face_per_rad_subtended}))
    return "the logistic coefficients must be finite";
  if (!(max_return > 0.0 && max_return < 1.0))
    return fmt::format("max_return {} is not in (0, 1)", max_return);
  if (!(sigma_min > 0.0 && std::isfinite(sigma_min)) ||
      !(sigma_relative >= 0.0 && std::isfinite(sigma_relative)))
    return fmt::format("need sigma_min > 0 and sigma_relative >= 0 (got {} and {})", sigma_min,
                       sigma_relative);
  if (!(exponential_rate > 0.0 && std::isfinite(exponential_rate)))
    return fmt::format("exponential_rate {} is not positive", exponential_rate);
  for (const auto& [which, u, e, m] :
       {std::tuple{"", uniform_weight, exponential_weight, max_weight},
        std::tuple{"clear ", clear_uniform_weight, clear_exponential_weight, clear_max_weight}}) {
    if (!(u > 0.0 && e >= 0.0 && m > 0.0))
      return fmt::format(
          "the {}outlier weights (uniform {}, exponential {}, max {}) must be positive (the "
          "exponential's may be zero)",
          which, u, e, m);
    if (std::abs(u + e + m - 1.0) > 1e-9)
      return fmt::format(
          "the {}outlier weights (uniform {}, exponential {}, max {}) sum to {}, not 1", which, u,
          e, m, u + e + m);
  }
  return {};
}

double SonarModel::IndependentReturn(const SonarFeature& f) const {
  // Paskin & Thrun, Sec. 2.3: a logistic independent-return model.
  const double logit =
      f.kind == SonarFeature::Kind::kCorner
          ? corner_bias + corner_per_m * f.distance + (f.concave ? concave_corner_bias : 0.0)
          : face_bias + face_per_m * f.distance +
                face_per_rad_projection * (f.projection - std::numbers::pi / 2.0) +
                face_per_rad_subtended * f.subtended;
  return max_return * Logistic(logit);
}

double SonarModel::ReturnProbabilities(std::span<const SonarFeature> features,
                                       std::vector<double>* returns) const {
  returns->clear();
  double none_closer = 1.0;  // Π_{g<f} (1 − q_g)
  for (const SonarFeature& f : features) {
    const double q = IndependentReturn(f);
    returns->push_back(q * none_closer);
    none_closer *= 1.0 - q;
  }
  return none_closer;
}

SonarModel::Draw SonarModel::Sample(std::span<const SonarFeature> features, double seen_fraction,
                                    double max_range, Rng& rng) const {
  const auto reading = [&](double r) {
    return r >= max_range ? Draw{.range = 0.0, .max_reading = true} : Draw{.range = r};
  };
  for (const SonarFeature& f : features) {
    if (!rng.Bernoulli(IndependentReturn(f))) continue;
    const double sigma = std::max(sigma_min, sigma_relative * f.distance);
    double r;
    do r = rng.Normal(f.distance, sigma);
    while (r < 0.0);
    return reading(r);
  }
  const bool specular = rng.Bernoulli(seen_fraction);
  const double u = specular ? uniform_weight : clear_uniform_weight;
  const double e = specular ? exponential_weight : clear_exponential_weight;
  const double pick = rng.Uniform();
  if (pick < u) return reading(rng.Uniform(0.0, max_range));
  if (pick < u + e)  // the exponential truncated to [0, R), by inversion
    return reading(std::min(
        std::nextafter(max_range, 0.0),
        -std::log1p(rng.Uniform() * std::expm1(-exponential_rate * max_range)) / exponential_rate));
  return {.range = 0.0, .max_reading = true};
}

double SonarModel::LogLikelihood(double reading, bool max_reading,
                                 std::span<const SonarFeature> features, double max_range,
                                 double seen_fraction) const {
  double density = 0.0;  // of the reading, or its probability when a max reading
  double none_closer = 1.0;
  for (const SonarFeature& f : features) {
    const double q = IndependentReturn(f);
    const double r = q * none_closer;
    none_closer *= 1.0 - q;
    const double sigma = std::max(sigma_min, sigma_relative * f.distance);
    // The Gaussian truncated to r >= 0: its mass on [0, ∞).
    const double kept = NormalCdf(f.distance / sigma);
    if (max_reading) {
      density += r * NormalTail((max_range - f.distance) / sigma) / kept;
    } else {
      const double z = (reading - f.distance) / sigma;
      density += r * std::exp(-0.5 * z * z) / (sigma * std::sqrt(2.0 * std::numbers::pi) * kept);
    }
  }
  const double specular = seen_fraction, clear = 1.0 - seen_fraction;
  double outlier;
  if (max_reading) {
    outlier = specular * max_weight + clear * clear_max_weight;
  } else {
    const double exponential = exponential_rate * std::exp(-exponential_rate * reading) /
                               -std::expm1(-exponential_rate * max_range);
    outlier = (specular * uniform_weight + clear * clear_uniform_weight) / max_range +
              (specular * exponential_weight + clear * clear_exponential_weight) * exponential;
  }
  return std::log(density + none_closer * outlier);
}

}  // namespace priormap::prf
