#include <priormap/core/rng.hpp>

#include <gtest/gtest.h>

#include <cmath>

namespace priormap {
namespace {

TEST(Rng, SameSeedSameSequence) {
  Rng a(42), b(42), c(43);
  bool differs = false;
  for (int i = 0; i < 100; ++i) {
    const double x = a.Normal();
    EXPECT_EQ(x, b.Normal());
    differs |= x != c.Normal();
  }
  EXPECT_TRUE(differs);
}

TEST(Rng, StreamsAreIndependentOfEachOther) {
  Rng s0 = Rng::ForStream(1, 0), s1 = Rng::ForStream(1, 1), s0_again = Rng::ForStream(1, 0);
  EXPECT_EQ(s0.Uniform(), s0_again.Uniform());
  EXPECT_NE(Rng::ForStream(1, 0).Uniform(), s1.Uniform());
  EXPECT_NE(Rng::ForStream(1, 0).Uniform(), Rng::ForStream(2, 0).Uniform());
}

// Moments against the closed forms, with 4-standard-error tolerances.
TEST(Rng, UniformHasTheRightMeanAndVariance) {
  Rng rng(7);
  constexpr int kN = 200000;
  double sum = 0.0, sum_sq = 0.0;
  for (int i = 0; i < kN; ++i) {
    const double u = rng.Uniform();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    sum += u;
    sum_sq += u * u;
  }
  const double mean = sum / kN, variance = sum_sq / kN - mean * mean;
  EXPECT_NEAR(mean, 0.5, 4 * std::sqrt(1.0 / 12 / kN));
  EXPECT_NEAR(variance, 1.0 / 12, 4 * std::sqrt(1.0 / 180 / kN));  // (mu_4 - sigma^4) / n = (1/80 - 1/144) / n
}

TEST(Rng, NormalHasTheRightMomentsAndTails) {
  Rng rng(9);
  constexpr int kN = 200000;
  double sum = 0.0, sum_sq = 0.0, sum_4 = 0.0;
  int beyond_2 = 0;
  for (int i = 0; i < kN; ++i) {
    const double z = rng.Normal();
    sum += z;
    sum_sq += z * z;
    sum_4 += z * z * z * z;
    beyond_2 += std::abs(z) > 2.0;
  }
  EXPECT_NEAR(sum / kN, 0.0, 4 * std::sqrt(1.0 / kN));
  EXPECT_NEAR(sum_sq / kN, 1.0, 4 * std::sqrt(2.0 / kN));
  EXPECT_NEAR(sum_4 / kN, 3.0, 4 * std::sqrt(96.0 / kN));  // Var(z^4) = 105 - 9
  const double p2 = std::erfc(2.0 / std::sqrt(2.0));
  EXPECT_NEAR(static_cast<double>(beyond_2) / kN, p2, 4 * std::sqrt(p2 * (1 - p2) / kN));
}

TEST(Rng, UniformIndexCoversTheRangeEvenly) {
  Rng rng(3);
  constexpr int kN = 70000;
  int counts[7] = {};
  for (int i = 0; i < kN; ++i) ++counts[rng.UniformIndex(7)];
  for (int c : counts) EXPECT_NEAR(c, kN / 7.0, 4 * std::sqrt(kN * (1.0 / 7) * (6.0 / 7)));
}

}  // namespace
}  // namespace priormap
