// The MAP scan of a scene does not depend on its scale: the same straight wall, square room or
// circle, with the sensor's noise and range scaled alike, 1e5 to 1e7 m away gives the same
// INMODEL, the same regions and about the same relative errors as at a few metres. The constraints
// whose residuals are lengths are measured relative to their windows' ranges beyond kUnitRange
// (src/priorlets/inner_problem.hpp); before, the penalty homotopy weighed them in metres against
// the normals' constraints in radians, stalled, and broke the scene apart.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/range_sensor.hpp>
#include <priormap/core/scene.hpp>
#include <priormap/dsl/prior_library.hpp>
#include <priormap/priorlets/engine.hpp>

#include "testing/scan_truth.hpp"

namespace priormap::priorlets {
namespace {

// One scan (seed 7) of the polyline `corners` scaled by `scale`, from (x, y) scaled alike and
// heading theta, by an LMS200 with `fov_deg` and `beams` whose noise and range limit scale too.
Scan ScaledScan(std::vector<Vec2> corners, bool closed, double scale, double x, double y,
                double theta, double fov_deg, int beams) {
  for (Vec2& c : corners) c *= scale;
  Scene scene;
  scene.surfaces.push_back({Polyline{std::move(corners), closed}, false, "walls"});
  RangeSensor sensor = RangeSensor::Preset("lms200").value();
  sensor.fov = DegToRad(fov_deg);
  sensor.num_beams = beams;
  sensor.sigma *= scale;
  sensor.max_range *= scale;
  return testing::SimulateScene(scene, sensor, Se2(x * scale, y * scale, theta), 7);
}

// A wall 2 units away along y, seen at 0.2 rad from (0.3, 0.1) over 120 degrees; its ends are
// beyond the sensor's range.
Scan WallScan(double scale) {
  return ScaledScan({{-10.0, 2.0}, {10.0, 2.0}}, false, scale, 0.3, 0.1, 0.2, 120.0, 121);
}

// A 6 x 4 room seen from inside over 270 degrees: four walls, three corners in view.
Scan RoomScan(double scale) {
  return ScaledScan({{-3.0, -2.0}, {3.0, -2.0}, {3.0, 2.0}, {-3.0, 2.0}}, true, scale, -1.5, -1.0,
                    0.6, 270.0, 271);
}

std::vector<std::size_t> ValidBeams(const Scan& scan) {
  std::vector<std::size_t> beams;
  for (std::size_t i = 0; i < scan.size(); ++i) {
    if (scan.IsValid(i)) beams.push_back(i);
  }
  return beams;
}

// Mean |rho - true range| / true range over the in-model beams.
double MeanRelativeRangeError(const Scan& scan, const MapScan& map) {
  double sum = 0.0;
  for (const std::size_t b : map.inmodel_beams)
    sum += std::abs(map.rho[b] - scan.truth->range[b]) / scan.truth->range[b];
  return sum / static_cast<double>(map.inmodel_beams.size());
}

// What a scale must give: every valid reading in the model, the true regions (a border within a
// beam of every true corner), and the relative range error of the same scene 1 m-scale.
void ExpectLikeTheNearScene(const Scan& scan, const MapScan& map, double near_error) {
  EXPECT_TRUE(map.feasible);
  EXPECT_EQ(map.inmodel_beams, ValidBeams(scan));
  const std::vector<std::size_t> corners = testing::TrueCorners(scan);
  ASSERT_EQ(map.regions.size(), corners.size() + 1);
  const std::vector<testing::FoundBorder> found = testing::FoundBorders(map);
  for (const std::size_t c : corners) EXPECT_LE(std::abs(testing::NearestBorder(c, found)), 1);
  // The noise scales with the scene: so does the error, which stays that of the near scene (to
  // 10 %, the corners' +-1 beam).
  EXPECT_NEAR(MeanRelativeRangeError(scan, map), near_error, 0.1 * near_error);
}

// Before the fix, every reading of this wall was an outlier from 1e5 m on (the violation of its
// collinearity constraints stalled at 0.6 m on the 2e5 m wall, against a tolerance of 1e-6).
TEST(EngineScale, AFarStraightWallKeepsEveryReadingAndItsAccuracy) {
  for (const std::string prior_name : {"polygonal", "rectangular"}) {
    const dsl::CompiledPrior prior = dsl::PriorLibrary().Load(prior_name).value();
    const Scan near = WallScan(1.0);
    const MapScan near_map = EstimateMapScan(near, prior);
    ASSERT_EQ(near_map.inmodel_beams, ValidBeams(near));
    ASSERT_GE(near_map.inmodel_beams.size(), 50u);
    const double near_error = MeanRelativeRangeError(near, near_map);
    // The estimate corrects the noise: well below sigma / range (5e-3 here).
    ASSERT_LT(near_error, 1e-3);
    for (const double scale : {1e5, 1e6, 1e7}) {
      SCOPED_TRACE(::testing::Message() << prior_name << " prior, wall at 2 x " << scale << " m");
      const Scan scan = WallScan(scale);
      ExpectLikeTheNearScene(scan, EstimateMapScan(scan, prior), near_error);
    }
  }
}

// Before the fix the polygonal prior kept 28 of the 271 readings at 1e5, 9 at 1e6 and none at
// 1e7; the rectangular one 54 at 1e5 and none further.
TEST(EngineScale, AFarSquareRoomKeepsItsFourWallsAndEveryReading) {
  for (const std::string prior_name : {"polygonal", "rectangular"}) {
    const dsl::CompiledPrior prior = dsl::PriorLibrary().Load(prior_name).value();
    const Scan near = RoomScan(1.0);
    ASSERT_EQ(testing::TrueCorners(near).size(), 3u) << "the pose sees four walls";
    const MapScan near_map = EstimateMapScan(near, prior);
    const double near_error = MeanRelativeRangeError(near, near_map);
    {
      SCOPED_TRACE(prior_name + " prior, the room at 1 m scale");
      ExpectLikeTheNearScene(near, near_map, near_error);
    }
    for (const double scale : {1e5, 1e6, 1e7}) {
      SCOPED_TRACE(::testing::Message() << prior_name << " prior, room scaled by " << scale);
      const Scan scan = RoomScan(scale);
      ExpectLikeTheNearScene(scan, EstimateMapScan(scan, prior), near_error);
    }
  }
}

// A circle of radius 2 units whose centre is 0.58 units from the sensor, seen over 270 degrees.
Scan CircleScan(double scale) {
  Scene scene;
  scene.surfaces.push_back({Circle{Vec2(0.5 * scale, 0.3 * scale), 2.0 * scale}, false, "c"});
  RangeSensor sensor = RangeSensor::Preset("lms200").value();
  sensor.fov = DegToRad(270.0);
  sensor.num_beams = 271;
  sensor.sigma *= scale;
  sensor.max_range *= scale;
  return testing::SimulateScene(scene, sensor, Se2(0.0, 0.0, 0.2), 7);
}

// The circular prior's constraints mix a curvature (an inverse length) with lengths and angles.
// Before the fix a circle scaled by 1e3 kept 96 of its 271 readings in 10 regions, by 1e5 none.
// Its error is that of the circle kUnitRange away, twice the 2 m circle's (their balance of data
// and constraints differs: 9e-5 at 2 m, 3e-4 at 200 m before the fix too).
TEST(EngineScale, AFarCircleIsOneRegionWithEveryReading) {
  const dsl::CompiledPrior prior = dsl::PriorLibrary().Load("circular").value();
  const Scan near = CircleScan(1.0);
  const MapScan near_map = EstimateMapScan(near, prior);
  ASSERT_EQ(near_map.inmodel_beams, ValidBeams(near));
  const double near_error = MeanRelativeRangeError(near, near_map);
  for (const double scale : {1e3, 1e5, 1e7}) {
    SCOPED_TRACE(::testing::Message() << "circle scaled by " << scale);
    const Scan scan = CircleScan(scale);
    const MapScan map = EstimateMapScan(scan, prior);
    EXPECT_TRUE(map.feasible);
    EXPECT_EQ(map.inmodel_beams, ValidBeams(scan));
    EXPECT_EQ(map.regions.size(), 1u);
    EXPECT_LT(MeanRelativeRangeError(scan, map), 2.5 * near_error);
  }
}

}  // namespace
}  // namespace priormap::priorlets
