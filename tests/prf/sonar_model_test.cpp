// The PRF sonar model: the return probabilities and the outlier weight sum to one, the density
// integrates to one over [0, R) plus the max-reading atom for any set of features, and the
// independent-return model moves the way the paper says.
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include <priormap/prf/sonar_model.hpp>

namespace priormap::prf {
namespace {

using Kind = SonarFeature::Kind;

SonarFeature Face(double distance, double projection, double subtended) {
  return {
      .kind = Kind::kFace, .distance = distance, .projection = projection, .subtended = subtended};
}
SonarFeature Corner(double distance) {
  return {.kind = Kind::kCorner, .distance = distance, .projection = 0.0, .subtended = 0.0};
}

// ∫_0^R p(r | features) dr + P(max | features), by Simpson's rule on a grid fine against the
// narrowest Gaussian.
double TotalProbability(const SonarModel& model, const std::vector<SonarFeature>& features,
                        double max_range) {
  const int n = 100000;  // even
  const double h = max_range / n;
  double sum = 0.0;
  for (int i = 0; i <= n; ++i) {
    const double weight = (i == 0 || i == n) ? 1.0 : (i % 2 == 1 ? 4.0 : 2.0);
    const double r = std::min(i * h, max_range * (1.0 - 1e-15));  // [0, R): just below R
    sum += weight * std::exp(model.LogLikelihood(r, false, features, max_range));
  }
  return sum * h / 3.0 + std::exp(model.LogLikelihood(max_range, true, features, max_range));
}

// Random features in depth order, as a view would give them.
std::vector<SonarFeature> RandomFeatures(std::mt19937_64& random, int count, double max_range) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<SonarFeature> features;
  double distance = 0.05;
  for (int k = 0; k < count; ++k) {
    distance += (max_range - distance) * unit(random) * 0.5;
    features.push_back(unit(random) < 0.5
                           ? Corner(distance)
                           : Face(distance, 0.2 + 1.37 * unit(random), 0.35 * unit(random)));
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

}  // namespace
}  // namespace priormap::prf
