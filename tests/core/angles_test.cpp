#include <priormap/core/angles.hpp>

#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <cmath>
#include <limits>

namespace priormap {
namespace {

TEST(Angles, WrapMapsIntoHalfOpenInterval) {
  EXPECT_DOUBLE_EQ(WrapAngle(0.0), 0.0);
  EXPECT_DOUBLE_EQ(WrapAngle(kPi), kPi);
  EXPECT_DOUBLE_EQ(WrapAngle(-kPi), kPi);  // -pi is outside (-pi, pi]
  EXPECT_NEAR(WrapAngle(3 * kPi), kPi, 1e-12);
  EXPECT_NEAR(WrapAngle(kTwoPi + 0.5), 0.5, 1e-12);
  EXPECT_NEAR(WrapAngle(-kTwoPi - 0.5), -0.5, 1e-12);
  EXPECT_TRUE(std::isnan(WrapAngle(std::numeric_limits<double>::infinity())));
  EXPECT_TRUE(std::isnan(WrapAngle(std::nan(""))));
}

RC_GTEST_PROP(Angles, WrapIsInRangeAndDiffersByWholeTurns, ()) {
  const double a = *rc::gen::map(rc::gen::inRange(-100000000, 100000000), [](int v) { return v * 1e-5; });
  const double w = WrapAngle(a);
  RC_ASSERT(w > -kPi);
  RC_ASSERT(w <= kPi);
  const double turns = (a - w) / kTwoPi;
  RC_ASSERT(std::abs(turns - std::round(turns)) < 1e-9);
}

TEST(Angles, DifferenceTakesTheShortWay) {
  EXPECT_NEAR(AngleDifference(0.1, -0.1), 0.2, 1e-15);
  EXPECT_NEAR(AngleDifference(-kPi + 0.1, kPi - 0.1), 0.2, 1e-12);
  EXPECT_NEAR(AngleDifference(kPi - 0.1, -kPi + 0.1), -0.2, 1e-12);
}

TEST(Angles, UnwrapRemovesJumps) {
  const std::vector<double> wrapped = {3.0, -3.1, -2.9, 3.05, 2.0};
  const std::vector<double> unwrapped = UnwrapAngles(wrapped);
  ASSERT_EQ(unwrapped.size(), wrapped.size());
  EXPECT_DOUBLE_EQ(unwrapped[0], 3.0);
  for (std::size_t i = 1; i < unwrapped.size(); ++i) {
    EXPECT_LE(std::abs(unwrapped[i] - unwrapped[i - 1]), kPi);
    EXPECT_NEAR(WrapAngle(unwrapped[i]), WrapAngle(wrapped[i]), 1e-12);
  }
  EXPECT_NEAR(unwrapped[1], -3.1 + kTwoPi, 1e-12);
}

TEST(Angles, UnwrapSkipsNonFiniteElements) {
  const double nan = std::nan("");
  const std::vector<double> unwrapped = UnwrapAngles(std::vector<double>{3.0, nan, -3.0});
  EXPECT_TRUE(std::isnan(unwrapped[1]));
  EXPECT_NEAR(unwrapped[2], -3.0 + kTwoPi, 1e-12);
}

TEST(Angles, DegreeConversionsAreInverse) {
  EXPECT_DOUBLE_EQ(DegToRad(180.0), kPi);
  EXPECT_DOUBLE_EQ(RadToDeg(kPi / 2), 90.0);
}

}  // namespace
}  // namespace priormap
