// BatchMeans against closed forms: a hand-computed record, iid normal draws (standard error
// 1/√n) and a stationary AR(1) chain (standard error √((1+φ)/((1−φ) n)) for unit variance).
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include <priormap/core/rng.hpp>
#include <priormap/prf/batch_means.hpp>

namespace priormap::prf {
namespace {

constexpr std::size_t kDraws = 100'000;
constexpr std::size_t kBatches = 50;

// With B batches whose means are (nearly) independent and normal, the batch-means variance is
// a chi-square with B - 1 degrees of freedom over B - 1: the standard error it gives has a
// relative standard deviation of about 1/√(2(B - 1)) = 0.10 for B = 50, so 40 % is 4 of them.
constexpr double kRelativeTolerance = 0.4;

TEST(BatchMeans, MatchesAHandComputationAndLeavesTheRemainderOutOfTheErrorOnly) {
  // Two batches of four: {1..4} (mean 2.5) and {5..8} (mean 6.5); the 9 is left over.
  // Variance of the mean: ((2.5 - 4.5)^2 + (6.5 - 4.5)^2) / (B - 1) / B = 8 / 1 / 2 = 4.
  const std::vector<double> record = {1, 2, 3, 4, 5, 6, 7, 8, 9};
  const Estimate estimate = BatchMeans(record, 2);
  EXPECT_DOUBLE_EQ(estimate.mean, 5.0);  // 45 / 9: the mean keeps the 9
  EXPECT_DOUBLE_EQ(estimate.standard_error, 2.0);
}

TEST(BatchMeans, StandardErrorOfIidNormalDrawsIsOneOverRootN) {
  Rng rng(20260101);
  std::vector<double> record(kDraws);
  for (double& x : record) x = rng.Normal();
  const Estimate estimate = BatchMeans(record, kBatches);
  const double expected = 1.0 / std::sqrt(static_cast<double>(kDraws));
  EXPECT_NEAR(estimate.standard_error / expected, 1.0, kRelativeTolerance);
  EXPECT_NEAR(estimate.mean, 0.0, 4.0 * expected);
}

// x_t = φ x_{t-1} + √(1 - φ²) ε_t started at x_0 ~ N(0, 1) is stationary with unit variance and
// autocorrelation φ^k; the variance of its mean is (1 + φ)/((1 - φ) n) to O(1/n²). The batches
// (2,000 draws) are 100 times the integrated autocorrelation time (1 + φ)/(1 - φ) = 19, so their
// means are nearly independent and the batch-means bias, about 2φ/((1 - φ)² L) / 19 = 0.5 %,
// is far below the tolerance.
TEST(BatchMeans, StandardErrorOfAnAr1ChainIncludesItsAutocorrelation) {
  const double phi = 0.9;
  Rng rng(20260102);
  std::vector<double> record(kDraws);
  const double innovation = std::sqrt(1.0 - phi * phi);
  double x = rng.Normal();
  for (double& value : record) {
    value = x;
    x = phi * x + innovation * rng.Normal();
  }
  const Estimate estimate = BatchMeans(record, kBatches);
  const double expected = std::sqrt((1.0 + phi) / ((1.0 - phi) * static_cast<double>(kDraws)));
  EXPECT_NEAR(estimate.standard_error / expected, 1.0, kRelativeTolerance);
  // An iid formula would be 4.4 times too small: the test tells the two apart.
  EXPECT_GT(estimate.standard_error, 2.0 / std::sqrt(static_cast<double>(kDraws)));
  EXPECT_NEAR(estimate.mean, 0.0, 4.0 * expected);
}

}  // namespace
}  // namespace priormap::prf
