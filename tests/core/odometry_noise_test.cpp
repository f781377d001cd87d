// SimulateLog's odometry noise against its closed form. LogSimulationOptions documents the error
// of each increment: a standard deviation per metre travelled for the translation, and per radian
// turned plus per metre travelled for the rotation. SimulateLog adds to the true increment
// (x, y, theta), in the frame of the pose at its start,
//   e_x, e_y ~ N(0, sigma_t^2),  sigma_t = odom_sigma_per_meter * d,
//   e_theta ~ N(0, sigma_r^2),   sigma_r = odom_sigma_rad_per_rad * |dtheta| +
//                                          odom_sigma_rad_per_meter * d,
// independent of each other and of the other increments (d = |translation| of the true
// increment), and integrates the noisy increments. So the errors of the logged increments
// (Between consecutive odometry poses, minus Between consecutive true poses) divided by their
// sigma are i.i.d. standard normal: mean 0, variance 1, fourth moment 3, no correlation between
// components or consecutive increments; and a turn in place (d = 0) has no translation error.
//
// Every estimate is compared with its closed form within 5 standard errors of its sampling
// distribution (the tests make ~40 comparisons; 5 rather than 4 keeps the family-wise false alarm
// rate of a fresh seed below 1e-4). The seed is fixed, so the result is deterministic.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/scene.hpp>
#include <priormap/core/simulate.hpp>

namespace priormap {
namespace {

// Not the defaults, so that each of the three coefficients must be read from the options.
LogSimulationOptions TestOptions() {
  LogSimulationOptions options;
  options.odom_sigma_per_meter = 0.05;
  options.odom_sigma_rad_per_rad = 0.03;
  options.odom_sigma_rad_per_meter = 0.02;
  return options;
}

enum class StepKind { kStraight, kTurnInPlace, kArc };
constexpr int kStepsPerKind = 12000;

StepKind KindOf(std::size_t step) {
  return static_cast<StepKind>(step % 3);
}

// 3 * kStepsPerKind increments, cycling through a straight step (d in [0.1, 0.8] m, sideways up to
// 0.5 rad off the heading so both x and y move, no turn), a turn in place (|dtheta| in
// [0.05, 0.8] rad) and an arc (both), so that each term of sigma_r is tested alone and in the sum.
std::vector<TimedPose> RandomTrajectory() {
  std::mt19937_64 rng(20261121);
  std::uniform_real_distribution<double> distance(0.1, 0.8), direction(-0.5, 0.5), turn(0.05, 0.8),
      sign(-1.0, 1.0);
  std::vector<TimedPose> trajectory{{0.0, Se2(1.0, 1.0, 0.3)}};
  for (std::size_t k = 0; k < 3 * kStepsPerKind; ++k) {
    const StepKind kind = KindOf(k);
    double d = distance(rng), phi = direction(rng);
    double dtheta = std::copysign(turn(rng), sign(rng));
    if (kind == StepKind::kStraight) dtheta = 0.0;
    if (kind == StepKind::kTurnInPlace) d = 0.0;
    const Se2 increment(d * std::cos(phi), d * std::sin(phi), dtheta);
    trajectory.push_back(
        {0.1 * static_cast<double>(k + 1), trajectory.back().pose.Compose(increment)});
  }
  return trajectory;
}

struct StandardisedErrors {
  // Per step (index = step of RandomTrajectory), NaN where sigma is 0.
  std::vector<double> x, y, theta;
  double largest_turn_in_place_translation_error = 0.0;
};

StandardisedErrors Simulate(std::uint64_t seed) {
  const Scene scene = *BuiltinScene("l-room");
  RangeSensor sensor = *RangeSensor::Preset("lms200");
  sensor.num_beams = 1;  // the scans are not under test
  const std::vector<TimedPose> trajectory = RandomTrajectory();
  const LogSimulationOptions options = TestOptions();
  const Log log = SimulateLog(scene, sensor, trajectory, seed, options);
  EXPECT_EQ(log.odometry.size(), trajectory.size());

  StandardisedErrors errors;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (std::size_t k = 1; k < trajectory.size(); ++k) {
    const Se2 truth = trajectory[k - 1].pose.Between(trajectory[k].pose);
    const Se2 measured = log.odometry[k - 1].pose.Between(log.odometry[k].pose);
    const double ex = measured.x() - truth.x(), ey = measured.y() - truth.y();
    const double etheta = AngleDifference(measured.theta(), truth.theta());
    const double d = truth.translation().norm();
    const double sigma_t = options.odom_sigma_per_meter * d;
    const double sigma_r = options.odom_sigma_rad_per_rad * std::abs(truth.theta()) +
                           options.odom_sigma_rad_per_meter * d;
    if (KindOf(k - 1) == StepKind::kTurnInPlace) {
      errors.largest_turn_in_place_translation_error =
          std::max({errors.largest_turn_in_place_translation_error, std::abs(ex), std::abs(ey)});
    }
    errors.x.push_back(sigma_t > 0.0 ? ex / sigma_t : nan);
    errors.y.push_back(sigma_t > 0.0 ? ey / sigma_t : nan);
    errors.theta.push_back(sigma_r > 0.0 ? etheta / sigma_r : nan);
  }
  return errors;
}

const StandardisedErrors& Errors() {
  static const StandardisedErrors errors = Simulate(11);
  return errors;
}

// The mean of f(step) over the steps of `kind` (all steps: nullopt), skipping NaN values; with
// their count.
template <typename F>
std::pair<double, double> MeanOver(std::optional<StepKind> kind, F f) {
  double sum = 0.0, n = 0.0;
  for (std::size_t k = 0; k < Errors().x.size(); ++k) {
    if (kind && KindOf(k) != *kind) continue;
    const double value = f(k);
    if (std::isnan(value)) continue;
    sum += value;
    n += 1.0;
  }
  return {sum / n, n};
}

struct Component {
  const char* name;
  const std::vector<double>* z;
};

std::vector<Component> Components() {
  return {{"x", &Errors().x}, {"y", &Errors().y}, {"theta", &Errors().theta}};
}

std::string KindName(std::optional<StepKind> kind) {
  if (!kind) return "all steps";
  switch (*kind) {
    case StepKind::kStraight:
      return "straight";
    case StepKind::kTurnInPlace:
      return "turn in place";
    case StepKind::kArc:
      return "arc";
  }
  return "?";
}

const std::vector<std::optional<StepKind>> kKinds = {std::nullopt, StepKind::kStraight,
                                                     StepKind::kTurnInPlace, StepKind::kArc};

// Mean 0 (standard error 1 / sqrt(n)); E z^2 = 1 (the mean known: var(z^2) = 2); E z^4 = 3
// (var(z^4) = E z^8 - 9 = 105 - 9 = 96): per component and per kind of step, so that a wrong
// coefficient cannot hide behind a right one.
TEST(SimulateLogOdometry, IncrementErrorsAreStandardNormalAfterScalingByTheirSigma) {
  for (const Component& c : Components()) {
    for (const std::optional<StepKind>& kind : kKinds) {
      SCOPED_TRACE(std::string(c.name) + ", " + KindName(kind));
      const auto [mean, n] = MeanOver(kind, [&](std::size_t k) { return (*c.z)[k]; });
      if (c.name != std::string("theta") && kind == StepKind::kTurnInPlace) {
        EXPECT_EQ(n, 0.0);  // sigma_t = 0: checked below
        continue;
      }
      ASSERT_GE(n, kStepsPerKind - 1.0);
      const auto [second, n2] =
          MeanOver(kind, [&](std::size_t k) { return std::pow((*c.z)[k], 2); });
      const auto [fourth, n4] =
          MeanOver(kind, [&](std::size_t k) { return std::pow((*c.z)[k], 4); });
      EXPECT_NEAR(mean, 0.0, 5.0 / std::sqrt(n));
      EXPECT_NEAR(second, 1.0, 5.0 * std::sqrt(2.0 / n));
      EXPECT_NEAR(fourth, 3.0, 5.0 * std::sqrt(96.0 / n));
    }
  }
}

// A turn in place travels no distance, so its translation has no error (up to rounding in the
// integration of the odometry poses).
TEST(SimulateLogOdometry, ATurnInPlaceHasNoTranslationError) {
  EXPECT_LT(Errors().largest_turn_in_place_translation_error, 1e-9);
}

// The three components are independent: E[z_a z_b] = 0 with var(z_a z_b) = 1.
TEST(SimulateLogOdometry, IncrementErrorComponentsAreUncorrelated) {
  const std::vector<Component> c = Components();
  for (std::size_t a = 0; a < c.size(); ++a) {
    for (std::size_t b = a + 1; b < c.size(); ++b) {
      for (const std::optional<StepKind>& kind : kKinds) {
        SCOPED_TRACE(std::string(c[a].name) + " and " + c[b].name + ", " + KindName(kind));
        const auto [product, n] =
            MeanOver(kind, [&](std::size_t k) { return (*c[a].z)[k] * (*c[b].z)[k]; });
        if (n == 0.0) continue;  // x or y on turns in place
        ASSERT_GE(n, kStepsPerKind - 1.0);
        EXPECT_NEAR(product, 0.0, 5.0 / std::sqrt(n));
      }
    }
  }
}

// Increments are independent of each other: consecutive errors (the same component, or any pair)
// have E[z_k z'_{k+1}] = 0. Integrating the increments into poses must not correlate them (a log
// whose increments were taken against the wrong pose would show -1/2 here).
TEST(SimulateLogOdometry, ConsecutiveIncrementErrorsAreUncorrelated) {
  for (const Component& a : Components()) {
    for (const Component& b : Components()) {
      SCOPED_TRACE(std::string(a.name) + "_k and " + b.name + "_k+1");
      double sum = 0.0, n = 0.0;
      for (std::size_t k = 0; k + 1 < a.z->size(); ++k) {
        const double product = (*a.z)[k] * (*b.z)[k + 1];
        if (std::isnan(product)) continue;
        sum += product;
        n += 1.0;
      }
      ASSERT_GE(n, kStepsPerKind - 1.0);
      EXPECT_NEAR(sum / n, 0.0, 5.0 / std::sqrt(n));
    }
  }
}

}  // namespace
}  // namespace priormap
