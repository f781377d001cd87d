#include <cmath>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include <priormap/core/angles.hpp>
#include <priormap/priorlets/corner_geometry.hpp>

namespace priormap::priorlets {
namespace {

constexpr double kPi = std::numbers::pi;

// Readings of the room corner (2, 2) seen from the origin: the wall x = 2 (normal towards the
// sensor: pi) below the corner's bearing of 45 deg, y = 2 (normal -pi/2) above it. Beams every
// half degree from 40 to 50 deg, none exactly at 45; `border` says which region the fitted
// points were given to: points up to `border` lie on the first wall's line (extended past the
// corner when the border is late), the others on the second's.
struct CornerScan {
  std::vector<double> phi, rho, alpha;
};

CornerScan SquareCorner(std::size_t border) {
  CornerScan s;
  for (int k = 0; k <= 20; ++k) {
    const double phi = (40.25 + 0.5 * k) * kPi / 180.0;
    const bool first_wall = static_cast<std::size_t>(k) <= border;
    s.phi.push_back(phi);
    s.rho.push_back(first_wall ? 2.0 / std::cos(phi) : 2.0 / std::sin(phi));
    s.alpha.push_back(first_wall ? kPi : -kPi / 2);
  }
  return s;
}

TEST(CheckCorner, FindsTheCornerBetweenTheBordersBeams) {
  const CornerScan s = SquareCorner(9);  // 44.75 | 45.25 deg
  const CornerCheck check = CheckCorner(s.phi, s.rho, s.alpha, 9);
  EXPECT_TRUE(check.turned);
  EXPECT_TRUE(check.corner);
  EXPECT_NEAR(check.bearing, kPi / 4, 1e-12);
  EXPECT_EQ(check.shift, 0);
}

TEST(CheckCorner, SaysHowFarABorderPlacedLateOrEarlyMustMove) {
  // Two points of the second wall placed on the first wall's line, past the corner: they go
  // to the region after the border.
  const CornerScan late = SquareCorner(11);
  const CornerCheck back = CheckCorner(late.phi, late.rho, late.alpha, 11);
  EXPECT_NEAR(back.bearing, kPi / 4, 1e-12);
  EXPECT_EQ(back.shift, -2);
  // Three points of the first wall placed on the second wall's line: they go before it.
  const CornerScan early = SquareCorner(6);
  const CornerCheck forward = CheckCorner(early.phi, early.rho, early.alpha, 6);
  EXPECT_NEAR(forward.bearing, kPi / 4, 1e-12);
  EXPECT_EQ(forward.shift, 3);
}

TEST(CheckCorner, LinesThatHardlyTurnDecideNothing) {
  CornerScan s = SquareCorner(9);
  // After the border, the line through the corner (2, 2) turned by 5.7 deg.
  const double nx = std::cos(kPi + 0.1), ny = std::sin(kPi + 0.1), d = 2.0 * nx + 2.0 * ny;
  for (std::size_t j = 10; j < s.alpha.size(); ++j) {
    s.rho[j] = d / (nx * std::cos(s.phi[j]) + ny * std::sin(s.phi[j]));
    s.alpha[j] = kPi + 0.1;
  }
  const CornerCheck check = CheckCorner(s.phi, s.rho, s.alpha, 9);
  EXPECT_FALSE(check.turned);
  EXPECT_FALSE(check.corner);
  EXPECT_FALSE(check.step);  // the points are within millimetres of each other's line
  EXPECT_EQ(check.shift, 0);
}

TEST(CheckCorner, ParallelLinesApartAreAStep) {
  // A box face x = 1.5 in front of the wall x = 2 behind it, turned by 0.5 deg (estimated).
  CornerScan s = SquareCorner(20);
  for (std::size_t j = 10; j < s.alpha.size(); ++j) {
    s.rho[j] = 1.5 / std::cos(s.phi[j]);
    s.alpha[j] = kPi + 0.01;
  }
  const CornerCheck check = CheckCorner(s.phi, s.rho, s.alpha, 9);
  EXPECT_FALSE(check.turned);
  EXPECT_TRUE(check.step);
}

TEST(CheckCorner, LinesMeetingBehindTheSensorAreNoCorner) {
  // After the border, the line 4x + y = 5 (through (1, 1) and (2, -3)), 14 deg off the wall
  // x = 2: the two lines meet at (2, -3), behind the sensor as seen along the border's rays.
  CornerScan s = SquareCorner(20);
  for (std::size_t j = 10; j < s.alpha.size(); ++j) {
    s.rho[j] = 5.0 / (4.0 * std::cos(s.phi[j]) + std::sin(s.phi[j]));
    s.alpha[j] = std::atan2(-1.0, -4.0);
  }
  const CornerCheck check = CheckCorner(s.phi, s.rho, s.alpha, 9);
  EXPECT_TRUE(check.turned);
  EXPECT_FALSE(check.corner);
}

TEST(CheckCorner, AnOcclusionPutsTheLinesCrossingFarFromTheBorder) {
  // A box face x = 1 (bearings below 45 deg) in front of the wall y = 3: the lines meet at
  // (1, 3), bearing 71.6 deg, far beyond the points after the border.
  CornerScan s;
  for (int k = 0; k <= 20; ++k) {
    const double phi = (40.25 + 0.5 * k) * kPi / 180.0;
    s.phi.push_back(phi);
    const bool box = k <= 9;
    s.rho.push_back(box ? 1.0 / std::cos(phi) : 3.0 / std::sin(phi));
    s.alpha.push_back(box ? kPi : -kPi / 2);
  }
  const CornerCheck check = CheckCorner(s.phi, s.rho, s.alpha, 9);
  EXPECT_TRUE(check.corner);
  EXPECT_NEAR(check.bearing, std::atan2(3.0, 1.0), 1e-12);
  EXPECT_EQ(check.shift, 11);  // every point after the border: up to the end of the spans
}

}  // namespace
}  // namespace priormap::priorlets
