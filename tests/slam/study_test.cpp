// The study's statistics, and the study itself against the acceptance points.
#include <gtest/gtest.h>

#include <priormap/slam/study.hpp>

namespace priormap::slam {
namespace {

TEST(ChiSquareQuantile, MatchesTables) {
  // Abramowitz & Stegun, Table 26.8 / any chi-square table.
  EXPECT_NEAR(ChiSquareQuantile(0.95, 1.0), 3.841459, 1e-5);
  EXPECT_NEAR(ChiSquareQuantile(0.999, 1.0), 10.827566, 1e-5);
  EXPECT_NEAR(ChiSquareQuantile(0.99, 2.0), 9.210340, 1e-5);
  EXPECT_NEAR(ChiSquareQuantile(0.025, 90.0), 65.646618, 1e-4);
  EXPECT_NEAR(ChiSquareQuantile(0.975, 90.0), 118.135893, 1e-4);
  EXPECT_NEAR(ChiSquareQuantile(0.5, 2.0), 2.0 * std::log(2.0), 1e-9);
}

TEST(Summarise, CountsErrorsInsideThreeSigmaAndTheNeesBand) {
  RunTrace run;
  for (int f = 0; f < 4; ++f) {
    run.error.push_back(Vec3(f == 3 ? 4.0 : f, 0.0, 0.0));
    run.sigma.push_back(Vec3::Ones());
    run.nees.push_back(f * f);
    run.result.frames.push_back({});
  }
  const VariantSummary s = Summarise({run}, 0.5, 5.0);
  EXPECT_NEAR(s.inside_3sigma.x(), 0.75, 1e-12);  // errors 0, 1, 2 inside, 4 outside
  EXPECT_NEAR(s.inside_3sigma_fraction, 0.75, 1e-12);
  EXPECT_NEAR(s.rms_position_m, std::sqrt((0.0 + 1 + 4 + 16) / 4), 1e-12);
  EXPECT_NEAR(s.mean_nees, (0.0 + 1 + 4 + 9) / 4, 1e-12);
  EXPECT_NEAR(s.nees_inside_band_fraction, 0.5, 1e-12);  // 1 and 4
}

}  // namespace
}  // namespace priormap::slam

namespace priormap::slam {
namespace {

// Plain EKF-SLAM (no prior map) over 10 runs of the study's scenario, scored against the truth.
VariantSummary PlainSlam(const SlamOptions& base) {
  const int runs = 10;
  const UrbanScenarioOptions scenario;
  const UrbanWorld world = MakeUrbanWorld(scenario, 1);
  SlamOptions options = base;
  options.use_prior_map = false;
  std::vector<RunTrace> traces;
  for (int r = 0; r < runs; ++r) {
    const UrbanRun run = SimulateUrbanRun(world, scenario, 1, r);
    traces.push_back(ScoreRun(RunSlam(run.input, nullptr, options), run.frame_truth));
  }
  return Summarise(traces, ChiSquareQuantile(0.025, 3.0 * runs) / runs,
                   ChiSquareQuantile(0.975, 3.0 * runs) / runs);
}

// The filter is consistent on its own before any prior map helps: first-estimate Jacobians and
// the range's second-order terms. The first-order EKF with current-estimate Jacobians is far
// overconfident on the same data (average NEES ~80 for 3 degrees of freedom).
TEST(Study, PlainSlamIsConsistentWithFirstEstimateJacobiansAndSecondOrderRange) {
  const VariantSummary consistent = PlainSlam(SlamOptions{});
  EXPECT_GE(consistent.nees_inside_band_fraction, 0.8);
  EXPECT_GE(consistent.inside_3sigma_fraction, 0.95);

  SlamOptions plain;
  plain.first_estimates_jacobians = false;
  plain.second_order_range = false;
  const VariantSummary overconfident = PlainSlam(plain);
  EXPECT_GT(overconfident.mean_nees, 20.0);
  EXPECT_LT(overconfident.inside_3sigma_fraction, 0.8);
}

// The acceptance points for the study (30 runs, seed 1); the figures are quoted in
// docs/slam-prior-map.md.
TEST(Study, PriorMapMakesTheFilterAccurateAndConsistent) {
  StudyOptions options;
  options.runs = 30;
  options.seed = 1;
  const StudyResult study = RunStudy(options);
  const VariantSummary& with = study.with_prior_summary;
  const VariantSummary& without = study.without_prior_summary;
  EXPECT_LE(3.0 * with.rms_position_m, without.rms_position_m);
  for (int k = 0; k < 3; ++k) EXPECT_GE(with.inside_3sigma[k], 0.95) << "axis " << k;
  EXPECT_GE(with.nees_inside_band_fraction, 0.8);
  EXPECT_LE(30.0 * static_cast<double>(study.relations.incorrect),
            static_cast<double>(study.relations.correct));
}

}  // namespace
}  // namespace priormap::slam
