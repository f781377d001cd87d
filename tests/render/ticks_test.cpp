#include <cmath>
#include <cstdint>
#include <iomanip>
#include <limits>
#include <optional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <priormap/core/check.hpp>
#include <priormap/render/ticks.hpp>

namespace priormap::render {
namespace {

using ::testing::Pointwise;

// Ticks are computed in floating point, so exact examples are compared to 1e-12.
MATCHER(NearlyEqual, "") {
  return std::abs(std::get<0>(arg) - std::get<1>(arg)) <=
         1e-12 * (1.0 + std::abs(std::get<1>(arg)));
}

TEST(NiceTicks, ZeroToTenInStepsOfTwo) {
  EXPECT_THAT(NiceTicks(0.0, 10.0),
              Pointwise(NearlyEqual(), std::vector<double>{0, 2, 4, 6, 8, 10}));
}

TEST(NiceTicks, ZeroToOneInStepsOfTwoTenths) {
  EXPECT_THAT(NiceTicks(0.0, 1.0),
              Pointwise(NearlyEqual(), std::vector<double>{0.0, 0.2, 0.4, 0.6, 0.8, 1.0}));
}

TEST(NiceTicks, UnalignedEndsGiveTheMultiplesOfTheStepInside) {
  // raw step 9.4 / 6 = 1.57 -> 2; multiples of 2 in [0.3, 9.7].
  EXPECT_THAT(NiceTicks(0.3, 9.7), Pointwise(NearlyEqual(), std::vector<double>{2, 4, 6, 8}));
}

TEST(NiceTicks, NegativeRangesAndFiveAsStep) {
  // raw step 130 / 6 = 21.7 -> 50.
  EXPECT_THAT(NiceTicks(-120.0, 10.0), Pointwise(NearlyEqual(), std::vector<double>{-100, -50, 0}));
  // raw step 0.3 / 6 = 0.05 -> 0.05.
  EXPECT_THAT(
      NiceTicks(-0.3, 0.0),
      Pointwise(NearlyEqual(), std::vector<double>{-0.3, -0.25, -0.2, -0.15, -0.1, -0.05, 0.0}));
}

TEST(NiceTicks, TargetCountChangesTheStep) {
  EXPECT_THAT(NiceTicks(0.0, 10.0, 2), Pointwise(NearlyEqual(), std::vector<double>{0, 5, 10}));
  EXPECT_THAT(NiceTicks(0.0, 10.0, 10),
              Pointwise(NearlyEqual(), std::vector<double>{0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10}));
}

TEST(NiceTicks, ZeroIsNeverNegativeZero) {
  const std::vector<double> ticks = NiceTicks(-0.3, 0.3);
  bool has_zero = false;
  for (double t : ticks) {
    if (t == 0.0) {
      has_zero = true;
      EXPECT_FALSE(std::signbit(t));
    }
  }
  EXPECT_TRUE(has_zero);
}

TEST(NiceTicks, EmptyOrNonFiniteRangeIsAContractError) {
  EXPECT_THROW((void)NiceTicks(1.0, 1.0), ContractError);
  EXPECT_THROW((void)NiceTicks(2.0, 1.0), ContractError);
  EXPECT_THROW((void)NiceTicks(0.0, std::numeric_limits<double>::infinity()), ContractError);
  EXPECT_THROW((void)NiceTicks(std::nan(""), 1.0), ContractError);
}

// A range only a few doubles wide (nearly constant data at a large offset, e.g. timestamps):
// the step is below the spacing of doubles there, and the ticks must still be finite in number.
TEST(NiceTicks, RangeOfAFewUlpsTerminatesWithIncreasingTicks) {
  const double lo = 1e9;
  const double hi = std::nextafter(std::nextafter(lo, 2e9), 2e9);
  const std::vector<double> ticks = NiceTicks(lo, hi);
  EXPECT_LE(ticks.size(), 7u);
  for (std::size_t i = 0; i < ticks.size(); ++i) {
    EXPECT_GE(ticks[i], lo);
    EXPECT_LE(ticks[i], hi);
    if (i > 0) {
      EXPECT_GT(ticks[i], ticks[i - 1]);
    }
  }
}

// hi - lo overflows to infinity; the ticks must not.
TEST(NiceTicks, RangeWiderThanTheLargestDoubleStillHasTicks) {
  const double big = std::numeric_limits<double>::max();
  const std::vector<double> ticks = NiceTicks(-big, big);
  ASSERT_GE(ticks.size(), 2u);
  for (double t : ticks) EXPECT_TRUE(std::isfinite(t));
  EXPECT_THAT(ticks, ::testing::Contains(0.0));
}

// Random ranges [lo, hi] with |lo| up to 1e10 and a width of at least 1e-5 |lo|, so that the
// spacing of doubles near the ticks is below 1e-9 of a step and "evenly spaced" is meaningful.
struct RandomRange {
  double lo, hi;
  int target;
};

// How rapidcheck prints a counterexample.
[[maybe_unused]] void showValue(const RandomRange& r, std::ostream& os) {
  os << std::setprecision(17) << "[" << r.lo << ", " << r.hi << "], target " << r.target;
}

rc::Gen<RandomRange> GenRange() {
  return rc::gen::exec([] {
    const int exponent = *rc::gen::inRange(-4, 11);
    const auto mantissa = *rc::gen::inRange<std::int64_t>(-1'000'000, 1'000'001);
    const double lo = static_cast<double>(mantissa) * 1e-6 * std::pow(10.0, exponent);
    const int width_exponent = *rc::gen::inRange(exponent - 5, exponent + 3);
    const auto width_mantissa = *rc::gen::inRange<std::int64_t>(1000, 10000);
    const double width =
        static_cast<double>(width_mantissa) * 1e-3 * std::pow(10.0, width_exponent);
    const int target = *rc::gen::inRange(5, 13);
    return RandomRange{lo, lo + width, target};
  });
}

// The value m x 10^k (m in 1, 2, 5) that `spacing` (a difference of two ticks, so with some
// rounding error) stands for; nullopt when it is not within 1e-6 of one.
std::optional<double> NiceStepNear(double spacing) {
  if (!(spacing > 0.0)) return std::nullopt;
  const double power = std::pow(10.0, std::floor(std::log10(spacing)));
  // 10 x 10^k: a step of 10^(k+1) that rounding put just below the power of ten.
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (std::abs(spacing - m * power) <= 1e-6 * m * power) return m * power;
  }
  return std::nullopt;
}

RC_GTEST_PROP(NiceTicks, StepIsOneTwoOrFiveTimesAPowerOfTen, ()) {
  const RandomRange r = *GenRange();
  const std::vector<double> ticks = NiceTicks(r.lo, r.hi, r.target);
  RC_ASSERT(ticks.size() >= 2u);
  RC_ASSERT(NiceStepNear(ticks[1] - ticks[0]).has_value());
}

RC_GTEST_PROP(NiceTicks, TicksAreStrictlyIncreasingEvenlySpacedMultiplesOfTheStep, ()) {
  const RandomRange r = *GenRange();
  const std::vector<double> ticks = NiceTicks(r.lo, r.hi, r.target);
  RC_ASSERT(ticks.size() >= 2u);
  const std::optional<double> step = NiceStepNear(ticks[1] - ticks[0]);
  RC_ASSERT(step.has_value());
  for (std::size_t i = 1; i < ticks.size(); ++i) {
    RC_ASSERT(ticks[i] > ticks[i - 1]);
    RC_ASSERT(std::abs((ticks[i] - ticks[i - 1]) - *step) <= 1e-6 * *step);
  }
  // Multiples of the step, so 0 is a tick whenever it is in the range.
  for (double t : ticks) RC_ASSERT(std::abs(t / *step - std::round(t / *step)) <= 1e-6);
}

RC_GTEST_PROP(NiceTicks, TicksLieInTheRangeAndCoverIt, ()) {
  const RandomRange r = *GenRange();
  const std::vector<double> ticks = NiceTicks(r.lo, r.hi, r.target);
  RC_ASSERT(ticks.size() >= 2u);
  const std::optional<double> step = NiceStepNear(ticks[1] - ticks[0]);
  RC_ASSERT(step.has_value());
  // The ends are snapped within 1e-9 of a step, so that a range whose ends are off by rounding
  // (0.30000000000000004) keeps its end tick; allow exactly that much.
  const double slack = 1e-9 * *step;
  RC_ASSERT(ticks.front() >= r.lo - slack);
  RC_ASSERT(ticks.back() <= r.hi + slack);
  // No tick is missing at either end: the next multiple of the step would be outside.
  RC_ASSERT(ticks.front() - *step < r.lo + slack);
  RC_ASSERT(ticks.back() + *step > r.hi - slack);
}

// The step is the smallest of 1, 2, 5 x 10^k that is at least raw = (hi - lo) / target, so
// raw <= step < 2.5 raw (the worst case is raw just above 2 x 10^k, rounded up to 5 x 10^k).
// step >= raw gives at most target + 1 ticks; step < 2.5 raw means the range holds more than
// target / 2.5 steps, so at least floor(target / 2.5) ticks. With target in [5, 12] that is >= 2.
RC_GTEST_PROP(NiceTicks, CountIsBetweenTwoFifthsOfTargetAndTargetPlusOne, ()) {
  const RandomRange r = *GenRange();
  const std::vector<double> ticks = NiceTicks(r.lo, r.hi, r.target);
  const auto lower = static_cast<std::size_t>((2 * r.target) / 5);
  RC_ASSERT(lower >= 2u);
  RC_ASSERT(ticks.size() >= lower);
  RC_ASSERT(ticks.size() <= static_cast<std::size_t>(r.target) + 1);
}

TEST(TickLabel, DecimalsFollowTheStep) {
  EXPECT_EQ(TickLabel(4.0, 2.0), "4");
  EXPECT_EQ(TickLabel(1500.0, 500.0), "1500");
  EXPECT_EQ(TickLabel(0.4, 0.2), "0.4");
  EXPECT_EQ(TickLabel(1.0, 0.5), "1.0");
  EXPECT_EQ(TickLabel(0.15, 0.05), "0.15");
  EXPECT_EQ(TickLabel(-0.002, 0.001), "-0.002");
  EXPECT_EQ(TickLabel(3.0, 1.0), "3");
}

TEST(TickLabel, RoundingNoiseInValueAndStepDoesNotAddDecimals) {
  // 0.1 + 0.2 and a step of 0.1 computed as a difference.
  EXPECT_EQ(TickLabel(0.1 + 0.2, 0.3 - 0.2), "0.3");
  EXPECT_EQ(TickLabel(0.7000000000000001, 0.09999999999999998), "0.7");
}

TEST(TickLabel, LabelsOfNiceTicksAreDistinct) {
  for (const auto& [lo, hi] : std::vector<std::pair<double, double>>{
           {0.0, 1.0}, {-0.3, 0.0}, {0.001, 0.0013}, {1e9, 1e9 + 10}, {-250, 7}}) {
    const std::vector<double> ticks = NiceTicks(lo, hi);
    ASSERT_GE(ticks.size(), 2u);
    const double step = ticks[1] - ticks[0];
    for (std::size_t i = 1; i < ticks.size(); ++i) {
      EXPECT_NE(TickLabel(ticks[i], step), TickLabel(ticks[i - 1], step)) << lo << ".." << hi;
    }
  }
}

// A tick label longer than 8 characters runs off a plot's margin: a range of 1e13 (a diverged
// filter's NEES) or of 1e-12 is labelled in scientific notation, each label still its own.
TEST(TickLabel, LabelsOfHugeAndTinyRangesAreShortAndDistinct) {
  for (const auto& [lo, hi] : std::vector<std::pair<double, double>>{
           {0.0, 1e13}, {0.0, 1e-12}, {-1e18, 1e18}, {1e-300, 1e-299}, {-3e-9, 7e-9}}) {
    const std::vector<double> ticks = NiceTicks(lo, hi);
    ASSERT_GE(ticks.size(), 2u);
    const double step = ticks[1] - ticks[0];
    for (std::size_t i = 0; i < ticks.size(); ++i) {
      const std::string label = TickLabel(ticks[i], step);
      EXPECT_LE(label.size(), 8u) << label;
      EXPECT_NEAR(std::stod(label), ticks[i], 1e-6 * step) << label;
      if (i > 0) {
        EXPECT_NE(label, TickLabel(ticks[i - 1], step)) << lo << ".." << hi;
      }
    }
  }
  EXPECT_EQ(TickLabel(5e12, 1e12), "5e+12");
  EXPECT_EQ(TickLabel(1.5e12, 5e11), "1.5e+12");
  EXPECT_EQ(TickLabel(2e-13, 2e-13), "2e-13");
  EXPECT_EQ(TickLabel(0.0, 2e-13), "0");
  // Where scientific notation is no shorter, the fixed label stays.
  EXPECT_EQ(TickLabel(1000000000.5, 0.5), "1000000000.5");
}

TEST(SpacedNiceTicks, ThinAxesGetFewerTicksNoCloserThanAsked) {
  // 0.5 m over 4 pixels: eight ticks would be a smear of labels.
  const std::vector<double> thin = SpacedNiceTicks(-0.25, 0.25, 8, 4.0, 14.0);
  ASSERT_FALSE(thin.empty());
  EXPECT_EQ(thin.size(), 1u);
  for (const double length : {30.0, 60.0, 120.0, 250.0}) {
    const std::vector<double> ticks = SpacedNiceTicks(0.0, 10.0, 8, length, 14.0);
    ASSERT_FALSE(ticks.empty()) << length;
    if (ticks.size() > 1) {
      EXPECT_GE((ticks[1] - ticks[0]) / 10.0 * length, 14.0) << length;
    }
  }
  // An axis with room for them keeps NiceTicks' ticks.
  EXPECT_EQ(SpacedNiceTicks(0.0, 10.0, 8, 700.0, 14.0), NiceTicks(0.0, 10.0, 8));
  const double big = std::numeric_limits<double>::max();
  EXPECT_GE(SpacedNiceTicks(-big, big, 8, 700.0, 14.0).size(), 2u);
}

}  // namespace
}  // namespace priormap::render
