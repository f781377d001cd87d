// What one sonar cone could see of a square room, cell by cell: MakeSonarEvaluationRaster.
#include <algorithm>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include <priormap/core/check.hpp>
#include <priormap/core/scene_truth.hpp>
#include <priormap/prf/sonar_observed_area.hpp>

namespace priormap::prf {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// A room [-1, 2] x [-2, 2]; its wall x = 2 is region 1. One cone from the origin along +x,
// 0.2 rad either side, R = 5 m; `range` < 2 m is an echo short of the wall.
class OneConeInARoom : public ::testing::Test {
 protected:
  OneConeInARoom() {
    scene_.surfaces.push_back({Polyline{{{-1, -2}, {2, -2}, {2, 2}, {-1, 2}}, true}, false, ""});
    data_.max_range = 5.0;
    data_.sensors = {Vec2::Zero()};
  }

  EvaluationRaster Observe(double range, bool max_reading, ConeWallHits* hits = nullptr) {
    data_.readings = {{.cone = {.origin = Vec2::Zero(),
                                .axis = Vec2::UnitX(),
                                .half_spread = 0.2,
                                .max_range = 5.0},
                       .range = range,
                       .max_reading = max_reading,
                       .sensor = 0}};
    const std::vector<Vec2> seeds{Vec2::Zero()};
    return MakeSonarEvaluationRaster(grid_, SceneTruth(scene_, seeds), scene_, data_,
                                     {.rays_per_cone = 21, .band = 0.1}, hits);
  }

  [[nodiscard]] std::size_t At(double x, double y) const {
    return static_cast<std::size_t>(grid_.CellOf(Vec2(x, y)));
  }

  Scene scene_;
  SonarData data_;
  CellGrid grid_ = CellGrid::Covering(Vec2(-1.5, -2.5), Vec2(3.5, 2.5), 0.05);
};

TEST_F(OneConeInARoom, SeesItsSpreadUpToTheWallAndTheBandBehindIt) {
  ConeWallHits hits;
  const EvaluationRaster raster = Observe(1.5, false, &hits);
  ASSERT_EQ(raster.size(), static_cast<std::size_t>(grid_.NumCells()));
  EXPECT_EQ(raster.observation[At(1.01, 0.01)], Observation::kVisible);
  EXPECT_EQ(raster.observation[At(1.99, 0.01)], Observation::kVisible);
  EXPECT_EQ(raster.observation[At(2.06, 0.01)], Observation::kBehindSurface);
  EXPECT_TRUE(raster.Observed(At(2.06, 0.01))) << "behind the wall is black in truth";
  EXPECT_EQ(raster.observation[At(2.51, 0.01)], Observation::kUnseen);
  // Outside the cone, in the room and within R: a sensor all round would have seen these.
  EXPECT_EQ(raster.observation[At(1.01, 1.01)], Observation::kUnseen);
  EXPECT_EQ(raster.observation[At(-0.51, 0.01)], Observation::kUnseen);
  // Every ray of the fan met the wall x = 2.
  ASSERT_EQ(hits.size(), 1u);
  ASSERT_EQ(hits.count(1), 1u);
  ASSERT_EQ(hits.at(1).size(), 21u);
  for (const Vec2& hit : hits.at(1)) EXPECT_NEAR(hit.x(), 2.0, 1e-9);
  EXPECT_NEAR(std::max_element(hits.at(1).begin(), hits.at(1).end(),
                               [](const Vec2& a, const Vec2& b) { return a.y() < b.y(); })
                  ->y(),
              2.0 * std::tan(0.2), 1e-9);
}

TEST_F(OneConeInARoom, CoversTheConeUpToItsReadingOrToRForAMaxReading) {
  const EvaluationRaster short_echo = Observe(1.5, false);
  EXPECT_EQ(short_echo.covered[At(1.01, 0.01)], 1);
  EXPECT_TRUE(short_echo.Sparse(At(1.76, 0.01))) << "seen beyond the echo, not covered";
  EXPECT_EQ(short_echo.covered[At(1.01, 1.01)], 0);
  const EvaluationRaster no_echo = Observe(5.0, true);
  EXPECT_EQ(no_echo.covered[At(1.76, 0.01)], 1);
  EXPECT_EQ(no_echo.covered[At(2.06, 0.01)], 0) << "the band behind the wall is not covered";
}

// Options that would mark nothing sensible, or mark a ray for ever (an infinite band, a
// subnormal step), are refused before any ray is followed.
TEST_F(OneConeInARoom, RefusesFansThatCannotBeMarked) {
  data_.readings.clear();  // so that a check that lets one through fails rather than hangs
  const std::vector<Vec2> seeds{Vec2::Zero()};
  const SceneTruth truth(scene_, seeds);
  const auto refused = [&](const ConeFanOptions& options) {
    try {
      (void)MakeSonarEvaluationRaster(grid_, truth, scene_, data_, options);
    } catch (const ContractError&) {
      return true;
    }
    return false;
  };
  EXPECT_TRUE(refused({.rays_per_cone = 1, .band = 0.1, .mark_step = 0.0}));
  EXPECT_TRUE(refused({.rays_per_cone = 21, .band = -0.1, .mark_step = 0.0}));
  EXPECT_TRUE(refused({.rays_per_cone = 21, .band = kInf, .mark_step = 0.0}));
  EXPECT_TRUE(refused({.rays_per_cone = 21, .band = 0.1, .mark_step = 1e-300}));
  EXPECT_TRUE(refused({.rays_per_cone = 21, .band = 0.1, .mark_step = -0.05}));
  EXPECT_FALSE(refused({.rays_per_cone = 21, .band = 0.1, .mark_step = 0.05}));
}

}  // namespace
}  // namespace priormap::prf
