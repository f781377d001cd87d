// The 0.5 contour of raster maps and its wall scores (contour_scores.hpp), on rasters whose
// contours and missed walls are known.
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include <priormap/core/angles.hpp>
#include <priormap/prf/contour_scores.hpp>

namespace priormap::prf {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A 4 m x 4 m room centred on the origin.
Scene Room() {
  Scene scene;
  scene.name = "room";
  scene.surfaces.push_back({Polyline{{{-2, -2}, {2, -2}, {2, 2}, {-2, 2}}, true}, false, "walls"});
  scene.waypoints = {{-0.5, -0.5}, {0.5, -0.5}};
  return scene;
}

// Values at the centres of `grid` from a function of the centre.
template <typename F>
std::vector<double> Values(const CellGrid& grid, F&& f) {
  std::vector<double> v(static_cast<std::size_t>(grid.NumCells()));
  for (int i = 0; i < grid.NumCells(); ++i) v[static_cast<std::size_t>(i)] = f(grid.Centre(i));
  return v;
}

TEST(HalfContour, AStepIsCutHalfwayBetweenTheCentresOnEitherSide) {
  const CellGrid grid = CellGrid::Covering({0, 0}, {4, 3}, 0.5);  // centres at 0.25, 0.75, ...
  const std::vector<double> step =
      Values(grid, [](const Vec2& p) { return p.x() > 2 ? 0.9 : 0.1; });
  const std::vector<Segment> contour = HalfContour(step, grid);
  ASSERT_EQ(contour.size(), 5u);  // one per row of squares
  double length = 0.0;
  for (const Segment& s : contour) {
    EXPECT_NEAR(s.a.x(), 2.0, 1e-12);
    EXPECT_NEAR(s.b.x(), 2.0, 1e-12);
    length += s.Length();
  }
  EXPECT_NEAR(length, 2.5, 1e-12);  // from the first row of centres to the last

  // Interpolated: 0.2 and 0.7 on either side put the level 3/5 of the way.
  const std::vector<double> ramp =
      Values(grid, [](const Vec2& p) { return p.x() > 2 ? 0.7 : 0.2; });
  for (const Segment& s : HalfContour(ramp, grid)) EXPECT_NEAR(s.a.x(), 1.75 + 0.3, 1e-12);

  // An unknown corner leaves its squares without contour; a constant raster has none.
  std::vector<double> unknown = step;
  unknown[static_cast<std::size_t>(grid.CellOf({1.75, 0.25}))] = kNaN;
  EXPECT_EQ(HalfContour(unknown, grid).size(), 4u);
  EXPECT_TRUE(HalfContour(std::vector<double>(step.size(), 0.3), grid).empty());
}

TEST(HalfContour, ASaddleFollowsTheMeanOfItsCorners) {
  const CellGrid grid = CellGrid::Covering({0, 0}, {2, 2}, 1.0);  // one square of centres
  const auto midpoints = [&](const std::vector<double>& values) {
    std::vector<Vec2> mids;
    for (const Segment& s : HalfContour(values, grid)) mids.push_back(0.5 * (s.a + s.b));
    std::sort(mids.begin(), mids.end(), [](const Vec2& p, const Vec2& q) { return p.x() < q.x(); });
    return mids;
  };
  // Cell order (0,0) (1,0) (0,1) (1,1): the centres (0.5, 0.5) and (1.5, 1.5) are high, the
  // other two low. Mean 0.55: the high corners connect through the centre and the contour cuts
  // off the low ones; each cut joins the level's crossings 4/7 and 3/7 along the sides.
  const std::vector<Vec2> high = midpoints({0.9, 0.2, 0.2, 0.9});
  ASSERT_EQ(high.size(), 2u);
  // Around (1.5, 0.5): from (0.5 + 4/7, 0.5) to (1.5, 0.5 + 3/7); around (0.5, 1.5), mirrored.
  EXPECT_TRUE(
      high[1].isApprox(Vec2((0.5 + 4.0 / 7.0 + 1.5) / 2.0, (0.5 + 0.5 + 3.0 / 7.0) / 2.0), 1e-12));
  EXPECT_TRUE(high[0].isApprox(Vec2(2.0 - high[1].x(), 2.0 - high[1].y()), 1e-12));
  // Mean 0.35: the low corners connect, and the contour cuts off the high ones, 0.2 from each.
  const std::vector<Vec2> low = midpoints({0.6, 0.1, 0.1, 0.6});
  ASSERT_EQ(low.size(), 2u);
  EXPECT_TRUE(low[0].isApprox(Vec2(0.6, 0.6), 1e-12));
  EXPECT_TRUE(low[1].isApprox(Vec2(1.4, 1.4), 1e-12));
}

TEST(ScoreContour, ARoomMissingOneWallMissesExactlyThatWall) {
  const Scene scene = Room();
  const SceneTruth truth = SceneTruth::OfScene(scene);
  const CellGrid grid = CellGrid::Covering({-3, -3}, {3, 3}, 0.05);
  EvaluationRaster raster;
  raster.grid = grid;
  const auto n = static_cast<std::size_t>(grid.NumCells());
  raster.truth_black.assign(n, 0);
  // Observed: the room and a 10 cm band around it.
  raster.observation.assign(n, Observation::kUnseen);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 c = grid.Centre(static_cast<int>(i));
    if (std::abs(c.x()) <= 2.1 && std::abs(c.y()) <= 2.1)
      raster.observation[i] = Observation::kVisible;
  }
  raster.covered.assign(n, 1);
  // Seen walls: each of the four sides, every 1 cm.
  std::vector<SeenWall> walls(4);
  const std::vector<Vec2> corners = {{-2, -2}, {2, -2}, {2, 2}, {-2, 2}};
  for (int k = 0; k < 4; ++k) {
    walls[k].length = 4.0;
    for (int j = 0; j < 400; ++j)
      walls[k].points.push_back(corners[k] +
                                (j + 0.5) / 400.0 * (corners[(k + 1) % 4] - corners[k]));
  }
  // Black outside the room, except beyond the east wall (x > 2), which the map left white.
  const std::vector<double> map = Values(grid, [](const Vec2& p) {
    return (std::abs(p.x()) <= 2 && std::abs(p.y()) <= 2) || p.x() > 2 ? 0.0 : 1.0;
  });
  const ContourWallScore score = ScoreContour(HalfContour(map, grid), walls, raster, truth);
  EXPECT_EQ(score.walls_seen, 4);
  EXPECT_EQ(score.walls_missed, 1);
  EXPECT_NEAR(score.recovered_fraction, 0.75, 0.02);
  // The contour lies on the three walls; the squares at the two open corners cut them diagonally.
  EXPECT_LT(score.mean_distance, 0.005);
  EXPECT_NEAR(score.contour_length, 3 * 4.0 + 0.1 * std::sqrt(2.0), 0.03);

  // Where nothing was observed nothing is scored.
  raster.observation.assign(n, Observation::kUnseen);
  const ContourWallScore unseen = ScoreContour(HalfContour(map, grid), walls, raster, truth);
  EXPECT_EQ(unseen.contour_length, 0.0);
  EXPECT_TRUE(std::isnan(unseen.mean_distance));
}

}  // namespace
}  // namespace priormap::prf
