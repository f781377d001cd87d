// The orientation preference (Paskin & Thrun, Sec. 4): κ Σ|e| sin²(2(θ_e − θ₀)) from the sums
// Σ|e| cos 4θ and Σ|e| sin 4θ that colorings keep, against the closed form edge by edge; and
// those sums kept right by every move of a chain that samples with the preference on.
#include <cmath>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include <priormap/prf/arak.hpp>
#include <priormap/prf/sampler.hpp>

namespace priormap::prf {
namespace {

constexpr double kPi = std::numbers::pi;

double DegToRad(double degrees) {
  return degrees * kPi / 180.0;
}

ColoringStats OneEdge(double length, double theta) {
  ColoringStats stats;
  stats.AddEdge(length * UnitVector(theta), 1.0);
  return stats;
}

// κ |e| sin²(2(θ − θ₀)) for one edge, straight from the definition.
double ClosedForm(double weight, double length, double theta, double angle) {
  const double s = std::sin(2.0 * (theta - angle));
  return weight * length * s * s;
}

TEST(OrientationPotential, OfSingleEdgesIsTheClosedForm) {
  const OrientationPrior axes{.weight = 2.0, .angle = 0.0};
  // Along and across the preferred direction nothing; at 45° the full κ|e|.
  EXPECT_NEAR(OrientationPotential(OneEdge(1.5, 0.0), axes), 0.0, 1e-12);
  EXPECT_NEAR(OrientationPotential(OneEdge(1.5, DegToRad(90)), axes), 0.0, 1e-12);
  EXPECT_NEAR(OrientationPotential(OneEdge(1.5, DegToRad(45)), axes), 3.0, 1e-12);
  EXPECT_NEAR(OrientationPotential(OneEdge(1.5, DegToRad(135)), axes), 3.0, 1e-12);
  EXPECT_NEAR(OrientationPotential(OneEdge(1.5, DegToRad(22.5)), axes), 1.5, 1e-12);
  // 30° against 15°: sin²(30°) = 1/4.
  const OrientationPrior tilted{.weight = 2.0, .angle = DegToRad(15)};
  EXPECT_NEAR(OrientationPotential(OneEdge(1.5, DegToRad(30)), tilted), 0.75, 1e-12);
  // An edge's direction is its own reverse, and θ₀ is defined modulo 90°.
  EXPECT_NEAR(OrientationPotential(OneEdge(1.5, DegToRad(210)), tilted), 0.75, 1e-12);
  const OrientationPrior quarter_turn{.weight = 2.0, .angle = DegToRad(105)};
  EXPECT_NEAR(OrientationPotential(OneEdge(1.5, DegToRad(30)), quarter_turn), 0.75, 1e-12);
  for (double degrees : {-170.0, -33.0, 7.0, 61.0, 100.0, 151.0}) {
    const double theta = DegToRad(degrees);
    for (double angle : {-0.4, 0.0, 0.3, 1.2}) {
      const OrientationPrior prior{.weight = 0.7, .angle = angle};
      EXPECT_NEAR(OrientationPotential(OneEdge(2.3, theta), prior),
                  ClosedForm(0.7, 2.3, theta, angle), 1e-12)
          << degrees << "° against " << angle << " rad";
    }
  }
}

TEST(OrientationPotential, AddsOverEdgesAndIsZeroWithoutWeight) {
  ColoringStats stats;
  const std::vector<std::pair<double, double>> edges = {{0.4, 0.1}, {1.1, 2.0}, {0.25, -0.7}};
  double expected = 0.0;
  for (const auto& [length, theta] : edges) {
    stats.AddEdge(length * UnitVector(theta), 1.0);
    expected += ClosedForm(1.3, length, theta, 0.2);
  }
  EXPECT_NEAR(OrientationPotential(stats, {.weight = 1.3, .angle = 0.2}), expected, 1e-12);
  EXPECT_GT(expected, 0.1);
  EXPECT_EQ(OrientationPotential(stats, {.weight = 0.0, .angle = 0.2}), 0.0);
  EXPECT_EQ(OrientationPotential(stats, OrientationPrior{}), 0.0);
}

TEST(ColoringStats, AddEdgeKeepsTheFourthHarmonicsAndRemovingUndoesIt) {
  const Vec2 d(0.3, -1.7);
  ColoringStats stats = OneEdge(d.norm(), std::atan2(d.y(), d.x()));
  const double theta = std::atan2(d.y(), d.x());
  EXPECT_NEAR(stats.sum_cos4, d.norm() * std::cos(4.0 * theta), 1e-12);
  EXPECT_NEAR(stats.sum_sin4, d.norm() * std::sin(4.0 * theta), 1e-12);
  EXPECT_NEAR(stats.total_length, d.norm(), 1e-15);
  EXPECT_NEAR(stats.sum_log_length, std::log(d.norm()), 1e-15);
  // The edge run the other way has the same direction modulo 180°.
  ColoringStats reversed;
  reversed.AddEdge(-d, 1.0);
  EXPECT_NEAR(reversed.sum_cos4, stats.sum_cos4, 1e-12);
  EXPECT_NEAR(reversed.sum_sin4, stats.sum_sin4, 1e-12);
  stats.AddEdge(d, -1.0);
  EXPECT_EQ(stats.edges, 0);
  EXPECT_NEAR(stats.total_length, 0.0, 1e-12);
  EXPECT_NEAR(stats.sum_log_length, 0.0, 1e-12);
  EXPECT_NEAR(stats.sum_cos4, 0.0, 1e-12);
  EXPECT_NEAR(stats.sum_sin4, 0.0, 1e-12);
}

TEST(OrientationPotential, AChainWithThePreferenceKeepsItsSumsRight) {
  // check_invariants recomputes the coloring's sums (the fourth harmonics included) after
  // every accepted move and throws on a difference.
  SamplerOptions options;
  options.p = 3.0;
  options.birth_scale = 0.3;
  options.step_scales = {0.01, 0.05, 0.2};
  options.orientation = {.weight = 2.0, .angle = 0.3};
  options.check_invariants = true;
  PrfSampler sampler(Coloring(Window{Vec2::Zero(), Vec2::Ones()}, 0.125), options, 41);
  sampler.Run(4000);
  const Coloring& coloring = sampler.coloring();
  EXPECT_FALSE(coloring.FindInvariantViolation(1e-9));
  ASSERT_GT(coloring.stats().edges, 10);
  EXPECT_GT(Total(sampler.counters()).accepted, 500u);
  // The potential of the chain's state, edge by edge from the definition.
  double expected = 0.0;
  for (EdgeId e : coloring.edge_ids()) {
    const Segment s = coloring.EdgeSegment(e);
    const Vec2 d = s.b - s.a;
    expected += ClosedForm(2.0, d.norm(), std::atan2(d.y(), d.x()), 0.3);
  }
  EXPECT_NEAR(OrientationPotential(coloring.stats(), options.orientation), expected, 1e-9);
  EXPECT_NEAR(sampler.LogPrior(), coloring.LogArakDensity(options.p) - expected, 1e-9);
}

}  // namespace
}  // namespace priormap::prf
