// The sonar occupancy grid: one cone is free before its arc, occupied on it and unobserved
// elsewhere; max readings clear their cones; rings are inserted reading by reading; and on a
// simulated room the grid calls the middle free and the walls occupied in part (specular
// misses clear the rest) where it saw them.
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include <priormap/core/scene.hpp>
#include <priormap/core/sonar_simulate.hpp>
#include <priormap/grid/sonar_grid.hpp>

namespace priormap::grid {
namespace {

// The cell holding point p.
std::pair<int, int> CellAt(const SonarGrid& grid, const Vec2& p) {
  const Vec2 q = (p - grid.origin()) / grid.options().resolution;
  return {static_cast<int>(std::floor(q.x())), static_cast<int>(std::floor(q.y()))};
}

double LogOddsAt(const SonarGrid& grid, const Vec2& p) {
  const auto [ix, iy] = CellAt(grid, p);
  return grid.LogOdds(ix, iy);
}

bool ObservedAt(const SonarGrid& grid, const Vec2& p) {
  const auto [ix, iy] = CellAt(grid, p);
  return grid.Observed(ix, iy);
}

TEST(SonarGrid, AConeIsFreeBeforeItsArcOccupiedOnItAndUnknownElsewhere) {
  SonarGrid grid(Box2(Vec2(-1, -3), Vec2(5, 3)), SonarGridOptions{});
  grid.InsertCone(Vec2(0.012, 0.013), 0.0, 0.17, 3.0, true);
  EXPECT_LT(LogOddsAt(grid, Vec2(1.5, 0.0)), 0.0);    // inside, before the arc
  EXPECT_LT(LogOddsAt(grid, Vec2(2.0, 0.3)), 0.0);    // inside, off the axis
  EXPECT_GT(LogOddsAt(grid, Vec2(3.0, 0.0)), 0.0);    // on the arc
  EXPECT_GT(LogOddsAt(grid, Vec2(2.96, 0.45)), 0.0);  // on the arc, near the cone's side
  EXPECT_FALSE(ObservedAt(grid, Vec2(3.5, 0.0)));     // beyond
  EXPECT_FALSE(ObservedAt(grid, Vec2(1.5, 1.0)));     // beside the cone
  EXPECT_FALSE(ObservedAt(grid, Vec2(-0.5, 0.0)));    // behind the apex
  const OccupancyRaster raster = grid.Raster();
  const auto [ix, iy] = CellAt(grid, Vec2(3.5, 0.0));
  EXPECT_TRUE(std::isnan(raster.probability(iy, ix)));
  const auto [ax, ay] = CellAt(grid, Vec2(3.0, 0.0));
  EXPECT_GT(raster.probability(ay, ax), 0.5);
}

TEST(SonarGrid, AMaxReadingClearsItsConeAndNothingIsOccupied) {
  SonarGridOptions options;
  options.max_range = 2.0;
  SonarGrid grid(Box2(Vec2(-1, -3), Vec2(5, 3)), options);
  Scan ring;
  ring.pose = Se2(0.01, 0.01, 0.0);
  ring.angles = {0.0, std::numbers::pi / 2};
  ring.ranges = {5.0, std::nan("")};
  ring.sigma = {0.01, 0.01};
  ring.max_range = 5.0;
  ring.ClassifyAll();
  ring.sonar.emplace();
  EXPECT_EQ(grid.Insert(ring), 1u);  // the NaN is skipped
  EXPECT_LT(LogOddsAt(grid, Vec2(1.9, 0.0)), 0.0);
  EXPECT_FALSE(ObservedAt(grid, Vec2(2.2, 0.0)));  // beyond the insertion range
  EXPECT_FALSE(ObservedAt(grid, Vec2(0.0, 1.0)));
  for (int iy = 0; iy < grid.height(); ++iy)
    for (int ix = 0; ix < grid.width(); ++ix) EXPECT_LE(grid.LogOdds(ix, iy), 0.0);
  // A laser scan is not a ring.
  Scan laser = ring;
  laser.sonar.reset();
  EXPECT_EQ(grid.Insert(laser), 0u);
}

TEST(SonarGrid, AMaxReadingClearsNoFurtherThanItsSensorReaches) {
  SonarGrid grid(Box2(Vec2(-1, -3), Vec2(5, 3)), SonarGridOptions{});  // inserts up to 5 m
  Scan ring;
  ring.pose = Se2(0.01, 0.01, 0.0);
  ring.angles = {0.0};
  ring.ranges = {2.0};
  ring.sigma = {0.01};
  ring.max_range = 2.0;
  ring.ClassifyAll();
  ring.sonar.emplace();
  ASSERT_EQ(grid.Insert(ring), 1u);
  EXPECT_LT(LogOddsAt(grid, Vec2(1.9, 0.0)), 0.0);
  EXPECT_FALSE(ObservedAt(grid, Vec2(2.2, 0.0)));
  EXPECT_FALSE(ObservedAt(grid, Vec2(4.0, 0.0)));
  Log log;
  log.scans = {ring};  // its extent, 1 m of margin included, stops short of 5 m too
  EXPECT_LT(SonarGrid::ExtentOf(log, 0, 1, SonarGridOptions{}).max().x(), 3.1);
}

TEST(SonarGrid, OnASimulatedRoomTheMiddleIsFreeAndTheWallsOftenOccupied) {
  const Scene scene = *BuiltinScene("square");  // walls at x, y = ±2
  const SonarSensor sensor = *SonarSensor::Preset("pioneer16");
  const auto trajectory = TrajectoryFromWaypoints(scene.waypoints, 0.2, 2.0);
  const Log log = SimulateSonarLog(scene, sensor, trajectory, 3);
  const SonarGridOptions options;
  const Box2 extent = SonarGrid::ExtentOf(log, 0, log.scans.size(), options);
  EXPECT_TRUE(extent.contains(scene.Bounds()));
  SonarGrid grid(extent, options);
  std::size_t inserted = 0;
  for (const Scan& ring : log.scans) inserted += grid.Insert(ring);
  EXPECT_GT(inserted, log.scans.size() * 8);
  // Cells on the walls (centre within a cell of a wall) and cells well inside, seen.
  int wall_seen = 0, wall_occupied = 0, middle_seen = 0, middle_free = 0;
  const double res = options.resolution;
  for (int iy = 0; iy < grid.height(); ++iy) {
    for (int ix = 0; ix < grid.width(); ++ix) {
      if (!grid.Observed(ix, iy)) continue;
      const Vec2 c = grid.origin() + res * Vec2(ix + 0.5, iy + 0.5);
      const double inside = 2.0 - c.cwiseAbs().maxCoeff();  // distance to the walls, inside
      if (std::abs(inside) < res) {
        ++wall_seen;
        wall_occupied += grid.LogOdds(ix, iy) > 0.0;
      } else if (inside > 0.5) {
        ++middle_seen;
        middle_free += grid.LogOdds(ix, iy) < 0.0;
      }
    }
  }
  // The specular misses clear parts of the walls (max readings free their whole cone: the
  // grid's known weakness with sonar, Paskin & Thrun Sec. 1.2), so the walls are occupied only
  // in part, but far more often than the middle.
  EXPECT_GT(wall_seen, 100);
  EXPECT_GT(wall_occupied, 0.3 * wall_seen);
  EXPECT_GT(middle_seen, 1000);
  EXPECT_GT(middle_free, 0.97 * middle_seen);
}

// A cone's cells as the model defines them, computed another way than the grid does (polar
// coordinates of every centre by atan2 and hypot, over the whole raster): free before z - α/2,
// occupied within α/2 of z, and, when no centre lies on the arc, the cell holding the echo's
// point on the axis occupied, as a laser beam's end cell is. Centres within 1e-9 of the cone's
// sides or of the arc's radii could go either way in floating point and are not compared.
struct ConeCase {
  Vec2 apex;
  double axis, half, range;
  bool hit;
};

void ExpectReferenceCone(const SonarGridOptions& options, const Box2& extent, const ConeCase& c) {
  SonarGrid grid(extent, options);
  grid.InsertCone(c.apex, c.axis, c.half, c.range, c.hit);
  const double half_arc = options.arc_thickness / 2.0;
  const double free_until = c.hit ? c.range - half_arc : c.range;
  const double reach = c.hit ? c.range + half_arc : c.range;
  enum class Kind { kUnobserved, kFree, kOccupied, kEither };
  std::vector<Kind> expected(static_cast<std::size_t>(grid.width()) * grid.height());
  bool arc_has_centre = false;
  for (int iy = 0; iy < grid.height(); ++iy)
    for (int ix = 0; ix < grid.width(); ++ix) {
      const Vec2 d = grid.origin() + options.resolution * Vec2(ix + 0.5, iy + 0.5) - c.apex;
      const double r = std::hypot(d.x(), d.y());
      const double off_axis =
          std::abs(std::remainder(std::atan2(d.y(), d.x()) - c.axis, 2.0 * std::numbers::pi));
      const double side = std::min(c.half, std::numbers::pi);
      const bool ambiguous = std::abs(off_axis - side) < 1e-9 || std::abs(r - free_until) < 1e-9 ||
                             std::abs(r - reach) < 1e-9;
      Kind kind = Kind::kUnobserved;
      // The apex itself is in its cone, in every direction.
      if ((off_axis <= side || r == 0.0) && r <= reach)
        kind = r < free_until ? Kind::kFree : c.hit ? Kind::kOccupied : Kind::kUnobserved;
      arc_has_centre |= kind == Kind::kOccupied || (ambiguous && c.hit);
      expected[static_cast<std::size_t>(iy) * grid.width() + ix] = ambiguous ? Kind::kEither : kind;
    }
  if (c.hit && !arc_has_centre) {
    const Vec2 echo = (c.apex + c.range * UnitVector(c.axis) - grid.origin()) / options.resolution;
    const int ex = static_cast<int>(std::floor(echo.x())),
              ey = static_cast<int>(std::floor(echo.y()));
    if (ex >= 0 && ey >= 0 && ex < grid.width() && ey < grid.height())
      expected[static_cast<std::size_t>(ey) * grid.width() + ex] = Kind::kOccupied;
  }
  int differences = 0;
  for (int iy = 0; iy < grid.height(); ++iy)
    for (int ix = 0; ix < grid.width(); ++ix) {
      const Kind want = expected[static_cast<std::size_t>(iy) * grid.width() + ix];
      const Kind got = !grid.Observed(ix, iy)     ? Kind::kUnobserved
                       : grid.LogOdds(ix, iy) < 0 ? Kind::kFree
                                                  : Kind::kOccupied;
      if (want != Kind::kEither && want != got && ++differences <= 3)
        ADD_FAILURE() << "cell (" << ix << ", " << iy << ") is " << static_cast<int>(got)
                      << ", expected " << static_cast<int>(want) << " (0 unobserved, 1 free, 2 "
                      << "occupied); cone from (" << c.apex.transpose() << ") along " << c.axis
                      << ", half-angle " << c.half << ", range " << c.range
                      << (c.hit ? " (echo)" : " (clear)") << ", resolution " << options.resolution;
    }
  EXPECT_EQ(differences, 0);
}

TEST(SonarGrid, RandomConesMarkTheCellsTheModelDefines) {
  std::mt19937 rng(20261130);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double pi = std::numbers::pi;
  for (int k = 0; k < 400; ++k) {
    SonarGridOptions options;
    // From the study's 5 cm to cells twice the arc's depth, where arcs often hold no centre.
    options.resolution = std::array{0.05, 0.1, 0.2, 0.37}[k % 4];
    const Box2 extent(Vec2(-3.0, -2.0), Vec2(4.0, 3.5));
    ConeCase c;
    // Apexes anywhere in and around the raster, every fifth on a cell corner, every seventh on
    // a centre.
    c.apex = Vec2(-4.0 + 9.0 * unit(rng), -3.0 + 7.5 * unit(rng));
    if (k % 5 == 0 || k % 7 == 0) {
      const Vec2 cell = ((c.apex - extent.min()) / options.resolution).array().floor();
      c.apex = extent.min() + options.resolution * (cell + Vec2::Constant(k % 5 == 0 ? 0 : 0.5));
    }
    c.axis = k % 11 == 0 ? pi / 2 * (k % 4) : -pi + 2 * pi * unit(rng);
    // Spreads from nearly none, through the usual 20°, to nearly 360°.
    c.half = std::array{1e-4, 0.01, 0.1745, 0.5, 1.5, pi / 2 - 1e-3, 3.1}[k % 7];
    // Arcs of tiny radius, within the raster, and long ones across it.
    c.range = std::array{0.01, 0.04, 0.3, 2.0, 3.5, 30.0}[k % 6] * (0.5 + unit(rng));
    c.hit = k % 3 != 0;
    ExpectReferenceCone(options, extent, c);
    if (::testing::Test::HasFailure()) return;
  }
}

TEST(SonarGrid, EveryEchoMarksAnOccupiedCellEvenWhenItsArcHoldsNoCentre) {
  // Cells twice as deep as the arc: a 20° cone's arc at 1.1 m passes between the centres
  // along its axis (at 1.0 and 1.2 m) and is narrower than a cell there.
  SonarGridOptions options;
  options.resolution = 0.2;
  SonarGrid grid(Box2(Vec2(-1, -1), Vec2(3, 1)), options);
  grid.InsertCone(Vec2(0.1, 0.1), 0.0, 0.1745, 1.1, true);  // apex on a centre
  EXPECT_GT(LogOddsAt(grid, Vec2(1.2, 0.1)), 0.0);          // the echo's cell
  EXPECT_LT(LogOddsAt(grid, Vec2(0.7, 0.1)), 0.0);
  // An echo nearer than any centre, from a cell's corner.
  SonarGrid near(Box2(Vec2(-1, -1), Vec2(1, 1)), SonarGridOptions{});
  near.InsertCone(Vec2(0.0, 0.0), 0.3, 0.1745, 0.02, true);
  EXPECT_GT(LogOddsAt(near, Vec2(0.019, 0.006)), 0.0);
  int occupied = 0;
  for (int iy = 0; iy < near.height(); ++iy)
    for (int ix = 0; ix < near.width(); ++ix) occupied += near.LogOdds(ix, iy) > 0.0;
  EXPECT_EQ(occupied, 1);
}

TEST(SonarGrid, AConeOfAFullTurnOrMoreIsTheWholeDisc) {
  for (const double half : {std::numbers::pi, 4.0, 2.0 * std::numbers::pi}) {
    SonarGrid grid(Box2(Vec2(-2, -2), Vec2(2, 2)), SonarGridOptions{});
    grid.InsertCone(Vec2(0.01, 0.02), 0.3, half, 1.0, false);
    for (const double angle : {0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0})
      EXPECT_LT(LogOddsAt(grid, Vec2(0.01, 0.02) + 0.8 * UnitVector(angle)), 0.0)
          << "half-angle " << half << ", direction " << angle;
    EXPECT_FALSE(ObservedAt(grid, Vec2(1.2, 0.0)));
  }
}

TEST(SonarGrid, AConeOfExactlyAHalfTurnHoldsTheCellsStraightBehindItsApex) {
  // At a half-angle of pi the cone test dot(axis, d) >= cos(pi) |d| is dot >= -|d|, which
  // rounding breaks for centres straight behind the apex: apexes on centres, axes through
  // centres (so that whole rows of centres lie straight behind).
  const double pi = std::numbers::pi;
  int cells = 0, unobserved = 0;
  for (int k = 0; k < 60; ++k) {
    SonarGrid grid(Box2(Vec2(-2, -2), Vec2(2, 2)), SonarGridOptions{});
    const Vec2 apex(0.025 + 0.05 * (k % 13), 0.025 - 0.05 * (k % 11));
    const double axis = std::atan2(k % 7 - 3.0, k % 5 - 2.0);
    grid.InsertCone(apex, axis, k % 2 == 0 ? pi : 2 * pi, 1.0, k % 3 == 0);
    for (int iy = 0; iy < grid.height(); ++iy)
      for (int ix = 0; ix < grid.width(); ++ix) {
        const double r = (grid.origin() + 0.05 * Vec2(ix + 0.5, iy + 0.5) - apex).norm();
        if (r > 0.9) continue;  // well before the arc or the cleared range
        ++cells;
        if (!grid.Observed(ix, iy) || grid.LogOdds(ix, iy) >= 0.0) {
          if (++unobserved <= 3)
            ADD_FAILURE() << "cell (" << ix << ", " << iy << ") at " << r << " m from apex ("
                          << apex.transpose() << "), axis " << axis << ", is not free";
        }
      }
  }
  EXPECT_GT(cells, 10000);
  EXPECT_EQ(unobserved, 0);
}

TEST(SonarGrid, WithoutClearingAnEchoAtTheInsertionRangeIsLeftOutLikeAMaxReading) {
  // docs/sonar.md: a max reading, and a reading at or beyond the insertion range (a max reading
  // for the PRF too), clears its cone unless max_readings_clear is off.
  SonarGridOptions options;
  options.max_range = 5.0;
  options.max_readings_clear = false;
  SonarGrid grid(Box2(Vec2(-1, -3), Vec2(7, 6)), options);
  Scan ring;
  ring.pose = Se2(0.01, 0.01, 0.0);
  ring.angles = {0.0, std::numbers::pi / 2, std::numbers::pi};
  ring.ranges = {5.05, 2.0, 5.11};  // an echo beyond R, one within it, a max reading
  ring.sigma = {0.01, 0.01, 0.01};
  ring.max_range = 5.11;
  ring.ClassifyAll();
  ring.sonar.emplace();
  ASSERT_EQ(ring.status[0], BeamStatus::kValid);
  EXPECT_EQ(grid.Insert(ring), 1u);
  EXPECT_FALSE(ObservedAt(grid, Vec2(2.0, 0.0)));
  EXPECT_FALSE(ObservedAt(grid, Vec2(4.9, 0.0)));
  EXPECT_GT(LogOddsAt(grid, Vec2(0.01, 2.0)), 0.0);
  Log log;
  log.scans = {ring};  // only the echo within R: its arc, 1 m of margin, no cone along x
  EXPECT_LT(SonarGrid::ExtentOf(log, 0, 1, options).max().x(), 2.0);
}

TEST(SonarGrid, RefusesConesWithoutAFiniteApexOrRange) {
  // An infinite range would clear the cone to the grid's edge and mark no echo anywhere.
  SonarGrid grid(Box2(Vec2(-2, -2), Vec2(2, 2)), SonarGridOptions{});
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(grid.InsertCone(Vec2(0, 0), 0.0, 0.17, inf, true), std::invalid_argument);
  EXPECT_THROW(grid.InsertCone(Vec2(0, 0), 0.0, 0.17, inf, false), std::invalid_argument);
  EXPECT_THROW(grid.InsertCone(Vec2(nan, 0), 0.0, 0.17, 1.0, true), std::invalid_argument);
  EXPECT_THROW(grid.InsertCone(Vec2(0, inf), 0.0, 0.17, 1.0, false), std::invalid_argument);
  EXPECT_THROW(grid.InsertCone(Vec2(0, 0), inf, 0.17, 1.0, false), std::invalid_argument);
  int observed = 0;
  for (int iy = 0; iy < grid.height(); ++iy)
    for (int ix = 0; ix < grid.width(); ++ix) observed += grid.Observed(ix, iy);
  EXPECT_EQ(observed, 0);
}

TEST(SonarGrid, RefusesConesWithoutAnAngleOrARange) {
  SonarGrid grid(Box2(Vec2(-2, -2), Vec2(2, 2)), SonarGridOptions{});
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(grid.InsertCone(Vec2(0, 0), 0.0, nan, 1.0, true), std::invalid_argument);
  EXPECT_THROW(grid.InsertCone(Vec2(0, 0), 0.0, -0.1, 1.0, true), std::invalid_argument);
  EXPECT_THROW(grid.InsertCone(Vec2(0, 0), 0.0, 0.17, nan, true), std::invalid_argument);
  EXPECT_THROW(grid.InsertCone(Vec2(0, 0), 0.0, 0.17, -1.0, true), std::invalid_argument);
  EXPECT_THROW(grid.InsertCone(Vec2(0, 0), nan, 0.17, 1.0, true), std::invalid_argument);
}

TEST(SonarGrid, AnEchoAtTheInsertionRangeIsAMaxReadingAsInThePrf) {
  // The PRF (SelectSonarReadings) and Scan::ClassifyAll take a reading at or above R for no
  // echo; RoboND's millimetre readings include 5000 mm, exactly the default R.
  SonarGridOptions options;
  options.max_range = 5.0;
  SonarGrid grid(Box2(Vec2(-1, -3), Vec2(7, 3)), options);
  Scan ring;
  ring.pose = Se2(0.01, 0.01, 0.0);
  ring.angles = {0.0, std::numbers::pi / 2};
  ring.ranges = {5.0, 2.0};
  ring.sigma = {0.01, 0.01};
  ring.max_range = 5.11;
  ring.ClassifyAll();
  ring.sonar.emplace();
  ASSERT_EQ(grid.Insert(ring), 2u);
  EXPECT_LT(LogOddsAt(grid, Vec2(4.9, 0.0)), 0.0);
  EXPECT_FALSE(ObservedAt(grid, Vec2(5.04, 0.01)));
  EXPECT_GT(LogOddsAt(grid, Vec2(0.01, 2.0)), 0.0);
  Log log;
  log.scans = {ring};  // cleared to 5 m, with no arc beyond: 5 m + 1 m of margin
  EXPECT_NEAR(SonarGrid::ExtentOf(log, 0, 1, options).max().x(), 6.01, 1e-9);
}

TEST(SonarGrid, RefusesBadOptions) {
  SonarGridOptions options;
  options.arc_thickness = 0.0;
  EXPECT_THROW(SonarGrid(Box2(Vec2(0, 0), Vec2(1, 1)), options), std::invalid_argument);
  options = SonarGridOptions{};
  options.log_odds_free = 0.1;
  EXPECT_THROW(SonarGrid(Box2(Vec2(0, 0), Vec2(1, 1)), options), std::invalid_argument);
  // Not finite: every cell in one, arcs or margins over the whole plane.
  const double inf = std::numeric_limits<double>::infinity();
  for (const auto& bad :
       {SonarGridOptions{.resolution = inf}, SonarGridOptions{.arc_thickness = inf},
        SonarGridOptions{.margin = std::nan("")}, SonarGridOptions{.margin = -1.0}})
    EXPECT_THROW(SonarGrid(Box2(Vec2(0, 0), Vec2(1, 1)), bad), std::invalid_argument);
}

}  // namespace
}  // namespace priormap::grid
