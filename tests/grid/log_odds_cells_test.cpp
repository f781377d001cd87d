// The grid's cells against straightforward references: a clamp per update, and the textbook
// Bresenham loop (error term, a bounds check per cell) over a plain row-major array, on random
// lines in and around random rasters, on lines long enough to leave the accumulator's exact
// range, and on lines from far outside.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include <climits>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <priormap/grid/log_odds_cells.hpp>

namespace priormap::grid {
namespace {

constexpr int kUnobserved = LogOddsCells::kUnobserved;

int Clamped(int state, int delta, int limit) {
  return std::clamp((state == kUnobserved ? 0 : state) + delta, -limit, limit);
}

// Row-major cells, each update a clamp.
class ReferenceCells {
 public:
  ReferenceCells(int width, int height)
      : width_(width),
        height_(height),
        cells_(static_cast<std::size_t>(width) * height, kUnobserved) {}

  int Get(int ix, int iy) const { return cells_[Index(ix, iy)]; }

  void Apply(std::int64_t ix, std::int64_t iy, int delta, int limit) {
    if (ix < 0 || iy < 0 || ix >= width_ || iy >= height_) return;
    int& cell = cells_[Index(static_cast<int>(ix), static_cast<int>(iy))];
    cell = Clamped(cell, delta, limit);
  }

  // Bresenham's line as the grid defines it: one cell per step along the major axis, the minor
  // one advanced when the error term, starting at major / 2, goes below zero.
  void TraceLine(std::int64_t x0, std::int64_t y0, std::int64_t x1, std::int64_t y1, int along,
                 int last, int limit) {
    const std::int64_t adx = std::abs(x1 - x0), ady = std::abs(y1 - y0);
    const int sx = x1 > x0 ? 1 : -1, sy = y1 > y0 ? 1 : -1;
    const bool x_major = adx >= ady;
    const std::int64_t major = x_major ? adx : ady, minor = x_major ? ady : adx;
    std::int64_t error = major / 2, x = x0, y = y0;
    for (std::int64_t n = 0; n < major; ++n) {
      Apply(x, y, along, limit);
      error -= minor;
      const bool minor_step = error < 0;
      if (minor_step) error += major;
      x += x_major ? sx : (minor_step ? sx : 0);
      y += x_major ? (minor_step ? sy : 0) : sy;
    }
    Apply(x1, y1, last, limit);
  }

 private:
  std::size_t Index(int ix, int iy) const {
    return static_cast<std::size_t>(iy) * static_cast<std::size_t>(width_) +
           static_cast<std::size_t>(ix);
  }
  int width_, height_;
  std::vector<int> cells_;
};

void ExpectSameCells(const LogOddsCells& cells, const ReferenceCells& reference) {
  int differences = 0;
  for (int iy = 0; iy < cells.height(); ++iy)
    for (int ix = 0; ix < cells.width(); ++ix)
      if (cells.Get(ix, iy) != reference.Get(ix, iy) && ++differences <= 5)
        ADD_FAILURE() << "cell (" << ix << ", " << iy << "): " << int{cells.Get(ix, iy)}
                      << ", reference " << reference.Get(ix, iy);
  EXPECT_EQ(differences, 0);
}

TEST(CellUpdate, IsAClampThatTakesUnobservedForZero) {
  for (const int limit : {1, 50, 127})
    for (int delta = -limit; delta <= limit; ++delta) {
      const CellUpdate update(delta, limit);
      for (int state = INT8_MIN; state <= INT8_MAX; ++state)
        ASSERT_EQ(update(static_cast<std::int8_t>(state)), Clamped(state, delta, limit))
            << "state " << state << ", delta " << delta << ", limit " << limit;
    }
}

TEST(CellUpdate, RejectsBadLimits) {
  EXPECT_THROW(CellUpdate(1, 0), std::invalid_argument);
  EXPECT_THROW(CellUpdate(1, 128), std::invalid_argument);
  EXPECT_THROW(CellUpdate(-6, 5), std::invalid_argument);
}

TEST(LogOddsCells, StartUnobservedInRastersOfAnyShape) {
  for (const auto& [w, h] : {std::pair{1, 1}, {7, 9}, {8, 8}, {17, 3}}) {
    const LogOddsCells cells(w, h);
    for (int iy = 0; iy < h; ++iy)
      for (int ix = 0; ix < w; ++ix) EXPECT_EQ(cells.Get(ix, iy), kUnobserved);
  }
  EXPECT_THROW(LogOddsCells(0, 5), std::invalid_argument);
  EXPECT_THROW(LogOddsCells(70000, 70000), std::invalid_argument);
}

TEST(LogOddsCells, EveryCellHasItsOwnPlace) {
  LogOddsCells cells(19, 13);
  ReferenceCells reference(19, 13);
  int delta = 0;
  for (int iy = 0; iy < 13; ++iy)
    for (int ix = 0; ix < 19; ++ix) {
      delta = delta % 100 + 1;
      cells.Apply(ix, iy, CellUpdate(delta, 127));
      reference.Apply(ix, iy, delta, 127);
    }
  ExpectSameCells(cells, reference);
}

TEST(LogOddsCells, ColumnsPastTwoToThe25HaveTheirOwnPlaces) {
  // A column's offset, ix / 8 * 64 + ix % 8, passes INT_MAX from column 2^25 on: computed in
  // int it overflowed (undefined behaviour, caught by the asan preset's UBSan). Such a raster
  // is a grid 1,700 km long at 5 cm, or 34,000 km at 1 m (about 0.4 GB here).
  const int width = (1 << 25) + 24;
  LogOddsCells cells(width, 1);
  const CellUpdate hit(5, 127), miss(-3, 127);
  cells.Apply(width - 1, 0, hit);
  cells.Apply(width - 9, 0, miss);
  cells.Apply(0, 0, miss);
  cells.Apply(1 << 25, 0, hit);
  cells.Apply(1 << 25, 0, hit);
  EXPECT_EQ(cells.Get(width - 1, 0), 5);
  EXPECT_EQ(cells.Get(width - 9, 0), -3);
  EXPECT_EQ(cells.Get(0, 0), -3);
  EXPECT_EQ(cells.Get(1 << 25, 0), 10);
  EXPECT_EQ(cells.Get((1 << 25) - 1, 0), kUnobserved);
  EXPECT_EQ(cells.Get(width - 2, 0), kUnobserved);
  // A line along the row from the first column past 2^25.
  cells.TraceLine((1 << 25) - 4, 0, (1 << 25) + 4, 0, miss, hit);
  EXPECT_EQ(cells.Get((1 << 25) - 1, 0), -3);
  EXPECT_EQ(cells.Get(1 << 25, 0), 7);
  EXPECT_EQ(cells.Get((1 << 25) + 4, 0), 5);
}

TEST(LogOddsCells, RandomLinesMatchTheTextbookBresenham) {
  std::mt19937 rng(20261124);
  for (int raster = 0; raster < 60; ++raster) {
    const int width = std::uniform_int_distribution<int>(1, 90)(rng);
    const int height = std::uniform_int_distribution<int>(1, 90)(rng);
    LogOddsCells cells(width, height);
    ReferenceCells reference(width, height);
    // Ends mostly inside, some around the raster and some far from it.
    const auto coordinate = [&](int size) {
      const int kind = std::uniform_int_distribution<int>(0, 9)(rng);
      if (kind < 7) return std::uniform_int_distribution<int>(0, size - 1)(rng);
      if (kind < 9) return std::uniform_int_distribution<int>(-20, size + 20)(rng);
      return std::uniform_int_distribution<int>(-3000, 3000)(rng);
    };
    for (int line = 0; line < 300; ++line) {
      const int x0 = coordinate(width), y0 = coordinate(height);
      const int x1 = coordinate(width), y1 = coordinate(height);
      const int limit = std::uniform_int_distribution<int>(1, 127)(rng);
      const int along = std::uniform_int_distribution<int>(-limit, limit)(rng);
      const int last = std::uniform_int_distribution<int>(-limit, limit)(rng);
      cells.TraceLine(x0, y0, x1, y1, CellUpdate(along, limit), CellUpdate(last, limit));
      reference.TraceLine(x0, y0, x1, y1, along, last, limit);
    }
    ExpectSameCells(cells, reference);
    if (::testing::Test::HasFailure()) return;
  }
}

TEST(LogOddsCells, LinesAcrossTheAccumulatorsExactRangeMatchTheTextbookBresenham) {
  // Up to 65,535 steps the minor coordinate comes from a fixed-point accumulator, beyond from
  // the error term: lines of both kinds, every slope with a minor extent below 48 (the
  // accumulator's rounding error grows along the line, so long lines are its hardest case).
  constexpr int kWidth = 65600, kHeight = 48;
  LogOddsCells cells(kWidth, kHeight);
  ReferenceCells reference(kWidth, kHeight);
  int delta = 0;
  for (const int major : {65534, 65535, 65536, 65599})
    for (int minor = 0; minor < kHeight; ++minor) {
      delta = delta % 120 + 1;
      const CellUpdate update(delta % 2 == 0 ? delta : -delta, 127);
      const int value = delta % 2 == 0 ? delta : -delta;
      // Rightwards from the left edge and leftwards from the right end, upwards and downwards.
      const int y_low = 0, y_high = minor;
      cells.TraceLine(0, y_low, major, y_high, update, update);
      reference.TraceLine(0, y_low, major, y_high, value, value, 127);
      cells.TraceLine(major, y_high, 0, y_low, update, update);
      reference.TraceLine(major, y_high, 0, y_low, value, value, 127);
      cells.TraceLine(kWidth - 1 - major, kHeight - 1, kWidth - 1, kHeight - 1 - minor, update,
                      update);
      reference.TraceLine(kWidth - 1 - major, kHeight - 1, kWidth - 1, kHeight - 1 - minor, value,
                          value, 127);
    }
  ExpectSameCells(cells, reference);
}

TEST(LogOddsCells, LinesFromFarOutsideOnlyTouchTheirCellsInside) {
  LogOddsCells cells(40, 30);
  ReferenceCells reference(40, 30);
  const CellUpdate miss(-7, 127), hit(9, 127);
  // Horizontal and vertical through the raster, from and to the ends of the int range: the
  // walk is clipped to the raster, so this is fast.
  cells.TraceLine(INT_MIN, 5, INT_MAX, 5, miss, hit);
  for (int ix = 0; ix < 40; ++ix) reference.Apply(ix, 5, -7, 127);
  cells.TraceLine(12, INT_MAX, 12, INT_MIN, miss, hit);
  for (int iy = 0; iy < 30; ++iy) reference.Apply(12, iy, -7, 127);
  // Ending inside: the end gets its own update.
  cells.TraceLine(-1000000000, 20, 25, 20, miss, hit);
  for (int ix = 0; ix < 25; ++ix) reference.Apply(ix, 20, -7, 127);
  reference.Apply(25, 20, 9, 127);
  // Missing the raster entirely.
  cells.TraceLine(-1000000000, -50, 1000000000, -49, miss, hit);
  cells.TraceLine(INT_MIN, INT_MIN, INT_MAX, INT_MIN + 5, miss, hit);
  // Corner to corner of the int range, one step short of the diagonal: Bresenham's formula
  // floor((k minor + major - 1 - major / 2) / major) puts it on (x, x - 1) here.
  cells.TraceLine(INT_MIN, INT_MIN, INT_MAX, INT_MAX - 1, miss, hit);
  for (int ix = 1; ix <= 30; ++ix) reference.Apply(ix, ix - 1, -7, 127);
  ExpectSameCells(cells, reference);
  // A diagonal from far away, against the textbook loop run over the part near the raster:
  // the clipped walk must resume Bresenham's state exactly.
  LogOddsCells diagonal(40, 30);
  ReferenceCells diagonal_reference(40, 30);
  const int x0 = -700001, y0 = -300000, x1 = 39, y1 = 28;
  diagonal.TraceLine(x0, y0, x1, y1, miss, hit);
  diagonal_reference.TraceLine(x0, y0, x1, y1, -7, 9, 127);
  ExpectSameCells(diagonal, diagonal_reference);
}

TEST(LogOddsCells, RasterOfGivesTheLogisticOfTheStates) {
  LogOddsCells cells(3, 2);
  cells.Apply(0, 0, CellUpdate(127, 127));
  cells.Apply(1, 0, CellUpdate(-40, 127));
  cells.Apply(2, 1, CellUpdate(0, 127));
  const OccupancyRaster raster = RasterOf(cells, Vec2(-1.0, 2.0), 0.1, 127.0 / 4.0);
  EXPECT_EQ(raster.origin, Vec2(-1.0, 2.0));
  EXPECT_EQ(raster.resolution, 0.1);
  ASSERT_EQ(raster.probability.rows(), 2);
  ASSERT_EQ(raster.probability.cols(), 3);
  EXPECT_DOUBLE_EQ(raster.probability(0, 0), 1.0 / (1.0 + std::exp(-4.0)));
  EXPECT_DOUBLE_EQ(raster.probability(0, 1), 1.0 / (1.0 + std::exp(40.0 * 4.0 / 127.0)));
  EXPECT_DOUBLE_EQ(raster.probability(1, 2), 0.5);
  EXPECT_TRUE(std::isnan(raster.probability(1, 0)));
}

TEST(LogOddsCells, CellsCoveringRoundEachSideUpToWholeCells) {
  const LogOddsCells cells = CellsCovering(Box2(Vec2(-1.0, 2.0), Vec2(1.01, 2.5)), 0.1);
  EXPECT_EQ(cells.width(), 21);  // 2.01 m: 20 cells and a sliver
  EXPECT_EQ(cells.height(), 5);
  const LogOddsCells line = CellsCovering(Box2(Vec2(0.0, 0.0), Vec2(3.0, 0.0)), 0.5);
  EXPECT_EQ(line.width(), 6);
  EXPECT_EQ(line.height(), 1);  // a flat extent still gets a row
  EXPECT_THROW((void)CellsCovering(Box2(), 0.1), std::invalid_argument);
  // Not finite: one cell at a NaN origin, or a size that means nothing.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_THROW((void)CellsCovering(Box2(Vec2(nan, 0.0), Vec2(1.0, 1.0)), 0.1),
               std::invalid_argument);
  EXPECT_THROW((void)CellsCovering(Box2(Vec2(0.0, 0.0), Vec2(1.0, inf)), 0.1),
               std::invalid_argument);
  EXPECT_THROW((void)CellsCovering(Box2(Vec2(0.0, 0.0), Vec2(1.0, 1.0)), inf),
               std::invalid_argument);
  EXPECT_THROW((void)CellsCovering(Box2(Vec2(0.0, 0.0), Vec2(1e4, 1e4)), 0.1),
               std::invalid_argument);  // 1e10 cells
  // 3e9 cells in one row: under the 4e9 the offsets address, but wider than an int. Refused
  // with the advice, not after casting the width to an int.
  try {
    (void)CellsCovering(Box2(Vec2(0.0, 0.0), Vec2(3e9, 0.0)), 1.0, 4e9);
    ADD_FAILURE() << "a row of 3e9 cells was accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_THAT(error.what(), ::testing::HasSubstr("3e+09 x 1 cells, a side longer than"));
  }
}

TEST(LogOddsCells, LogOddsOfAnUnobservedCellIsEvenOdds) {
  EXPECT_EQ(LogOddsOf(kUnobserved, 127.0 / 4.0), 0.0);
  EXPECT_DOUBLE_EQ(LogOddsOf(127, 127.0 / 4.0), 4.0);
  EXPECT_DOUBLE_EQ(LogOddsOf(-40, 127.0 / 4.0), -40.0 * 4.0 / 127.0);
}

}  // namespace
}  // namespace priormap::grid
