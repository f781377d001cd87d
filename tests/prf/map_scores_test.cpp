#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include <priormap/core/angles.hpp>
#include <priormap/prf/map_scores.hpp>
#include <priormap/prf/map_study.hpp>

namespace priormap::prf {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

Scene Room(double w, double h) {
  Scene scene;
  scene.name = "room";
  scene.surfaces.push_back(
      {Polyline{{{-w / 2, -h / 2}, {w / 2, -h / 2}, {w / 2, h / 2}, {-w / 2, h / 2}}, true}, false,
       "walls"});
  scene.waypoints = {{-0.5, -0.5}, {0.5, -0.5}};
  return scene;
}

// The room's walls moved inwards by `inset`, as map edges.
std::vector<Segment> InsetWalls(double half, double inset) {
  const double h = half - inset;
  return {{{-h, -h}, {h, -h}}, {{h, -h}, {h, h}}, {{h, h}, {-h, h}}, {{-h, h}, {-h, -h}}};
}

TEST(MapScores, DecisionsAtAndAroundOneHalf) {
  EXPECT_EQ(Decide(0.7), Decision::kBlack);
  EXPECT_EQ(Decide(0.3), Decision::kWhite);
  EXPECT_EQ(Decide(0.5), Decision::kUndecided);
  EXPECT_EQ(Decide(kNaN), Decision::kUndecided);
}

TEST(MapScores, ClassificationCountsUndecidedAsErrorsAndSkipsTheUnobserved) {
  EvaluationRaster raster;
  raster.grid = CellGrid{.origin = Vec2::Zero(), .cell = Vec2::Ones(), .nx = 6, .ny = 1};
  using O = Observation;
  raster.observation = {O::kVisible,       O::kVisible, O::kBehindSurface,
                        O::kBehindSurface, O::kUnseen,  O::kVisible};
  raster.truth_black = {0, 0, 1, 0, 1, 0};
  raster.covered = {1, 0, 1, 1, 0, 0};
  // Right; undecided (sparse); right; not scored (white behind a wall: unseen free space);
  // not scored (unseen); wrong (sparse).
  const std::vector<double> p = {0.2, kNaN, 0.9, 0.9, 0.1, 0.6};
  EXPECT_TRUE(raster.Observed(3) == false && raster.Sparse(1) && !raster.Sparse(3));
  const MapClassification score = ScoreClassification(p, raster);
  EXPECT_EQ(score.observed.points, 4u);
  EXPECT_EQ(score.observed.decided, 3u);
  EXPECT_EQ(score.observed.correct, 2u);
  EXPECT_DOUBLE_EQ(score.observed.Accuracy(), 0.5);
  EXPECT_DOUBLE_EQ(score.observed.Coverage(), 0.75);
  EXPECT_DOUBLE_EQ(score.observed.DecidedAccuracy(), 2.0 / 3.0);
  EXPECT_EQ(score.sparse.points, 2u);
  EXPECT_EQ(score.sparse.decided, 1u);
  EXPECT_EQ(score.sparse.correct, 0u);
  EXPECT_EQ(score.covered.points, 2u);
  EXPECT_EQ(score.covered.correct, 2u);
  EXPECT_TRUE(std::isnan(ClassificationScore{}.Accuracy()));
}

TEST(MapScores, RasterMapsAreReadAtTheCellHoldingEachCentre) {
  OccupancyRaster map;
  map.origin = Vec2(0, 0);
  map.resolution = 1.0;
  map.probability.resize(2, 3);
  map.probability << 0.1, 0.2, 0.3,  //
      0.4, 0.5, kNaN;
  // Centres at x = 0.5, 1.5, 2.5, 3.5 and y = 0.25, 1.75.
  const CellGrid grid{.origin = Vec2(0, -0.5), .cell = Vec2(1.0, 1.5), .nx = 4, .ny = 2};
  const std::vector<double> values = SampleAtCentres(map, grid);
  ASSERT_EQ(values.size(), 8u);
  EXPECT_DOUBLE_EQ(values[0], 0.1);
  EXPECT_DOUBLE_EQ(values[2], 0.3);
  EXPECT_TRUE(std::isnan(values[3]));  // beyond the map
  EXPECT_DOUBLE_EQ(values[4], 0.4);
  EXPECT_DOUBLE_EQ(values[5], 0.5);
  EXPECT_TRUE(std::isnan(values[6]));  // never observed

  Eigen::MatrixXd m(2, 4);
  m << 0, 1, 2, 3,  //
      4, 5, 6, 7;
  const std::vector<double> flat = Flatten(m, grid);
  for (int i = 0; i < 8; ++i) EXPECT_EQ(flat[static_cast<std::size_t>(i)], i);
}

TEST(MapScores, CoverageIsTheCellsBeamsCrossOrEndIn) {
  EvaluationRaster raster;
  raster.grid = CellGrid{.origin = Vec2::Zero(), .cell = Vec2::Ones(), .nx = 10, .ny = 10};
  raster.covered.assign(100, 0);
  LaserData data;
  data.max_range = 20;
  data.beams.push_back({.origin = {0.5, 0.5}, .direction = {1, 0}, .range = 3.0});  // 4 cells
  // Leaves the raster at the top: 5 cells, none wrapped or clamped.
  data.beams.push_back(
      {.origin = {5.5, 5.5}, .direction = {0, 1}, .range = 20, .max_reading = true});
  // Enters from outside on the left: 2 cells.
  data.beams.push_back({.origin = {-2, 2.5}, .direction = {1, 0}, .range = 3.7});
  MarkCoverage(data, &raster);
  int covered = 0;
  for (const std::uint8_t c : raster.covered) covered += c;
  EXPECT_EQ(covered, 4 + 5 + 2);
  for (int ix = 0; ix <= 3; ++ix) EXPECT_TRUE(raster.covered[static_cast<std::size_t>(ix)]);
  for (int iy = 5; iy <= 9; ++iy)
    EXPECT_TRUE(raster.covered[static_cast<std::size_t>(iy * 10 + 5)]);
  EXPECT_TRUE(raster.covered[20] && raster.covered[21] && !raster.covered[22]);
}

TEST(MapScores, WeightedQuantiles) {
  EXPECT_EQ(WeightedQuantile({3, 1, 4, 2}, {1, 1, 1, 1}, 0.5), 2);
  EXPECT_EQ(WeightedQuantile({3, 1, 4, 2}, {1, 1, 1, 1}, 0.25), 1);
  EXPECT_EQ(WeightedQuantile({3, 1, 4, 2}, {1, 1, 1, 1}, 0.9), 4);
  EXPECT_EQ(WeightedQuantile({3, 1, 4, 2}, {1, 1, 1, 1}, 1.0), 4);
  EXPECT_EQ(WeightedQuantile({1, 2, 3}, {0, 0, 5}, 0.1), 3);
  EXPECT_EQ(WeightedQuantile({1, 2, 3}, {8, 1, 1}, 0.8), 1);
  EXPECT_EQ(WeightedQuantile({1, 2, 3}, {8, 1, 1}, 0.85), 2);
  EXPECT_TRUE(std::isnan(WeightedQuantile({1, 2}, {0, 0}, 0.5)));
}

TEST(MapScores, WallsInsetByTwoCentimetresAreTwoCentimetresOffAndRecovered) {
  const Scene scene = Room(4, 4);
  const SceneTruth truth = SceneTruth::OfScene(scene);
  const ObservedArea observed(scene, {{.pose = Se2(0, 0, 0), .fov = kTwoPi, .max_range = 8}}, 0.1);
  const std::vector<Vec2> wall_points = VisibleWallPoints(scene, observed, 0.01);
  ASSERT_EQ(wall_points.size(), 1600u);
  const WallScore inset = ScoreWalls(InsetWalls(2.0, 0.02), truth, observed, wall_points);
  EXPECT_NEAR(inset.scored_length, 4 * 3.96, 1e-9);
  EXPECT_NEAR(inset.mean_distance, 0.02, 1e-9);
  EXPECT_NEAR(inset.p90_distance, 0.02, 1e-9);
  EXPECT_NEAR(inset.max_distance, 0.02, 1e-9);
  EXPECT_EQ(inset.wall_points, 1600u);
  EXPECT_DOUBLE_EQ(inset.recovered_fraction, 1.0);

  // Six centimetres off: nothing within the 5 cm tolerance.
  const WallScore far = ScoreWalls(InsetWalls(2.0, 0.06), truth, observed, wall_points);
  EXPECT_NEAR(far.mean_distance, 0.06, 1e-9);
  EXPECT_DOUBLE_EQ(far.recovered_fraction, 0.0);

  // Plus a spurious 1 m edge across the middle, 1.5–2 m from every wall (1.75 m on average).
  std::vector<Segment> edges = InsetWalls(2.0, 0.02);
  edges.push_back({{-0.5, 0}, {0.5, 0}});
  const WallScore spurious = ScoreWalls(edges, truth, observed, wall_points);
  EXPECT_NEAR(spurious.scored_length, 4 * 3.96 + 1.0, 1e-9);
  EXPECT_NEAR(spurious.mean_distance, (4 * 3.96 * 0.02 + 1.0 * 1.75) / (4 * 3.96 + 1.0), 1e-9);
  EXPECT_NEAR(spurious.p90_distance, 0.02, 1e-9);   // 94 % of the length is 2 cm off
  EXPECT_NEAR(spurious.max_distance, 1.995, 1e-9);  // the piece midpoints nearest the centre

  // Edges behind the walls: within the band they count, beyond it they are not scored.
  const std::vector<Segment> behind = {{{2.05, -1}, {2.05, 1}}, {{2.5, -1}, {2.5, 1}}};
  const WallScore outside = ScoreWalls(behind, truth, observed, wall_points);
  EXPECT_NEAR(outside.scored_length, 2.0, 1e-9);
  EXPECT_NEAR(outside.mean_distance, 0.05, 1e-9);
  EXPECT_NEAR(outside.recovered_fraction, 200.0 / 1600.0, 1e-9);  // x = 2, |y| <= 1
  EXPECT_DOUBLE_EQ(outside.border_length, 0.0);  // the far edge is unseen on both sides
}

TEST(MapScores, EdgesAlongTheBorderOfTheUnseenAreNotWalls) {
  const Scene scene = Room(4, 4);
  const SceneTruth truth = SceneTruth::OfScene(scene);
  // Looking along +x with 180°: x < 0 is unseen, so an edge along x = 0 is the map's guess
  // where the unseen begins, and one along x = 1 a claim of a wall (1 m off).
  const ObservedArea half(scene, {{.pose = Se2(0, 0, 0), .fov = kPi, .max_range = 8}}, 0.1);
  const std::vector<Segment> edges = {{{0, -1}, {0, 1}}, {{1, -1}, {1, 1}}};
  const WallScore score = ScoreWalls(edges, truth, half, VisibleWallPoints(scene, half, 0.01));
  EXPECT_NEAR(score.border_length, 2.0, 1e-9);
  EXPECT_NEAR(score.scored_length, 2.0, 1e-9);
  EXPECT_NEAR(score.mean_distance, 1.0, 1e-9);
  EXPECT_DOUBLE_EQ(score.recovered_fraction, 0.0);
}

TEST(MapScores, SupportedWallsAreThePiecesNearWhereBeamsEnded) {
  const Scene scene = Room(4, 4);
  const SceneTruth truth = SceneTruth::OfScene(scene);
  const ObservedArea observed(scene, {{.pose = Se2(0, 0, 0), .fov = kTwoPi, .max_range = 8}}, 0.1);
  const std::vector<Vec2> wall_points = VisibleWallPoints(scene, observed, 0.01);
  // The walls inset by 2 cm, and a 1 m edge across the middle 1.75 m from the walls on average.
  std::vector<Segment> edges = InsetWalls(2.0, 0.02);
  edges.push_back({{-0.5, 0}, {0.5, 0}});
  // Hits along the east wall only (y in [-1, 1]), and one 25 cm off the middle edge's end.
  std::vector<Vec2> hits;
  for (int k = 0; k <= 20; ++k) hits.emplace_back(2.0, -1.0 + 0.1 * k);
  hits.emplace_back(0.75, 0.0);
  WallScoreOptions options;
  options.support_radius = 0.3;
  const WallScore score = ScoreWalls(edges, truth, observed, wall_points, options, hits);
  EXPECT_NEAR(score.scored_length, 4 * 3.96 + 1.0, 1e-9);
  // Supported: the east wall's pieces within 0.3 m of a hit, y in [-1.3, 1.3] (2.6 m, 2 cm off),
  // and the middle edge's pieces within 0.3 m of (0.75, 0), x in [0.45, 0.5] (1.75 m off).
  EXPECT_NEAR(score.supported_length, 2.6 + 0.05, 0.03);  // pieces of 1 cm at three ends
  const double mean = (2.6 * 0.02 + 0.05 * 1.525) / 2.65;
  EXPECT_NEAR(score.supported_mean_distance, mean, 0.01);
  EXPECT_NEAR(score.supported_p90_distance, 0.02, 1e-9);
  EXPECT_NEAR(score.supported_max_distance, 1.545, 0.01);
  // Without hits, nothing is supported and the supported scores are NaN.
  const WallScore none = ScoreWalls(edges, truth, observed, wall_points, options);
  EXPECT_EQ(none.supported_length, 0.0);
  EXPECT_TRUE(std::isnan(none.supported_mean_distance));
  EXPECT_NEAR(none.mean_distance, score.mean_distance, 1e-12);
}

TEST(MapStudy, PosesAreSpacedEvenlyAlongTheWaypointPath) {
  const Scene rectangle = *BuiltinScene("rectangle");  // a closed 10 m loop from (-1.5, -1)
  const std::vector<Se2> two = StudyPoses(rectangle, 2);
  ASSERT_EQ(two.size(), 2u);
  EXPECT_TRUE(two[0].vector().isApprox(Vec3(-1.5, -1.0, 0.0)));
  EXPECT_TRUE(two[1].vector().isApprox(Vec3(1.5, 1.0, kPi / 2)));
  const std::vector<Se2> five = StudyPoses(rectangle, 5);
  ASSERT_EQ(five.size(), 5u);
  EXPECT_TRUE(five[1].translation().isApprox(Vec2(0.5, -1.0)));
  EXPECT_TRUE(five[4].translation().isApprox(Vec2(-1.5, 1.0)));
}

}  // namespace
}  // namespace priormap::prf
