// The numerical pose-independence check (paper Def. 3): the built-in priors pass it, and terms
// that look at the map in the sensor's frame are reported by name.
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <priormap/dsl/pose_independence.hpp>
#include <priormap/dsl/prior_library.hpp>

namespace priormap::dsl {
namespace {

CompiledPrior Compile(const std::string& text) {
  Result<CompiledPrior> prior = PriorLibrary().CompileText(text, "test.prior");
  if (!prior) ADD_FAILURE() << prior.error();
  return std::move(prior).value();
}

const Term& TermOf(const CompiledPrior& prior, const PoseIndependenceViolation& v) {
  return prior.block(v.block)->terms()[static_cast<std::size_t>(v.term)];
}

TEST(PoseIndependence, EveryBuiltinPriorPasses) {
  const PriorLibrary library;
  const std::vector<PriorListing> builtins = library.List();
  ASSERT_EQ(builtins.size(), 10u);
  for (const PriorListing& listing : builtins) {
    const Result<CompiledPrior> prior = library.Load(listing.name);
    ASSERT_TRUE(prior.ok()) << prior.error();
    const PoseIndependenceReport report = CheckPoseIndependence(prior.value());
    EXPECT_EQ(report.configurations, 200);
    EXPECT_TRUE(report.ok()) << listing.name << ": " << report.violations.size()
                             << " term(s) changed, first "
                             << (report.ok() ? ""
                                             : TermOf(prior.value(), report.violations[0]).source);
  }
}

TEST(PoseIndependence, OrientationInTheSensorFrameIsReportedWithItsTerm) {
  const CompiledPrior prior = Compile(
      "name: Absolute\norder: 2\npriorlet same_region:\n"
      "  alpha_1 == alpha_2\n"
      "  alpha_1 == 0\n");
  const PoseIndependenceReport report = CheckPoseIndependence(prior, 50, 3);
  ASSERT_EQ(report.violations.size(), 1u);
  const PoseIndependenceViolation& v = report.violations[0];
  EXPECT_EQ(v.block, BlockKind::kSameRegion);
  EXPECT_EQ(v.term, 1);
  EXPECT_EQ(TermOf(prior, v).source, "alpha_1 == 0");
  // The term is alpha_1 itself, and the motion turns it by dtheta.
  EXPECT_NEAR(v.value_after - v.value_before, v.dtheta, 1e-12);
  EXPECT_NE(v.dtheta, 0.0);
}

TEST(PoseIndependence, RangeInTheSensorFrameIsReportedWithItsTerm) {
  const CompiledPrior prior = Compile(
      "name: Range\norder: 2\n"
      "priorlet different_region:\n"
      "  model_likelihood (alpha_2 - alpha_1)^2\n"
      "priorlet different_surface:\n"
      "  rho_1 == 2\n");
  const PoseIndependenceReport report = CheckPoseIndependence(prior, 50, 3);
  ASSERT_EQ(report.violations.size(), 1u);
  const PoseIndependenceViolation& v = report.violations[0];
  EXPECT_EQ(v.block, BlockKind::kDifferentSurface);
  EXPECT_EQ(v.term, 0);
  EXPECT_EQ(TermOf(prior, v).source, "rho_1 == 2");
  EXPECT_NE(v.value_before, v.value_after);
}

TEST(PoseIndependence, EachChangingTermIsReportedOnce) {
  const CompiledPrior prior = Compile(
      "name: Both\norder: 2\npriorlet same_region:\n"
      "  alpha_1 == 0\n"
      "  [rho_1; rho_2] == 1\n");
  const PoseIndependenceReport report = CheckPoseIndependence(prior, 100, 5);
  std::vector<int> terms;
  for (const PoseIndependenceViolation& v : report.violations) terms.push_back(v.term);
  EXPECT_THAT(terms, ::testing::ElementsAre(0, 1, 2));
}

TEST(PoseIndependence, SameSeedGivesTheSameReportAndAnotherSeedAnother) {
  const CompiledPrior prior =
      Compile("name: Absolute\norder: 2\npriorlet same_region:\n  alpha_1 == 0\n");
  const auto fields = [](const PoseIndependenceReport& r) {
    std::vector<double> out;
    for (const PoseIndependenceViolation& v : r.violations) {
      out.insert(out.end(), {static_cast<double>(v.term), v.value_before, v.value_after, v.dx, v.dy,
                             v.dtheta});
    }
    return out;
  };
  const PoseIndependenceReport first = CheckPoseIndependence(prior, 20, 11);
  const PoseIndependenceReport again = CheckPoseIndependence(prior, 20, 11);
  const PoseIndependenceReport other = CheckPoseIndependence(prior, 20, 12);
  ASSERT_FALSE(first.ok());
  EXPECT_EQ(fields(first), fields(again));
  EXPECT_NE(fields(first), fields(other));
}

TEST(PoseIndependence, ReportSaysHowManyConfigurationsWereTried) {
  const CompiledPrior prior =
      Compile("name: Fine\norder: 2\npriorlet same_region:\n  alpha_1 == alpha_2\n");
  const PoseIndependenceReport report = CheckPoseIndependence(prior, 17, 1);
  EXPECT_EQ(report.configurations, 17);
  EXPECT_TRUE(report.ok());
}

// abs(sqrt(phi_1)) - sqrt(phi_1) is 0 wherever phi_1 >= 0 and undefined elsewhere: its value never
// moves, but whether it is defined does, which depends on the pose as much.
TEST(PoseIndependence, ATermDefinedAtOnePoseOnlyIsReported) {
  const CompiledPrior prior = Compile(
      "name: OneSided\norder: 1\npriorlet same_region:\n  abs(sqrt(phi_1)) - sqrt(phi_1) == 0\n");
  const PoseIndependenceReport report = CheckPoseIndependence(prior, 100, 2);
  ASSERT_EQ(report.violations.size(), 1u);
  const PoseIndependenceViolation& v = report.violations[0];
  EXPECT_NE(std::isfinite(v.value_before), std::isfinite(v.value_after));
  EXPECT_EQ(v.Change(), std::numeric_limits<double>::infinity());
  EXPECT_GT(report.undefined_evaluations, 0);
}

TEST(PoseIndependence, TermsUndefinedAtBothPosesAreCountedNotPassed) {
  const CompiledPrior prior =
      Compile("name: Never\norder: 1\npriorlet same_region:\n  sqrt(phi_1 - 10) == 0\n");
  const PoseIndependenceReport report = CheckPoseIndependence(prior, 30, 4);
  EXPECT_TRUE(report.ok());
  EXPECT_EQ(report.undefined_evaluations, 30);
}

}  // namespace
}  // namespace priormap::dsl
