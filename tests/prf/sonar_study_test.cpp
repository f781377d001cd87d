// The sonar comparison (sonar_study.hpp, issue 7) on a simulated office: what it measures of the
// sonar grid and the PRF posterior built from the same rings. The full study's numbers, and
// where the PRF falls short of the targets, are in docs/prf.md.
#include <gtest/gtest.h>

#include <priormap/core/scene.hpp>
#include <priormap/prf/sonar_model_io.hpp>
#include <priormap/prf/sonar_study.hpp>

namespace priormap::prf {
namespace {

TEST(SonarStudy, ThePrfFindsTheWallsTheGridErasesOnASimulatedOffice) {
  SonarStudyOptions options;
  options.scenes = {*BuiltinScene("office")};
  options.mapping.samples = 50000;
  options.mapping.burn_in = 50000;
  options.mapping.chains = 2;
  ASSERT_EQ(options.Problem(), "");
  const SonarStudyResult result = RunSonarStudy(options);
  ASSERT_EQ(result.cases.size(), 1u);
  const SonarStudyCase& c = result.cases[0];
  EXPECT_EQ(c.readings, c.ring_poses.size() * 16);
  EXPECT_GT(c.max_readings, c.readings / 4);  // specular misses and rooms beyond R
  const SonarStudyMethod& grid = c.Method("grid");
  const SonarStudyMethod& prf = c.Method("prf posterior");
  // Both are scored on the same walls: the office's corridor and room walls the cones saw.
  EXPECT_GT(grid.walls.walls_seen, 30);
  EXPECT_EQ(grid.walls.walls_seen, prf.walls.walls_seen);
  // The grid's max-range readings clear the corridor's walls (Paskin & Thrun, Sec. 1.2): it
  // misses most of them, the PRF far fewer, and the PRF's contour recovers more of them.
  EXPECT_GT(grid.walls.walls_missed, grid.walls.walls_seen / 2);
  EXPECT_LT(prf.walls.walls_missed + 5, grid.walls.walls_missed);
  EXPECT_GT(prf.walls.recovered_fraction, grid.walls.recovered_fraction + 0.3);
  // The grid decides nearly all of what the cones saw; the PRF decides everything.
  EXPECT_GT(grid.classification.observed.Coverage(), 0.95);
  EXPECT_GT(prf.classification.observed.Coverage(), 0.95);
}

// docs/prf.md's protocol at CI length: the shipped sonar model (fitted on other seeds, with
// multipath), the free-space and orientation priors, a tempered start. On the office the
// posterior classifies what the cones saw clearly better than the grid, misses fewer walls and
// draws its 0.5 contour within 10 cm of the true walls on average. (Issue 7 asks for 5 points
// of accuracy: with 3M steps per chain docs/prf.md measures 6.0 and 6.3 on two seeds; at this
// length the chains are not yet mixed, so the margin is asked only to pass 4 points.)
TEST(SonarStudy, WithTheFittedModelAndPriorsThePrfBeatsTheGridOnTheOffice) {
  SonarStudyOptions options;
  options.scenes = {*BuiltinScene("office")};
  const Result<SonarModel> model =
      ReadSonarModel(PRIORMAP_EXAMPLES_DIR "/formats/sonar-model-simulated.json");
  ASSERT_TRUE(model.ok()) << model.error();
  options.model = model.value();
  options.mapping.sampler.free_space = 1.0;
  options.mapping.sampler.orientation.weight = 1.0;
  options.mapping.burn_in_temperature = 5.0;
  options.mapping.burn_in = 600000;
  options.mapping.samples = 600000;
  options.mapping.chains = 2;
  ASSERT_EQ(options.Problem(), "");
  const SonarStudyResult result = RunSonarStudy(options);
  ASSERT_EQ(result.cases.size(), 1u);
  const SonarStudyMethod& grid = result.cases[0].Method("grid");
  const SonarStudyMethod& prf = result.cases[0].Method("prf posterior");
  EXPECT_GT(prf.classification.observed.Accuracy(), grid.classification.observed.Accuracy() + 0.04);
  EXPECT_LT(prf.walls.walls_missed, grid.walls.walls_missed);
  EXPECT_LT(prf.walls.mean_distance, 0.10);
}

TEST(SonarStudy, ReportsBadOptions) {
  SonarStudyOptions options;
  EXPECT_NE(options.Problem(), "");  // no scene
  options.scenes = {*BuiltinScene("office")};
  options.rate = 0.0;
  EXPECT_NE(options.Problem().find("rate"), std::string::npos);
  // A typo of the rate: refused before 1e12 rings are simulated.
  options.rate = 1e12;
  EXPECT_NE(options.Problem().find("more than the 1e+06 a study takes"), std::string::npos)
      << options.Problem();
  options.rate = 2.0;  // about 1,600 readings in the office
  EXPECT_EQ(options.Problem(), "");
}

}  // namespace
}  // namespace priormap::prf
