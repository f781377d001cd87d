// The window's perimeter coordinates and the grid walk (DDA) against brute force.
#include <algorithm>
#include <cmath>
#include <set>

#include <gtest/gtest.h>

#include <priormap/core/rng.hpp>
#include <priormap/prf/cell_grid.hpp>
#include <priormap/prf/window.hpp>

#include "prf/brute_force.hpp"

namespace priormap::prf {
namespace {

const Window kWindow{Vec2(-1.0, 2.0), Vec2(3.0, 4.5)};  // 4 × 2.5, off the origin

TEST(Window, PerimeterCoordinatesRoundTripOnEverySide) {
  EXPECT_DOUBLE_EQ(kWindow.Perimeter(), 13.0);
  EXPECT_DOUBLE_EQ(kWindow.Area(), 10.0);
  Rng rng(3);
  for (int i = 0; i < 1000; ++i) {
    const double s = rng.Uniform(0.0, kWindow.Perimeter());
    const int side = kWindow.SideAt(s);
    ASSERT_GE(side, 0);
    const Vec2 p = kWindow.PointAt(s);
    EXPECT_NEAR(kWindow.CoordinateOf(p, side), s, 1e-12);
    // On its side's line exactly.
    const double across = side % 2 == 0 ? p.y() : p.x();
    const double line = side == 0   ? kWindow.min.y()
                        : side == 1 ? kWindow.max.x()
                        : side == 2 ? kWindow.max.y()
                                    : kWindow.min.x();
    EXPECT_EQ(across, line);
  }
}

TEST(Window, CornersAreNoSideAndCoordinatesWrap) {
  for (int k = 0; k < kNumSides; ++k) {
    EXPECT_EQ(kWindow.SideAt(kWindow.CornerCoordinate(k)), -1);
    EXPECT_EQ(kWindow.PointAt(kWindow.CornerCoordinate(k)), kWindow.Corner(k));
    // Side k runs from corner k to corner k + 1 in its direction.
    const Vec2 along = kWindow.Corner(k + 1) - kWindow.Corner(k);
    EXPECT_NEAR((along.normalized() - kWindow.SideDirection(k)).norm(), 0.0, 1e-15);
    EXPECT_DOUBLE_EQ(along.norm(), kWindow.SideLength(k));
  }
  EXPECT_DOUBLE_EQ(kWindow.Wrap(-0.5), 12.5);
  EXPECT_DOUBLE_EQ(kWindow.Wrap(13.25), 0.25);
  EXPECT_EQ(kWindow.SideAt(-0.5), 3);
}

// map_server and the figures take square cells; a grid fitted to its window has cells a little
// taller or wider than they are long, and its rows are resampled so that every raster row lies
// where it says.
TEST(SquareCellRaster, ResamplesRowsSoThatEachSquareCellHoldsTheValueAtItsCentre) {
  const CellGrid grid = CellGrid::Covering({0, 0}, {4, 3}, 1.4);  // cells 4/3 x 3/3: 3 x 3
  ASSERT_EQ(grid.nx, 3);
  ASSERT_EQ(grid.ny, 3);
  Eigen::MatrixXd values(3, 3);
  for (int r = 0; r < 3; ++r) values.row(r).setConstant(r);
  const OccupancyRaster raster = SquareCellRaster(values, grid);
  EXPECT_DOUBLE_EQ(raster.resolution, 4.0 / 3.0);
  ASSERT_EQ(raster.probability.rows(), 2);  // 3 m at 4/3 m: 2.25 rows
  ASSERT_EQ(raster.probability.cols(), 3);
  // Row centres at 2/3 m and 2 m lie in the grid's rows 0 and 2.
  EXPECT_EQ(raster.probability(0, 1), 0.0);
  EXPECT_EQ(raster.probability(1, 1), 2.0);
  // Square cells are passed through.
  const CellGrid square = CellGrid::Covering({0, 0}, {2, 2}, 1.0);
  EXPECT_EQ(SquareCellRaster(Eigen::MatrixXd::Ones(2, 2), square).probability.rows(), 2);
}

TEST(WalkCells, VisitsExactlyTheCellsTheSegmentCrossesInOrder) {
  const CellGrid grid = CellGrid::Covering(kWindow.min, kWindow.max, 0.3);
  EXPECT_EQ(grid.nx, 14);
  EXPECT_EQ(grid.ny, 9);
  Rng rng(5);
  for (int i = 0; i < 2000; ++i) {
    const Vec2 a(rng.Uniform(kWindow.min.x(), kWindow.max.x()),
                 rng.Uniform(kWindow.min.y(), kWindow.max.y()));
    // Short, long, axis-parallel and boundary segments.
    Vec2 b(rng.Uniform(kWindow.min.x(), kWindow.max.x()),
           rng.Uniform(kWindow.min.y(), kWindow.max.y()));
    if (i % 5 == 1) b = a + 0.05 * (b - a);
    if (i % 5 == 2) b.y() = a.y();
    if (i % 5 == 3) b.x() = kWindow.max.x();
    std::vector<int> visited;
    std::vector<double> enter, exit;
    WalkCells(grid, a, b, [&](int cell, double t0, double t1) {
      visited.push_back(cell);
      enter.push_back(t0);
      exit.push_back(t1);
      return true;
    });
    const std::set<int> expected = CellsByClipping(grid, a, b);
    // Every cell the segment passes through is visited once; the walk may add a cell the
    // segment only grazes at a corner, never one it misses.
    std::set<int> unique(visited.begin(), visited.end());
    ASSERT_EQ(unique.size(), visited.size()) << "a cell visited twice";
    for (int cell : unique)
      ASSERT_TRUE(expected.count(cell)) << "cell " << cell << " is off the segment";
    EXPECT_EQ(unique.size(), expected.size());
    EXPECT_EQ(enter.front(), 0.0);
    EXPECT_EQ(exit.back(), 1.0);
    for (std::size_t k = 1; k < enter.size(); ++k) EXPECT_DOUBLE_EQ(enter[k], exit[k - 1]);
    EXPECT_EQ(visited.front(), grid.CellOf(a));
    EXPECT_EQ(visited.back(), grid.CellOf(b));
  }
}

TEST(WalkCells, ReachesEndsOnGridLinesAndBothCellsAtACorner) {
  const CellGrid grid = CellGrid::Covering(Vec2::Zero(), Vec2::Ones(), 0.25);
  const auto walk = [&](const Vec2& a, const Vec2& b) {
    std::set<int> cells;
    WalkCells(grid, a, b, [&](int cell, double, double) {
      cells.insert(cell);
      return true;
    });
    return cells;
  };
  // b on the vertical line x = 0.5: the cell holding b (column 2) is reached.
  EXPECT_EQ(walk(Vec2(0.1, 0.6), Vec2(0.5, 0.6)), (std::set<int>{8, 9, 10}));
  // Through the corner (0.5, 0.5): both cells beside it are visited as well.
  const std::set<int> diagonal = walk(Vec2(0.3, 0.3), Vec2(0.7, 0.7));
  EXPECT_EQ(diagonal, CellsByClipping(grid, Vec2(0.3, 0.3), Vec2(0.7, 0.7)));
  EXPECT_TRUE(diagonal.count(1 * 4 + 2) && diagonal.count(2 * 4 + 1));
  // Far outside or NaN coordinates are clamped, not undefined.
  EXPECT_EQ(grid.CellOf(Vec2(1e300, -1e300)), 3);
  EXPECT_EQ(grid.CellOf(Vec2(std::nan(""), 0.6)), 8);
}

TEST(WalkCells, StopsWhenAsked) {
  const CellGrid grid = CellGrid::Covering(Vec2::Zero(), Vec2::Ones(), 0.1);
  int visits = 0;
  WalkCells(grid, Vec2(0.05, 0.05), Vec2(0.95, 0.05),
            [&](int, double, double) { return ++visits < 3; });
  EXPECT_EQ(visits, 3);
}

}  // namespace
}  // namespace priormap::prf
