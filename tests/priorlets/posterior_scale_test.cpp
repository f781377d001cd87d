// The degrees of freedom of a scene do not depend on its scale: the same geometry from 1 m to
// 1e8 m has the same Free, Extr and Intr (ComputeKernel decides the rank with the normals in
// metres, their range times their angle; see constraint_kernel.hpp, "Units").
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/range_sensor.hpp>
#include <priormap/core/scene.hpp>
#include <priormap/dsl/prior_library.hpp>
#include <priormap/priorlets/posterior.hpp>

#include "testing/scan_truth.hpp"

namespace priormap::priorlets {
namespace {

dsl::CompiledPrior Prior(const std::string& name) {
  return dsl::PriorLibrary().Load(name).value();
}

// The scales of the tests: every decade from 1 to 1e8.
std::vector<double> Scales() {
  std::vector<double> scales;
  for (int e = 0; e <= 8; ++e) scales.push_back(std::pow(10.0, e));
  return scales;
}

// A noise-free scan of a straight wall at `distance` (its normal at angle `normal`), `count`
// beams over normal +- half_width; the sensor's noise and range limits scale with `scale` too.
Scan WallScan(std::size_t count, double half_width, double normal, double distance, double scale) {
  Scan scan;
  scan.angles = EvenlySpacedAngles(count, normal - half_width, normal + half_width);
  for (double phi : scan.angles) scan.ranges.push_back(scale * distance / std::cos(phi - normal));
  scan.sigma.assign(count, 0.01 * scale);
  scan.status.assign(count, BeamStatus::kValid);
  scan.min_range = 0.1 * scale;
  scan.max_range = 30.0 * scale;
  return scan;
}

// A straight wall far away. Before the fix, at 2e8 m, seen by 5 beams over 0.1 rad it had 5
// degrees of freedom (right up to 1.3e7 m, wrong from 1.6e7 m), by 10 beams over 0.1 rad 10
// (right up to 1e7 m), by 200 beams over 1 rad 200 (right up to 3.2e6 m, 3 at 4e6 m, 18 at
// 2e7 m). Its two degrees of freedom (the line's offset and direction) are both extrinsic.
TEST(PosteriorScale, AStraightWallHasTwoDegreesOfFreedomAtAnyDistance) {
  const dsl::CompiledPrior prior = Prior("polygonal");
  struct Wall {
    std::size_t count;
    double half_width;
  };
  for (const Wall wall : {Wall{5, 0.05}, Wall{5, 0.5}, Wall{10, 0.05}, Wall{200, 0.5}}) {
    double kept_at_one = 0.0;
    for (const double scale : Scales()) {
      SCOPED_TRACE(::testing::Message() << wall.count << " beams over +-" << wall.half_width
                                        << " rad at 2 x " << scale << " m");
      const Scan scan = WallScan(wall.count, wall.half_width, 0.3, 2.0, scale);
      const MapScan map = EstimateMapScan(scan, prior);
      ASSERT_TRUE(map.feasible);
      ASSERT_EQ(map.regions.size(), 1u);
      ASSERT_EQ(map.inmodel_beams.size(), wall.count);
      const Posterior post = AnalysePosterior(scan, prior, map);
      EXPECT_EQ(post.dof.free, 2u);
      EXPECT_EQ(post.dof.extrinsic, 2u);
      EXPECT_EQ(post.dof.intrinsic, 0u);
      EXPECT_TRUE(post.dof.pose_independent) << post.note;
      // The rank decision sees the same matrix at every scale, up to where the engine left the
      // estimate (its feasibility tolerance is 1e-6 of 2 m, 1e-8 of the ranges beyond 100 m:
      // EngineOptions::feasibility_tolerance). Before the fix the smallest kept singular value
      // fell as 1 / scale.
      const double kept = post.dof.kernel.smallest_kept_singular_value;
      if (scale == 1.0) kept_at_one = kept;
      EXPECT_NEAR(kept / kept_at_one, 1.0, 1e-3);
    }
  }
}

// The MAP scan of a noise-free simulated scan built from its ground truth (true ranges, normals
// unwrapped along the scan as the engine's are, true region borders as different_region links):
// the degrees of freedom of the geometry alone, whatever the engine makes of the scene (its
// own MAP scan of a far room is checked in engine_scale_test.cpp).
MapScan MapScanOfTheTruth(const Scan& scan) {
  const ScanTruth& truth = *scan.truth;
  const std::size_t n = scan.size();
  MapScan map;
  map.rho = truth.range;
  map.alpha.assign(n, std::nan(""));
  map.initial_alpha_sigma.assign(n, 0.2);
  map.inmodel.assign(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    if (!scan.IsValid(i)) continue;
    const double facing = scan.angles[i] + kPi;
    map.alpha[i] = facing + WrapAngle(truth.alpha[i] - facing);
    map.inmodel[i] = 1;
    if (!map.inmodel_beams.empty()) {
      map.links.push_back(truth.region[map.inmodel_beams.back()] == truth.region[i]
                              ? Link::kSameRegion
                              : Link::kDifferentRegion);
    }
    map.inmodel_beams.push_back(i);
  }
  map.initial_alpha = map.alpha;
  map.feasible = true;
  return map;
}

// Sec. V of the paper, at every scale: a rectangular room seen from inside (270 deg, every wall
// in view) has 5 degrees of freedom under the rectangular prior (3 extrinsic, 2 intrinsic: width
// and height), 8 under the polygonal one. Before the fix the rectangular prior's room had 9 at
// 1e8 (1 m rooms to 1e7 m ones were right).
TEST(PosteriorScale, ARectangularRoomHasTheSameDegreesOfFreedomAtEveryScale) {
  struct Case {
    const char* prior;
    std::size_t free, extrinsic, intrinsic;
  };
  for (const Case c : {Case{"rectangular", 5, 3, 2}, Case{"polygonal", 8, 3, 5}}) {
    const dsl::CompiledPrior prior = Prior(c.prior);
    for (const double scale : Scales()) {
      SCOPED_TRACE(::testing::Message() << c.prior << " prior, room scaled by " << scale);
      Scene scene;
      scene.surfaces.push_back({Polyline{{{-3.0 * scale, -2.0 * scale},
                                          {3.0 * scale, -2.0 * scale},
                                          {3.0 * scale, 2.0 * scale},
                                          {-3.0 * scale, 2.0 * scale}},
                                         true},
                                false, "walls"});
      RangeSensor sensor = RangeSensor::Preset("lms200").value();
      sensor.fov = DegToRad(270.0);
      sensor.sigma *= scale;
      sensor.max_range *= scale;
      Scan scan = testing::SimulateScene(scene, sensor, Se2(-1.5 * scale, -1.0 * scale, 0.6), 1);
      scan.ranges = scan.truth->range;
      const MapScan map = MapScanOfTheTruth(scan);
      ASSERT_EQ(map.inmodel_beams.size(), scan.size());
      const Posterior post = AnalysePosterior(scan, prior, map);
      EXPECT_EQ(post.dof.free, c.free) << post.note;
      EXPECT_EQ(post.dof.extrinsic, c.extrinsic);
      EXPECT_EQ(post.dof.intrinsic, c.intrinsic);
      EXPECT_TRUE(post.dof.pose_independent) << post.note;
      EXPECT_LT(post.dof.kernel.largest_null_singular_value,
                1e-2 * post.dof.kernel.smallest_kept_singular_value);
    }
  }
}

}  // namespace
}  // namespace priormap::priorlets
