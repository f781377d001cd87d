// Far windows' residuals (src/priorlets/inner_problem.hpp, kUnitRange): constraints that are
// lengths are measured relative to their windows' ranges beyond kUnitRange, so that a far scene
// is solved as the same scene kUnitRange away would be. The rescaling must not hide a real
// violation: a bump relative to the ranges is the same violation at every scale from
// kUnitRange on, and a corner is still no straight wall.
#include <cmath>
#include <cstddef>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <gtest/gtest.h>

#include <priormap/core/angles.hpp>
#include <priormap/dsl/prior_library.hpp>
#include <priormap/priorlets/engine.hpp>

#include "inner_problem.hpp"
#include "inner_solver.hpp"

namespace priormap::priorlets {
namespace {

constexpr double kPi = std::numbers::pi;

// Readings of a corner scaled by `scale`: the sensor at the origin, a wall x = 3 (beams from
// -0.5 rad up to the corner at (3, 2)) and a wall y = 2 after it, 40 beams in all over
// [-0.5, 1.6] rad, sigma 0.01 per unit of scale, off the truth by `noise` sigma times a fixed
// pattern in [-1, 1].
struct Corner {
  std::vector<ProblemPoint> points;
  std::vector<double> sigma;
  std::size_t last_on_first_wall = 0;
  Eigen::VectorXd truth;
};

Corner MakeCorner(double scale, double noise = 0.0) {
  Corner corner;
  constexpr std::size_t kBeams = 40;
  corner.truth.resize(2 * kBeams);
  const double corner_angle = std::atan2(2.0, 3.0);
  for (std::size_t i = 0; i < kBeams; ++i) {
    const double phi = -0.5 + 2.1 * static_cast<double>(i) / (kBeams - 1);
    const bool first_wall = phi < corner_angle;
    if (first_wall) corner.last_on_first_wall = i;
    const double rho = scale * (first_wall ? 3.0 / std::cos(phi) : 2.0 / std::sin(phi));
    const double alpha = first_wall ? kPi : -kPi / 2 + 2 * kPi;  // towards the sensor
    const double sigma = 0.01 * scale;
    ProblemPoint pt;
    pt.phi = phi;
    pt.rho_measured = rho + noise * sigma * std::sin(7.0 * static_cast<double>(i));
    pt.rho_lower = pt.rho_measured - 4 * sigma;
    pt.rho_upper = pt.rho_measured + 4 * sigma;
    const double facing = phi + kPi;
    pt.alpha_initial = facing + WrapAngle(alpha - facing);
    pt.alpha_sigma = 0.2;
    pt.alpha_lower = facing - DegToRad(89.0);
    pt.alpha_upper = facing + DegToRad(89.0);
    corner.points.push_back(pt);
    corner.sigma.push_back(sigma);
    corner.truth[static_cast<Eigen::Index>(2 * i)] = rho;
    corner.truth[static_cast<Eigen::Index>(2 * i + 1)] = pt.alpha_initial;
  }
  return corner;
}

InnerProblem MakeProblem(const dsl::CompiledPrior& prior, const Corner& corner,
                         bool corner_is_a_border) {
  std::vector<Link> links(corner.points.size() - 1, Link::kSameRegion);
  if (corner_is_a_border) links[corner.last_on_first_wall] = Link::kDifferentRegion;
  return InnerProblem(prior, corner.points, links, corner.sigma, std::nullopt);
}

// The scales of the tests: from a corner 3 m away to one 3e7 m away.
constexpr double kScales[] = {1.0, 1e3, 1e5, 1e6, 1e7};

// The true scene satisfies the polygonal prior at every scale, to rounding; a range moved by
// 1e-7 of itself (3 m on a wall 3e7 m away, ten times what the tolerance allows beyond
// kUnitRange) breaks it by the same violation at every scale from 1e3 on, as it would a wall
// kUnitRange away. (At 1e-7 * 3 m = 3e-7 m a corner 3 m away is feasible: its tolerance is
// 1e-6 m.)
TEST(InnerProblemScale, ABumpRelativeToTheRangesIsTheSameViolationAtEveryFarScale) {
  const dsl::CompiledPrior prior = dsl::PriorLibrary().Load("polygonal").value();
  const EngineOptions options;
  std::optional<double> far_violation;
  for (const double scale : kScales) {
    SCOPED_TRACE(::testing::Message() << "corner scaled by " << scale);
    const Corner corner = MakeCorner(scale);
    InnerProblem problem = MakeProblem(prior, corner, true);
    EXPECT_LE(problem.Violations(corner.truth).max_residual, 1e-2 * options.feasibility_tolerance);
    Eigen::VectorXd bumped = corner.truth;
    bumped[10] *= 1.0 + 1e-7;  // point 5, on the first wall
    const double violation = problem.Violations(bumped).max_residual;
    if (scale < kUnitRange) {
      EXPECT_LT(violation, options.feasibility_tolerance);
      continue;
    }
    EXPECT_GT(violation, 5.0 * options.feasibility_tolerance);
    if (!far_violation) far_violation = violation;
    EXPECT_NEAR(violation, *far_violation, 1e-3 * *far_violation);
  }
}

// SolveInner decides feasibility: the corner as one region is infeasible at every scale (it is
// no straight wall, however far); with the border at the corner it is feasible, and the two
// walls fitted to readings 1 sigma off are as close to the truth, relative to the ranges, at
// every scale. Before the fix the two walls were given up as infeasible from 1e5 on (the
// violation stalled at 0.03-0.04 m on the walls 3e5-3e7 m away; the one wall was rightly
// infeasible).
TEST(InnerProblemScale, ACornerIsInfeasibleAsOneWallAndFeasibleAsTwoAtEveryScale) {
  const dsl::CompiledPrior prior = dsl::PriorLibrary().Load("polygonal").value();
  const EngineOptions options;
  std::optional<double> near_error;
  for (const double scale : kScales) {
    SCOPED_TRACE(::testing::Message() << "corner scaled by " << scale);
    const Corner corner = MakeCorner(scale, 1.0);
    InnerProblem one_wall = MakeProblem(prior, corner, false);
    const InnerResult merged = SolveInner(one_wall, nullptr, options);
    EXPECT_FALSE(merged.feasible) << "violation " << merged.violation.max_residual;
    EXPECT_GT(merged.violation.max_residual, 1e3 * options.feasibility_tolerance);

    InnerProblem two_walls = MakeProblem(prior, corner, true);
    const InnerResult split = SolveInner(two_walls, nullptr, options);
    EXPECT_TRUE(split.feasible) << "violation " << split.violation.max_residual;
    double worst = 0.0;
    for (std::size_t p = 0; p < corner.points.size(); ++p) {
      const auto r = static_cast<Eigen::Index>(2 * p);
      worst = std::max(worst, std::abs(split.x[r] - corner.truth[r]) / corner.truth[r]);
    }
    if (!near_error) near_error = worst;
    // The fit halves the noise (1 sigma = 3e-3 of the ranges) ...
    EXPECT_LT(worst, 2e-3);
    // ... alike at every scale.
    EXPECT_NEAR(worst, *near_error, 0.1 * *near_error);
  }
}

}  // namespace
}  // namespace priormap::priorlets
