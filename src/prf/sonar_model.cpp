#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <tuple>
#include <utility>
#include <vector>

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

// `weight` times a reading Gaussian around `mean` (σ), truncated to r >= 0: its density at
// `reading`, or, for a max reading, its mass at or beyond R.
double WeightedTruncatedNormal(double weight, double reading, bool max_reading, double mean,
                               double sigma, double max_range) {
  const double kept = NormalCdf(mean / sigma);  // the mass on [0, ∞)
  if (max_reading) return weight * NormalTail((max_range - mean) / sigma) / kept;
  const double z = (reading - mean) / sigma;
  return weight * std::exp(-0.5 * z * z) / (sigma * std::sqrt(2.0 * std::numbers::pi) * kept);
}

// A range's noise: a share of the distance, never below the floor.
double Spread(double floor, double relative, double distance) {
  return std::max(floor, relative * distance);
}

// A draw of that Gaussian.
double DrawTruncatedNormal(double mean, double sigma, Rng& rng) {
  double r;
  do r = rng.Normal(mean, sigma);
  while (r < 0.0);
  return r;
}

// The largest logistic coefficient accepted. A feature's logit sums a bias and three slopes
// times a distance (at most a few 1e9 m, priormap's bound on coordinates) or an angle; with
// coefficients up to 1e100 in magnitude no term overflows, where two opposite infinite terms
// (say face_per_m = -1e308 and face_per_rad_subtended = 1e308) would make it NaN. A logistic
// saturates long before: no usable model comes near the bound.
constexpr double kMaxCoefficient = 1e100;

// log(Φ(x)) for the truncation's kept mass (x >= 0 here: at least log(1/2)).
double LogNormalCdf(double x) {
  return std::log(NormalCdf(x));
}

// log(1 - Φ(x)), also where 1 - Φ(x) underflows (x beyond about 37): the asymptotic series
// -x²/2 - log(x √(2π)) + log(1 - 1/x² + 3/x⁴), relative error below 1e-7 there.
double LogNormalTail(double x) {
  if (x < 30.0) return std::log(NormalTail(x));
  const double inv2 = 1.0 / (x * x);
  return -0.5 * x * x - std::log(x * std::sqrt(2.0 * std::numbers::pi)) +
         std::log1p(-inv2 + 3.0 * inv2 * inv2);
}

// The log of WeightedTruncatedNormal's value for weight 1.
double LogTruncatedNormal(double reading, bool max_reading, double mean, double sigma,
                          double max_range) {
  const double log_kept = LogNormalCdf(mean / sigma);
  if (max_reading) return LogNormalTail((max_range - mean) / sigma) - log_kept;
  const double z = (reading - mean) / sigma;
  return -0.5 * z * z - std::log(sigma * std::sqrt(2.0 * std::numbers::pi)) - log_kept;
}

// log(Σ exp(terms)), terms of -inf left out.
double LogSumExp(const std::vector<double>& terms) {
  double top = -std::numeric_limits<double>::infinity();
  for (const double t : terms) top = std::max(top, t);
  if (!std::isfinite(top)) return top;
  double sum = 0.0;
  for (const double t : terms) sum += std::exp(t - top);
  return top + std::log(sum);
}

}  // namespace

std::string SonarModel::Problem() const {
  // Each message starts with the parameter's name, so that a file's reader reports it at its
  // value.
  for (const auto& [name, value] :
       {std::pair{"corner_bias", corner_bias}, std::pair{"corner_per_m", corner_per_m},
        std::pair{"concave_corner_bias", concave_corner_bias}, std::pair{"face_bias", face_bias},
        std::pair{"face_per_m", face_per_m},
        std::pair{"face_per_rad_projection", face_per_rad_projection},
        std::pair{"face_per_rad_subtended", face_per_rad_subtended}})
    if (!(std::abs(value) <= kMaxCoefficient))
      return fmt::format(
          "{} {} is not a finite logistic coefficient within ±{:g} (beyond it a feature's logit "
          "could overflow)",
          name, value, kMaxCoefficient);
  if (!(max_return > 0.0 && max_return < 1.0))
    return fmt::format("max_return {} is not in (0, 1)", max_return);
  // A subnormal sigma_min (below 2.2e-308) is refused: the density of a reading at its
  // feature's distance, 1/(sigma sqrt(2 pi)), would overflow to +inf.
  if (!(std::isnormal(sigma_min) && sigma_min > 0.0))
    return fmt::format("sigma_min {} is not a positive number of at least {} m", sigma_min,
                       std::numeric_limits<double>::min());
  if (!(sigma_relative >= 0.0 && std::isfinite(sigma_relative)))
    return fmt::format("sigma_relative {} is not a finite number >= 0", sigma_relative);
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
  if (!(multipath_weight >= 0.0 && multipath_weight < 1.0))
    return fmt::format("multipath_weight {} is not in [0, 1)", multipath_weight);
  if (!(multipath_sigma_relative > 0.0 && std::isfinite(multipath_sigma_relative)))
    return fmt::format("multipath_sigma_relative {} is not positive", multipath_sigma_relative);
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
                                    double max_range, Rng& rng,
                                    std::optional<double> multipath) const {
  const auto reading = [&](double r) {
    return r >= max_range ? Draw{.range = 0.0, .max_reading = true} : Draw{.range = r};
  };
  for (const SonarFeature& f : features) {
    if (!rng.Bernoulli(IndependentReturn(f))) continue;
    return reading(
        DrawTruncatedNormal(f.distance, Spread(sigma_min, sigma_relative, f.distance), rng));
  }
  if (multipath && models_multipath() && rng.Bernoulli(multipath_weight)) {
    if (!std::isfinite(*multipath)) return {.range = 0.0, .max_reading = true};
    return reading(DrawTruncatedNormal(
        *multipath, Spread(sigma_min, multipath_sigma_relative, *multipath), rng));
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
                                 double seen_fraction, std::optional<double> multipath) const {
  double density = 0.0;  // of the reading, or its probability when a max reading
  double none_closer = 1.0;
  for (const SonarFeature& f : features) {
    const double q = IndependentReturn(f);
    const double r = q * none_closer;
    none_closer *= 1.0 - q;
    density += WeightedTruncatedNormal(r, reading, max_reading, f.distance,
                                       Spread(sigma_min, sigma_relative, f.distance), max_range);
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
  if (multipath && models_multipath()) {
    // Heard along the mirrored path, or beyond R (a max reading) when that path is not.
    const double mirrored =
        std::isfinite(*multipath)
            ? WeightedTruncatedNormal(1.0, reading, max_reading, *multipath,
                                      Spread(sigma_min, multipath_sigma_relative, *multipath),
                                      max_range)
            : (max_reading ? 1.0 : 0.0);
    outlier = multipath_weight * mirrored + (1.0 - multipath_weight) * outlier;
  }
  const double likelihood = density + none_closer * outlier;
  if (!(likelihood < std::numeric_limits<double>::min())) return std::log(likelihood);
  // Underflow: many features that nearly always echo leave an outlier weight Π (1 − q_f) below
  // the smallest double, and a reading far from all of them has no echo term left either, so
  // the sum above is 0 (or subnormal) and its log -inf (or inexact), though every term of the
  // mixture is positive. The same sum in logarithms, term by term.
  std::vector<double> terms;
  terms.reserve(features.size() + 1);
  double log_none_closer = 0.0;
  for (const SonarFeature& f : features) {
    const double q = IndependentReturn(f);
    if (q > 0.0)
      terms.push_back(std::log(q) + log_none_closer +
                      LogTruncatedNormal(reading, max_reading, f.distance,
                                         Spread(sigma_min, sigma_relative, f.distance), max_range));
    log_none_closer += std::log1p(-q);
  }
  terms.push_back(log_none_closer + std::log(outlier));
  return LogSumExp(terms);
}

}  // namespace priormap::prf
