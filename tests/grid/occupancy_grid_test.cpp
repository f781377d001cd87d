// The log-odds occupancy grid: one beam's cells by hand, saturation, a simulated room mapped
// free inside and occupied on its walls, and the ROS map_server pair it is saved as.
#include <cmath>
#include <fstream>
#include <sstream>

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

TEST(OccupancyGrid, RejectsBadOptions) {
  EXPECT_THROW(OccupancyGrid(Box2(Vec2::Zero(), Vec2::Ones()), {.resolution = 0.0}),
               std::invalid_argument);
  EXPECT_THROW(OccupancyGrid(Box2(), {}), std::invalid_argument);
  EXPECT_THROW(OccupancyGrid(Box2(Vec2::Zero(), Vec2::Ones()), {.beam_step = 0}),
               std::invalid_argument);
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
  for (const char* key : {"image: map.pgm", "resolution: 0.1", "origin: [-1.5, 2, 0.0]",
                          "negate: 0", "occupied_thresh: 0.65", "free_thresh: 0.196"})
    EXPECT_NE(yaml.find(key), std::string::npos) << key;
}

}  // namespace
}  // namespace priormap::grid
