// The log-odds occupancy grid: one beam's cells by hand, saturation, the raster of random beams
// and scans against a straightforward reference, a simulated room mapped free inside and
// occupied on its walls, and the ROS map_server pair it is saved as.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <vector>

#include <gtest/gtest.h>

#include <priormap/core/file_io.hpp>
#include <priormap/core/map_server.hpp>
#include <priormap/core/range_sensor.hpp>
#include <priormap/core/scene.hpp>
#include <priormap/core/simulate.hpp>
#include <priormap/grid/occupancy_grid.hpp>

#include "testing/temp_dir.hpp"

namespace priormap::grid {
namespace {

TEST(OccupancyGrid, ABeamClearsItsCellsAndMarksItsEnd) {
  OccupancyGrid grid(Box2(Vec2::Zero(), Vec2(1.0, 1.0)), {.resolution = 0.1});
  ASSERT_EQ(grid.width(), 10);
  grid.InsertBeam(Vec2(0.05, 0.55), Vec2(0.55, 0.55), true);
  // 8-bit log-odds: within half a step (4 / 127 / 2) of the model's values.
  constexpr double kHalfStep = 0.5 * 4.0 / 127.0;
  for (int ix = 0; ix < 5; ++ix) EXPECT_NEAR(grid.LogOdds(ix, 5), -0.4, kHalfStep) << ix;
  EXPECT_NEAR(grid.LogOdds(5, 5), 0.85, kHalfStep);
  EXPECT_FALSE(grid.Observed(6, 5));
  EXPECT_FALSE(grid.Observed(2, 4));
  // A slanted beam visits Bresenham's line: one cell per column, 9 steps from (0, 0) to
  // (9, 4), each within half a cell of the line between the cells' centres.
  grid.InsertBeam(Vec2(0.05, 0.05), Vec2(0.95, 0.42), false);
  int observed = 0;
  for (int iy = 0; iy < 5; ++iy)
    for (int ix = 0; ix < 10; ++ix) {
      if (!grid.Observed(ix, iy)) continue;
      ++observed;
      EXPECT_LE(std::abs(iy - 4.0 * ix / 9.0), 0.5 + 1e-12) << ix << ", " << iy;
    }
  EXPECT_EQ(observed, 9 + 1);
  EXPECT_TRUE(grid.Observed(0, 0));
  EXPECT_TRUE(grid.Observed(9, 4));
}

TEST(OccupancyGrid, SaturatesAtTheLimit) {
  OccupancyGrid grid(Box2(Vec2::Zero(), Vec2(1.0, 1.0)), {.resolution = 0.1});
  for (int i = 0; i < 100; ++i) grid.InsertBeam(Vec2(0.05, 0.55), Vec2(0.55, 0.55), true);
  EXPECT_DOUBLE_EQ(grid.LogOdds(5, 5), 4.0);
  EXPECT_DOUBLE_EQ(grid.LogOdds(1, 5), -4.0);
}

// The grid as the textbook writes it: doubles in a row-major array, NaN for unobserved, every
// beam a Bresenham loop with an error term and a bounds check per cell, saturated with a clamp.
// Cell indices and fixed-point steps are computed as the grid does (that is the definition of
// the grid's cells, not what is under test).
class ReferenceGrid {
 public:
  ReferenceGrid(const Box2& extent, const GridOptions& options)
      : options_(options), origin_(extent.min()), scale_(127.0 / options.log_odds_limit) {
    const Vec2 size = extent.sizes() / options.resolution;
    width_ = std::max(1, static_cast<int>(std::ceil(size.x())));
    height_ = std::max(1, static_cast<int>(std::ceil(size.y())));
    cells_.assign(static_cast<std::size_t>(width_) * height_, kUnobserved);
    hit_ = std::max(1, static_cast<int>(std::lround(options.log_odds_hit * scale_)));
    miss_ = std::min(-1, static_cast<int>(std::lround(options.log_odds_miss * scale_)));
  }

  void InsertBeam(const Vec2& origin, const Vec2& end, bool hit) {
    const double inv = 1.0 / options_.resolution;
    const double x0 = (origin.x() - origin_.x()) * inv, y0 = (origin.y() - origin_.y()) * inv;
    const double x1 = (end.x() - origin_.x()) * inv, y1 = (end.y() - origin_.y()) * inv;
    for (const double c : {x0, y0, x1, y1})
      if (!(std::abs(c) < (1 << 29))) return;
    const long ix = std::lround(std::floor(x0)), iy = std::lround(std::floor(y0));
    const long ex = std::lround(std::floor(x1)), ey = std::lround(std::floor(y1));
    const long adx = std::abs(ex - ix), ady = std::abs(ey - iy);
    const bool x_major = adx >= ady;
    const long major = x_major ? adx : ady, minor = x_major ? ady : adx;
    long error = major / 2, x = ix, y = iy;
    for (long n = 0; n < major; ++n) {
      Add(x, y, miss_);
      error -= minor;
      const bool minor_step = error < 0;
      if (minor_step) error += major;
      if (x_major || minor_step) x += ex > ix ? 1 : -1;
      if (!x_major || minor_step) y += ey > iy ? 1 : -1;
    }
    Add(ex, ey, hit ? hit_ : miss_);
  }

  void Insert(const Scan& scan) {
    if (!scan.pose.IsFinite()) return;
    const double c = std::cos(scan.pose.theta()), s = std::sin(scan.pose.theta());
    for (std::size_t i = 0; i < scan.size(); i += options_.beam_step) {
      double range = scan.ranges[i];
      bool hit = true;
      if (scan.status[i] == BeamStatus::kInvalid) continue;
      if (scan.status[i] == BeamStatus::kMaxRange) {
        if (!options_.max_readings_clear) continue;
        range = std::min(options_.max_range, scan.max_range);
        hit = false;
      } else if (range >= options_.max_range) {  // a max reading, as in the PRF
        if (!options_.max_readings_clear) continue;
        range = options_.max_range;
        hit = false;
      }
      const Vec2 u = UnitVector(scan.angles[i]);
      const Vec2 direction(c * u.x() - s * u.y(), s * u.x() + c * u.y());
      InsertBeam(scan.pose.translation(), scan.pose.translation() + range * direction, hit);
    }
  }

  // NaN where unobserved.
  double LogOdds(int ix, int iy) const {
    const int cell = cells_[static_cast<std::size_t>(iy) * width_ + ix];
    return cell == kUnobserved ? std::numeric_limits<double>::quiet_NaN() : cell / scale_;
  }
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  static constexpr int kUnobserved = -128;

  void Add(long x, long y, int delta) {
    if (x < 0 || y < 0 || x >= width_ || y >= height_) return;
    int& cell = cells_[static_cast<std::size_t>(y) * width_ + x];
    cell = std::clamp((cell == kUnobserved ? 0 : cell) + delta, -127, 127);
  }

  GridOptions options_;
  Vec2 origin_;
  double scale_;
  int width_ = 0, height_ = 0, hit_ = 0, miss_ = 0;
  std::vector<int> cells_;
};

void ExpectSameGrid(const OccupancyGrid& grid, const ReferenceGrid& reference) {
  ASSERT_EQ(grid.width(), reference.width());
  ASSERT_EQ(grid.height(), reference.height());
  const OccupancyRaster raster = grid.Raster();
  int differences = 0;
  for (int iy = 0; iy < grid.height(); ++iy)
    for (int ix = 0; ix < grid.width(); ++ix) {
      const double expected = reference.LogOdds(ix, iy);
      const bool same = std::isnan(expected)
                            ? !grid.Observed(ix, iy) && std::isnan(raster.probability(iy, ix))
                            : grid.Observed(ix, iy) && grid.LogOdds(ix, iy) == expected &&
                                  raster.probability(iy, ix) == 1.0 / (1.0 + std::exp(-expected));
      if (!same && ++differences <= 5)
        ADD_FAILURE() << "cell (" << ix << ", " << iy << "): " << grid.LogOdds(ix, iy)
                      << (grid.Observed(ix, iy) ? "" : " (unobserved)") << ", reference "
                      << expected;
    }
  EXPECT_EQ(differences, 0);
}

TEST(OccupancyGrid, RandomBeamsGiveTheReferenceRaster) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> inside(0.0, 6.0), around(-2.0, 8.0);
  for (const double resolution : {0.05, 0.1, 0.37}) {
    const GridOptions options{.resolution = resolution, .log_odds_limit = 2.5};
    const Box2 extent(Vec2(0.0, 0.0), Vec2(6.0, 4.5));
    OccupancyGrid grid(extent, options);
    ReferenceGrid reference(extent, options);
    for (int beam = 0; beam < 3000; ++beam) {
      // Origins inside and ends anywhere around the grid, or both ends around it.
      const bool from_inside = beam % 3 != 0;
      const Vec2 origin(from_inside ? inside(rng) : around(rng),
                        from_inside ? 0.75 * inside(rng) : around(rng));
      const Vec2 end(around(rng), around(rng));
      const bool hit = beam % 2 == 0;
      grid.InsertBeam(origin, end, hit);
      reference.InsertBeam(origin, end, hit);
    }
    ExpectSameGrid(grid, reference);
  }
}

TEST(OccupancyGrid, RandomScansGiveTheReferenceRaster) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> position(0.5, 9.5), heading(-M_PI, M_PI), range(0.0, 12.0);
  for (const bool clear : {true, false}) {
    const GridOptions options{.resolution = 0.05, .max_range = 8.0, .max_readings_clear = clear};
    const Box2 extent(Vec2(0.0, 0.0), Vec2(10.0, 10.0));
    OccupancyGrid grid(extent, options);
    ReferenceGrid reference(extent, options);
    for (int k = 0; k < 40; ++k) {
      Scan scan;
      scan.pose = Se2(position(rng), position(rng), heading(rng));
      scan.angles = EvenlySpacedAngles(181, -M_PI / 2, M_PI / 2);
      // Sensors that reach beyond the insertion range and one that stops short of it.
      scan.max_range = k % 2 == 0 ? 10.0 : 6.0;
      scan.min_range = 0.1;
      for (std::size_t i = 0; i < scan.angles.size(); ++i) {
        // Returns within and beyond the insertion range, max-range and unusable readings.
        const int kind = std::uniform_int_distribution<int>(0, 9)(rng);
        scan.ranges.push_back(kind == 0   ? scan.max_range
                              : kind == 1 ? 0.05
                              : kind == 2 ? std::numeric_limits<double>::quiet_NaN()
                                          : range(rng));
      }
      scan.sigma.assign(scan.ranges.size(), 0.01);
      scan.ClassifyAll();
      grid.Insert(scan);
      reference.Insert(scan);
    }
    ExpectSameGrid(grid, reference);
  }
}

TEST(OccupancyGrid, RejectsBadOptions) {
  EXPECT_THROW(OccupancyGrid(Box2(Vec2::Zero(), Vec2::Ones()), {.resolution = 0.0}),
               std::invalid_argument);
  EXPECT_THROW(OccupancyGrid(Box2(), {}), std::invalid_argument);
  EXPECT_THROW(OccupancyGrid(Box2(Vec2::Zero(), Vec2::Ones()), {.beam_step = 0}),
               std::invalid_argument);
  // An insertion range of 0 would turn every return into a miss at the sensor, a negative one
  // draw beams backwards, NaN make every return a hit at any range; an infinite one has no end
  // to clear a max reading to. Cells of infinite size, or a margin that is not a length, make
  // a grid of one cell or none.
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const GridOptions& bad :
       {GridOptions{.max_range = 0.0}, GridOptions{.max_range = -5.0},
        GridOptions{.max_range = nan}, GridOptions{.max_range = inf},
        GridOptions{.resolution = inf}, GridOptions{.margin = nan}, GridOptions{.margin = -1.0}})
    EXPECT_THROW(OccupancyGrid(Box2(Vec2::Zero(), Vec2::Ones()), bad), std::invalid_argument)
        << "max_range " << bad.max_range << ", resolution " << bad.resolution << ", margin "
        << bad.margin;
}

TEST(OccupancyGrid, AReadingAtTheInsertionRangeIsAMaxReadingAsInThePrf) {
  // The PRF (SelectBeams) and Scan::ClassifyAll take a reading at or above R for no return,
  // and the study compares the two at equal data.
  const GridOptions options{.resolution = 0.1, .max_range = 5.0};
  OccupancyGrid grid(Box2(Vec2(-1.0, -1.0), Vec2(6.0, 6.0)), options);
  Scan scan;
  scan.pose = Se2(0.05, 0.05, 0.0);
  scan.angles = {0.0, M_PI / 2};
  scan.ranges = {5.0, 4.0};
  scan.sigma = {0.01, 0.01};
  scan.max_range = 30.0;
  scan.ClassifyAll();
  ASSERT_EQ(grid.Insert(scan), 2u);
  // The end cells: (5.05, 0.05) cleared, (0.05, 4.05) a hit.
  EXPECT_LT(grid.LogOdds(60, 10), 0.0);
  EXPECT_GT(grid.LogOdds(10, 50), 0.0);
}

TEST(OccupancyGrid, WithoutClearingAReturnAtTheInsertionRangeIsLeftOutLikeAMaxReading) {
  // A return at or beyond R is a max reading (as in the PRF): with max_readings_clear off it
  // clears nothing, as the sensor's own max readings do not.
  const GridOptions options{.resolution = 0.1, .max_range = 5.0, .max_readings_clear = false};
  OccupancyGrid grid(Box2(Vec2(-1.0, -1.0), Vec2(8.0, 8.0)), options);
  Scan scan;
  scan.pose = Se2(0.05, 0.05, 0.0);
  scan.angles = {0.0, M_PI / 4, M_PI / 2};
  scan.ranges = {5.0, 30.0, 4.0};  // a return at R, a max reading, a return within R
  scan.sigma = {0.01, 0.01, 0.01};
  scan.max_range = 30.0;
  scan.ClassifyAll();
  ASSERT_EQ(scan.status[0], BeamStatus::kValid);
  EXPECT_EQ(grid.Insert(scan), 1u);
  // Along x from the sensor's cell (which the hit's beam clears) to R.
  for (int ix = 11; ix <= 60; ++ix) EXPECT_FALSE(grid.Observed(ix, 10)) << "cell " << ix;
  EXPECT_GT(grid.LogOdds(10, 50), 0.0);
  // Its extent holds no beam to R either.
  Log log;
  log.scans = {scan};
  EXPECT_LT(OccupancyGrid::ExtentOf(log, 0, 1, options).max().x(), 5.0);
}

TEST(OccupancyGrid, ABeamStepInsertsTheBeamsThePrfSelects) {
  const Scene scene = *BuiltinScene("rectangle");
  const RangeSensor sensor = *RangeSensor::Preset("lms200");
  const Log log = SimulateLog(scene, sensor, TrajectoryFromWaypoints(scene.waypoints, 0.5, 1.0), 3);
  const Scan& scan = log.scans.at(0);
  const GridOptions every{.resolution = 0.05};
  const GridOptions third{.resolution = 0.05, .beam_step = 3};
  OccupancyGrid all(OccupancyGrid::ExtentOf(log, 0, 1, every), every);
  OccupancyGrid some(OccupancyGrid::ExtentOf(log, 0, 1, third), third);
  std::size_t usable = 0, usable_thirds = 0;
  for (std::size_t i = 0; i < scan.size(); ++i) {
    if (scan.status[i] == BeamStatus::kInvalid) continue;
    ++usable;
    if (i % 3 == 0) ++usable_thirds;
  }
  EXPECT_EQ(all.Insert(scan), usable);
  EXPECT_EQ(some.Insert(scan), usable_thirds);
  EXPECT_LT(usable_thirds, usable / 2);
}

TEST(OccupancyGrid, MapsASimulatedRoomFreeInsideAndOccupiedOnItsWalls) {
  const Scene scene = *BuiltinScene("rectangle");
  const RangeSensor sensor = *RangeSensor::Preset("lms200");
  const Log log = SimulateLog(scene, sensor, TrajectoryFromWaypoints(scene.waypoints, 0.5, 1.0), 3);
  const GridOptions options{.resolution = 0.05};
  OccupancyGrid grid(OccupancyGrid::ExtentOf(log, 0, log.scans.size(), options), options);
  for (const Scan& scan : log.scans) grid.Insert(scan);
  const OccupancyRaster raster = grid.Raster();
  // Every scan's true end points lie in occupied cells (or next to one: the end may sit on a
  // cell's border); the midpoints of the beams lie in free cells.
  int ends = 0, occupied_ends = 0, middles = 0, free_middles = 0;
  const auto probability = [&](const Vec2& p) {
    const Vec2 c = (p - raster.origin) / raster.resolution;
    return raster.probability(static_cast<int>(c.y()), static_cast<int>(c.x()));
  };
  for (const Scan& scan : log.scans) {
    for (std::size_t i = 0; i < scan.size(); i += 3) {
      if (scan.status[i] != BeamStatus::kValid) continue;
      const Vec2 d = UnitVector(scan.pose.theta() + scan.angles[i]);
      ++ends;
      double best = 0.0;
      for (double back : {0.0, 0.02, -0.02})
        best = std::max(best, probability(scan.pose.translation() + (scan.ranges[i] + back) * d));
      occupied_ends += best > 0.5 ? 1 : 0;
      ++middles;
      free_middles += probability(scan.pose.translation() + 0.5 * scan.ranges[i] * d) < 0.5 ? 1 : 0;
    }
  }
  ASSERT_GT(ends, 1000);
  EXPECT_GT(occupied_ends, 0.97 * ends);
  EXPECT_GT(free_middles, 0.99 * middles);
}

TEST(MapServer, WritesThePgmTopRowFirstAndTheYamlKeys) {
  testing::TempDir dir;
  OccupancyRaster raster;
  raster.probability.resize(2, 3);
  raster.probability << 0.0, 1.0, std::nan(""),  // bottom row
      0.5, 0.25, 0.75;
  raster.origin = Vec2(-1.5, 2.0);
  raster.resolution = 0.1;
  WriteMapServerMap(dir.path() / "map.yaml", raster);
  const std::string pgm = testing::ReadAll(dir.path() / "map.pgm");
  const std::string header = "P5\n3 2\n255\n";
  ASSERT_EQ(pgm.size(), header.size() + 6);
  EXPECT_EQ(pgm.substr(0, header.size()), header);
  const auto pixel = [&](int k) { return static_cast<unsigned char>(pgm[header.size() + k]); };
  EXPECT_EQ(pixel(0), 128);  // top row: 0.5, 0.25, 0.75
  EXPECT_EQ(pixel(1), 191);
  EXPECT_EQ(pixel(2), 64);
  EXPECT_EQ(pixel(3), 255);  // bottom row: free, occupied, unknown
  EXPECT_EQ(pixel(4), 0);
  EXPECT_EQ(pixel(5), 205);
  const std::string yaml = testing::ReadAll(dir.path() / "map.yaml");
  for (const char* key : {"image: map.pgm", "resolution: 0.1", "origin: [-1.5, 2.0, 0.0]",
                          "negate: 0", "occupied_thresh: 0.65", "free_thresh: 0.196"})
    EXPECT_NE(yaml.find(key), std::string::npos) << key;
}

}  // namespace
}  // namespace priormap::grid
