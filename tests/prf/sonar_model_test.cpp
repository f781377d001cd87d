// The PRF sonar model: the return probabilities and the outlier weight sum to one, the density
// integrates to one over [0, R) plus the max-reading atom for any set of features and share of
// the cone seen, Sample draws from that density, and the independent-return model moves the way
// the paper says (concave corners echoing more when their bias says so).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <priormap/core/rng.hpp>
#include <priormap/prf/sonar_model.hpp>

namespace priormap::prf {
namespace {

using Kind = SonarFeature::Kind;

SonarFeature Face(double distance, double projection, double subtended) {
  return {
      .kind = Kind::kFace, .distance = distance, .projection = projection, .subtended = subtended};
}
SonarFeature Corner(double distance, bool concave = false) {
  return {.kind = Kind::kCorner,
          .distance = distance,
          .projection = 0.0,
          .subtended = 0.0,
          .concave = concave};
}

// ∫_0^R p(r | features) dr + P(max | features), by Simpson's rule on a grid fine against the
// narrowest Gaussian.
double TotalProbability(const SonarModel& model, const std::vector<SonarFeature>& features,
                        double max_range, double seen_fraction = 1.0,
                        std::optional<double> multipath = std::nullopt) {
  const int n = 100000;  // even
  const double h = max_range / n;
  double sum = 0.0;
  for (int i = 0; i <= n; ++i) {
    const double weight = (i == 0 || i == n) ? 1.0 : (i % 2 == 1 ? 4.0 : 2.0);
    const double r = std::min(i * h, max_range * (1.0 - 1e-15));  // [0, R): just below R
    sum += weight *
           std::exp(model.LogLikelihood(r, false, features, max_range, seen_fraction, multipath));
  }
  return sum * h / 3.0 + std::exp(model.LogLikelihood(max_range, true, features, max_range,
                                                      seen_fraction, multipath));
}

// Random features in depth order, as a view would give them; corners are concave half of the
// time when `with_concave_corners`.
std::vector<SonarFeature> RandomFeatures(std::mt19937_64& random, int count, double max_range,
                                         bool with_concave_corners = false) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<SonarFeature> features;
  double distance = 0.05;
  for (int k = 0; k < count; ++k) {
    distance += (max_range - distance) * unit(random) * 0.5;
    if (unit(random) < 0.5)
      features.push_back(Corner(distance, with_concave_corners && unit(random) < 0.5));
    else
      features.push_back(Face(distance, 0.2 + 1.37 * unit(random), 0.35 * unit(random)));
  }
  return features;
}

TEST(SonarModel, ReturnProbabilitiesAndTheOutlierWeightSumToOne) {
  const SonarModel model;
  ASSERT_EQ(model.Problem(), "");
  std::mt19937_64 random(3);
  std::vector<double> returns;
  for (int trial = 0; trial < 200; ++trial) {
    const auto features = RandomFeatures(random, trial % 9, 5.0);
    const double outlier = model.ReturnProbabilities(features, &returns);
    ASSERT_EQ(returns.size(), features.size());
    double total = outlier;
    for (double r : returns) {
      EXPECT_GE(r, 0.0);
      total += r;
    }
    EXPECT_NEAR(total, 1.0, 1e-12);
  }
  // Three features that would each echo half of the time: 1/2, 1/4, 1/8 and 1/8 left over,
  // where the paper's printed (1 - r_g) would give 1/2, 1/4, 3/16 and a total above one.
  SonarModel half = model;
  half.corner_bias = 0.0;
  half.corner_per_m = 0.0;
  half.max_return = 0.999999;
  const double q = half.IndependentReturn(Corner(1.0));
  const std::vector<SonarFeature> three = {Corner(1), Corner(2), Corner(3)};
  const double outlier = half.ReturnProbabilities(three, &returns);
  EXPECT_NEAR(returns[0], q, 1e-15);
  EXPECT_NEAR(returns[1], q * (1 - q), 1e-15);
  EXPECT_NEAR(returns[2], q * (1 - q) * (1 - q), 1e-15);
  EXPECT_NEAR(outlier, std::pow(1 - q, 3), 1e-15);
}

TEST(SonarModel, IntegratesToOneOverRangeForAnyFeatures) {
  const SonarModel model;
  const double r_max = 5.0;
  EXPECT_NEAR(TotalProbability(model, {}, r_max), 1.0, 1e-6);
  EXPECT_NEAR(TotalProbability(model, {Face(2.0, std::numbers::pi / 2, 0.35)}, r_max), 1.0, 1e-6);
  // Near the apex (the truncation at 0 matters) and near R (mass beyond R is a max reading).
  EXPECT_NEAR(TotalProbability(model, {Corner(0.01), Face(4.99, 1.2, 0.1)}, r_max), 1.0, 1e-6);
  std::mt19937_64 random(8);
  for (int trial = 0; trial < 6; ++trial)
    EXPECT_NEAR(TotalProbability(model, RandomFeatures(random, 1 + trial, r_max), r_max), 1.0, 1e-6)
        << "trial " << trial;
  SonarModel wide;
  wide.sigma_min = 0.2;
  wide.sigma_relative = 0.05;
  wide.uniform_weight = 0.5;
  wide.exponential_weight = 0.0;
  wide.max_weight = 0.5;
  EXPECT_NEAR(TotalProbability(wide, {Corner(0.1), Face(3.0, 1.5, 0.2)}, 3.5), 1.0, 1e-6);
}

TEST(SonarModel, EchoesAreLessLikelyFartherObliquerAndNarrower) {
  const SonarModel model;
  const double normal = std::numbers::pi / 2;
  EXPECT_GT(model.IndependentReturn(Face(1.0, normal, 0.3)),
            model.IndependentReturn(Face(3.0, normal, 0.3)));
  EXPECT_GT(model.IndependentReturn(Face(2.0, normal, 0.3)),
            model.IndependentReturn(Face(2.0, normal - 0.2, 0.3)));
  EXPECT_GT(model.IndependentReturn(Face(2.0, normal, 0.3)),
            model.IndependentReturn(Face(2.0, normal, 0.05)));
  EXPECT_GT(model.IndependentReturn(Corner(1.0)), model.IndependentReturn(Corner(3.0)));
  EXPECT_LE(model.IndependentReturn(Face(0.0, normal, 10.0)), model.max_return);
}

TEST(SonarModel, TheNearestFeatureOutweighsOnesBehindIt) {
  const SonarModel model;
  const std::vector<SonarFeature> features = {Face(1.0, std::numbers::pi / 2, 0.35),
                                              Face(2.0, std::numbers::pi / 2, 0.35)};
  EXPECT_GT(model.LogLikelihood(1.0, false, features, 5.0),
            model.LogLikelihood(2.0, false, features, 5.0));
  // With nothing in the cone a max reading is likelier than with a wall in front.
  EXPECT_GT(model.LogLikelihood(5.0, true, {}, 5.0), model.LogLikelihood(5.0, true, features, 5.0));
}

TEST(SonarModel, ReportsBadParameters) {
  SonarModel model;
  model.max_return = 1.0;
  EXPECT_NE(model.Problem(), "");
  model = SonarModel{};
  model.sigma_min = 0.0;
  EXPECT_NE(model.Problem(), "");
  model = SonarModel{};
  model.max_weight = 0.5;
  EXPECT_NE(model.Problem(), "");
  model = SonarModel{};
  model.face_bias = std::nan("");
  EXPECT_NE(model.Problem(), "");
}

// A model with concave corners favoured and a clear mixture unlike the specular one, so that
// both new parts of the density are exercised.
SonarModel MixtureModel() {
  SonarModel model;
  model.concave_corner_bias = 1.5;
  model.clear_uniform_weight = 0.15;
  model.clear_exponential_weight = 0.05;
  model.clear_max_weight = 0.8;
  return model;
}

TEST(SonarModel, IntegratesToOneForAnySeenFractionAndConcaveCorners) {
  const SonarModel model = MixtureModel();
  ASSERT_EQ(model.Problem(), "");
  const double r_max = 5.0;
  std::mt19937_64 random(21);
  for (double seen : {0.0, 0.3, 0.75, 1.0}) {
    SCOPED_TRACE(::testing::Message() << "seen fraction " << seen);
    EXPECT_NEAR(TotalProbability(model, {}, r_max, seen), 1.0, 1e-6);
    EXPECT_NEAR(TotalProbability(model, {Corner(0.02, true), Corner(2.0, false)}, r_max, seen), 1.0,
                1e-6);
    EXPECT_NEAR(TotalProbability(model, {Corner(1.0, true), Face(4.98, 1.5, 0.1)}, r_max, seen),
                1.0, 1e-6);
    for (int trial = 0; trial < 3; ++trial)
      EXPECT_NEAR(
          TotalProbability(model, RandomFeatures(random, 2 + trial, r_max, true), r_max, seen), 1.0,
          1e-6)
          << "trial " << trial;
  }
}

TEST(SonarModel, WithEqualMixturesTheSeenFractionChangesNothing) {
  // The defaults: the clear mixture equals the specular one (the paper's single mixture).
  SonarModel model;
  model.concave_corner_bias = 0.8;
  ASSERT_EQ(model.clear_uniform_weight, model.uniform_weight);
  ASSERT_EQ(model.clear_exponential_weight, model.exponential_weight);
  ASSERT_EQ(model.clear_max_weight, model.max_weight);
  const double r_max = 5.0;
  const std::vector<SonarFeature> features = {Corner(1.2, true), Face(2.5, 1.4, 0.2)};
  for (double r : {0.0, 0.7, 1.2, 2.5, 4.9}) {
    const double at_one = model.LogLikelihood(r, false, features, r_max, 1.0);
    for (double seen : {0.0, 0.37, 0.9})
      EXPECT_NEAR(model.LogLikelihood(r, false, features, r_max, seen), at_one, 1e-14)
          << "r = " << r << ", seen fraction " << seen;
  }
  const double max_at_one = model.LogLikelihood(r_max, true, features, r_max, 1.0);
  EXPECT_NEAR(model.LogLikelihood(r_max, true, features, r_max, 0.0), max_at_one, 1e-14);
  // With no feature the reading is an outlier: the paper's mixture in closed form.
  const double rate = model.exponential_rate;
  for (double r : {0.0, 1.0, 3.3}) {
    const double density = model.uniform_weight / r_max + model.exponential_weight * rate *
                                                              std::exp(-rate * r) /
                                                              (1.0 - std::exp(-rate * r_max));
    EXPECT_NEAR(model.LogLikelihood(r, false, {}, r_max, 0.2), std::log(density), 1e-12);
  }
  EXPECT_NEAR(model.LogLikelihood(r_max, true, {}, r_max, 0.6), std::log(model.max_weight), 1e-14);
  // With unequal mixtures it does matter: a cone that sees nothing gets the clear mixture.
  const SonarModel unequal = MixtureModel();
  EXPECT_NEAR(unequal.LogLikelihood(r_max, true, {}, r_max, 0.0),
              std::log(unequal.clear_max_weight), 1e-14);
  EXPECT_NEAR(unequal.LogLikelihood(r_max, true, {}, r_max, 0.25),
              std::log(0.25 * unequal.max_weight + 0.75 * unequal.clear_max_weight), 1e-14);
}

TEST(SonarModel, ConcaveCornersEchoMoreByTheirBias) {
  SonarModel model;
  EXPECT_EQ(model.IndependentReturn(Corner(2.0, true)), model.IndependentReturn(Corner(2.0)));
  model.concave_corner_bias = 1.3;
  for (double d : {0.5, 2.0, 4.0}) {
    const double concave = model.IndependentReturn(Corner(d, true));
    const double convex = model.IndependentReturn(Corner(d, false));
    EXPECT_GT(concave, convex);
    // q = max_return · logistic(logit): the logits differ by the bias exactly.
    const auto logit = [&](double q) { return std::log(q / (model.max_return - q)); };
    EXPECT_NEAR(logit(concave) - logit(convex), 1.3, 1e-9) << "d = " << d;
  }
  // The flag is a corner's: a face's echo ignores it.
  SonarFeature face = Face(2.0, 1.4, 0.2);
  const double before = model.IndependentReturn(face);
  face.concave = true;
  EXPECT_EQ(model.IndependentReturn(face), before);
  model.concave_corner_bias = -2.0;
  EXPECT_LT(model.IndependentReturn(Corner(1.0, true)), model.IndependentReturn(Corner(1.0)));
}

// ∫ p(r | features) dr over [lo, hi) by Simpson's rule (fine against the narrowest Gaussian).
double BinProbability(const SonarModel& model, const std::vector<SonarFeature>& features,
                      double max_range, double seen_fraction, std::optional<double> multipath,
                      double lo, double hi) {
  const int n = 400;  // even
  const double h = (hi - lo) / n;
  double sum = 0.0;
  for (int i = 0; i <= n; ++i) {
    const double weight = (i == 0 || i == n) ? 1.0 : (i % 2 == 1 ? 4.0 : 2.0);
    const double r = std::min(lo + i * h, max_range * (1.0 - 1e-15));
    sum += weight *
           std::exp(model.LogLikelihood(r, false, features, max_range, seen_fraction, multipath));
  }
  return sum * h / 3.0;
}

// Draws 200000 readings from Sample and compares the share of max readings and of each 0.1 m
// bin of [0, R) with the model's probabilities. Each count is binomial(n, p): within 5 of its
// standard errors sqrt(n p (1 - p)), so that with 51 counts a correct sampler fails less than
// once in 30000 seeds (and the seed is fixed).
void ExpectSampleMatchesLikelihood(const SonarModel& model,
                                   const std::vector<SonarFeature>& features, double seen,
                                   std::uint64_t seed,
                                   std::optional<double> multipath = std::nullopt) {
  const double r_max = 5.0;
  constexpr int kBins = 50;
  constexpr int kDraws = 200000;
  Rng rng(seed);
  std::vector<int> counts(kBins, 0);
  int max_readings = 0;
  for (int i = 0; i < kDraws; ++i) {
    const SonarModel::Draw draw = model.Sample(features, seen, r_max, rng, multipath);
    if (draw.max_reading) {
      ++max_readings;
      continue;
    }
    ASSERT_GE(draw.range, 0.0);
    ASSERT_LT(draw.range, r_max);
    ++counts[static_cast<std::size_t>(std::min(kBins - 1, static_cast<int>(draw.range / 0.1)))];
  }
  const auto expect_count = [&](int count, double p, const std::string& what) {
    const double mean = kDraws * p;
    const double standard_error = std::sqrt(kDraws * p * (1.0 - p));
    EXPECT_LE(std::abs(count - mean), 5.0 * standard_error + 1.0)
        << what << ": " << count << " draws, expected " << mean << " ± " << standard_error;
  };
  const double p_max = std::exp(model.LogLikelihood(r_max, true, features, r_max, seen, multipath));
  expect_count(max_readings, p_max, "max readings");
  double total = p_max;
  for (int b = 0; b < kBins; ++b) {
    const double p =
        BinProbability(model, features, r_max, seen, multipath, 0.1 * b, 0.1 * (b + 1));
    total += p;
    expect_count(counts[static_cast<std::size_t>(b)], p, "bin " + std::to_string(b));
  }
  EXPECT_NEAR(total, 1.0, 1e-6);  // the bins cover the whole observation space
}

TEST(SonarModel, SampleDrawsFromTheLikelihoodsDensity) {
  SonarModel model = MixtureModel();
  model.sigma_min = 0.05;  // wide enough for 0.1 m bins to resolve each echo's shape
  model.sigma_relative = 0.02;
  // Echoes: near the apex (the truncation at 0), a concave and a convex corner, and a face
  // whose Gaussian reaches past R (part of its mass is max readings).
  {
    SCOPED_TRACE("echoes");
    ExpectSampleMatchesLikelihood(model,
                                  {Corner(0.04, false), Face(1.5, 1.5, 0.3), Corner(2.5, true),
                                   Corner(3.2, false), Face(4.95, std::numbers::pi / 2, 0.35)},
                                  0.6, 2024);
  }
  // Outliers: one narrow oblique face that hardly ever echoes, in a cone mostly clear, so that
  // both mixtures weigh (the clear one more).
  {
    SCOPED_TRACE("outliers");
    const std::vector<SonarFeature> faint = {Face(3.0, 1.1, 0.05)};
    ASSERT_LT(model.IndependentReturn(faint[0]), 0.01);
    ExpectSampleMatchesLikelihood(model, faint, 0.3, 2025);
  }
}

// MixtureModel with the multipath component on, its spread wide enough for 0.1 m bins.
SonarModel MultipathModel() {
  SonarModel model = MixtureModel();
  model.multipath_weight = 0.4;
  model.multipath_sigma_relative = 0.03;
  model.sigma_min = 0.05;
  return model;
}

TEST(SonarModel, WithMultipathItStillIntegratesToOne) {
  const SonarModel model = MultipathModel();
  ASSERT_EQ(model.Problem(), "");
  const double r_max = 5.0;
  const double inf = std::numeric_limits<double>::infinity();
  std::mt19937_64 random(22);
  // A path well inside R, one whose Gaussian straddles R (part of it a max reading), one near
  // the apex (truncated at 0), one not heard within R, and no mirror at all.
  for (const std::optional<double> multipath :
       {std::optional(2.7), std::optional(4.97), std::optional(0.03), std::optional(inf),
        std::optional<double>()}) {
    SCOPED_TRACE(::testing::Message() << "multipath " << multipath.value_or(-1.0));
    for (double seen : {0.0, 0.6, 1.0}) {
      EXPECT_NEAR(TotalProbability(model, {}, r_max, seen, multipath), 1.0, 1e-6);
      EXPECT_NEAR(
          TotalProbability(model, RandomFeatures(random, 3, r_max, true), r_max, seen, multipath),
          1.0, 1e-6);
    }
  }
}

TEST(SonarModel, MultipathMixesAGaussianAtThePathIntoTheOutliers) {
  SonarModel model = MixtureModel();
  const double r_max = 5.0;
  const double seen = 0.7;
  const std::vector<SonarFeature> features = {Face(1.0, 1.2, 0.1)};
  // Off (weight 0), the path changes nothing: the paper's model.
  for (double r : {0.5, 2.0, 3.1})
    EXPECT_EQ(model.LogLikelihood(r, false, features, r_max, seen, 3.0),
              model.LogLikelihood(r, false, features, r_max, seen));
  model.multipath_weight = 0.25;
  model.multipath_sigma_relative = 0.02;
  std::vector<double> returns;
  const double outlier = model.ReturnProbabilities(features, &returns);
  const auto gaussian = [](double r, double mean, double sigma) {
    const double z = (r - mean) / sigma;
    return std::exp(-0.5 * z * z) / (sigma * std::sqrt(2.0 * std::numbers::pi));
  };
  // p = echo + outlier · mixture without the path; with it, the mixture becomes
  // 0.25 N(r; 3, 0.02 · 3) + 0.75 · mixture, and the echo stays.
  for (double r : {0.99, 2.9, 3.0, 3.05, 4.0}) {
    const double without = std::exp(model.LogLikelihood(r, false, features, r_max, seen));
    const double echo = returns[0] * gaussian(r, 1.0, model.sigma_min);
    const double mixture = (without - echo) / outlier;
    const double expected = echo + outlier * (0.25 * gaussian(r, 3.0, 0.06) + 0.75 * mixture);
    EXPECT_NEAR(std::exp(model.LogLikelihood(r, false, features, r_max, seen, 3.0)), expected,
                1e-9 * expected)
        << "r = " << r;
  }
  // A path not heard within R gives its share to the max reading.
  const double max_without = std::exp(model.LogLikelihood(r_max, true, features, r_max, seen));
  const double max_with = std::exp(model.LogLikelihood(r_max, true, features, r_max, seen,
                                                       std::numeric_limits<double>::infinity()));
  EXPECT_NEAR(max_with, outlier * 0.25 + 0.75 * max_without, 1e-12);
  // Beyond R a Gaussian path is a max reading too: half of one centred on R.
  const double max_at_r = std::exp(model.LogLikelihood(r_max, true, features, r_max, seen, r_max));
  EXPECT_NEAR(max_at_r, outlier * 0.25 * 0.5 + 0.75 * max_without, 1e-12);
}

TEST(SonarModel, SampleDrawsMultipathReadingsFromTheLikelihoodsDensity) {
  const SonarModel model = MultipathModel();
  const std::vector<SonarFeature> faint = {Face(2.0, 1.1, 0.05), Corner(4.0, false)};
  {
    SCOPED_TRACE("a path within R");
    ExpectSampleMatchesLikelihood(model, faint, 0.8, 2026, 3.4);
  }
  {
    SCOPED_TRACE("a path straddling R");
    ExpectSampleMatchesLikelihood(model, faint, 0.8, 2027, 4.9);
  }
  {
    SCOPED_TRACE("a path not heard within R");
    ExpectSampleMatchesLikelihood(model, faint, 0.8, 2028, std::numeric_limits<double>::infinity());
  }
}

TEST(SonarModel, ReportsBadMultipathParameters) {
  using ::testing::HasSubstr;
  SonarModel model;
  model.multipath_weight = 1.0;
  EXPECT_THAT(model.Problem(), HasSubstr("multipath_weight"));
  model.multipath_weight = -0.1;
  EXPECT_THAT(model.Problem(), HasSubstr("multipath_weight"));
  model = SonarModel{};
  model.multipath_sigma_relative = 0.0;
  EXPECT_THAT(model.Problem(), HasSubstr("multipath_sigma_relative"));
  model.multipath_sigma_relative = std::nan("");
  EXPECT_THAT(model.Problem(), HasSubstr("multipath_sigma_relative"));
}

TEST(SonarModel, ReportsBadClearWeightsAndCoefficients) {
  using ::testing::HasSubstr;
  SonarModel model;
  model.clear_max_weight = 0.5;  // sums to 0.9
  EXPECT_THAT(model.Problem(), HasSubstr("clear outlier weights"));
  EXPECT_THAT(model.Problem(), HasSubstr("sum to"));
  model = SonarModel{};
  model.clear_uniform_weight = 0.0;  // sums to one, but no uniform part
  model.clear_max_weight = 0.9;
  EXPECT_THAT(model.Problem(), HasSubstr("clear outlier weights"));
  model = SonarModel{};
  model.clear_max_weight = 0.0;
  model.clear_uniform_weight = 0.9;
  EXPECT_THAT(model.Problem(), HasSubstr("positive"));
  model = SonarModel{};
  model.clear_exponential_weight = -0.1;
  model.clear_max_weight = 0.8;
  EXPECT_NE(model.Problem(), "");
  model = SonarModel{};
  model.clear_uniform_weight = std::nan("");
  EXPECT_NE(model.Problem(), "");
  // The exponential's weight may be zero.
  model = SonarModel{};
  model.clear_exponential_weight = 0.0;
  model.clear_max_weight = 0.7;
  EXPECT_EQ(model.Problem(), "");
  model = SonarModel{};
  model.concave_corner_bias = std::nan("");
  EXPECT_THAT(model.Problem(), HasSubstr("finite"));
  model = SonarModel{};
  model.corner_per_m = std::numeric_limits<double>::infinity();
  EXPECT_THAT(model.Problem(), HasSubstr("finite"));
}

}  // namespace
}  // namespace priormap::prf
