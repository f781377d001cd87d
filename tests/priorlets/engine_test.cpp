#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <set>
#include <vector>

#include <gtest/gtest.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/check.hpp>
#include <priormap/core/range_sensor.hpp>
#include <priormap/core/scene.hpp>
#include <priormap/dsl/prior_library.hpp>
#include <priormap/priorlets/engine.hpp>

#include "testing/scan_truth.hpp"

namespace priormap::priorlets {
namespace {

Scan Simulate(const std::string& scene_name, const std::string& sensor_name, const Se2& pose,
              std::uint64_t seed) {
  return testing::SimulateScene(BuiltinScene(scene_name).value(),
                                RangeSensor::Preset(sensor_name).value(), pose, seed);
}

dsl::CompiledPrior Prior(const std::string& name) {
  return dsl::PriorLibrary().Load(name).value();
}

using testing::TrueBorders;
using testing::TrueRegionCount;

std::vector<std::size_t> FoundBorders(const MapScan& map) {
  std::vector<std::size_t> borders;
  for (std::size_t r = 0; r + 1 < map.regions.size(); ++r) borders.push_back(map.regions[r].last);
  return borders;
}

// Mean |normal error| in degrees over in-model beams, leaving out the beams next to a true
// border when `skip_border_beams`: a beam within a beam spacing of a corner fits either wall
// within the noise, so which wall it is given is a coin toss that says nothing about the
// normals (it costs 90 deg / n of the mean when it goes wrong).
double MeanNormalErrorDeg(const Scan& scan, const MapScan& map, bool skip_border_beams) {
  std::set<std::size_t> skip;
  if (skip_border_beams) {
    for (std::size_t b : TrueBorders(scan)) {
      skip.insert(b);
      skip.insert(b + 1);
    }
  }
  double sum = 0.0;
  int count = 0;
  for (std::size_t i = 0; i < scan.size(); ++i) {
    if (!map.inmodel[i] || !std::isfinite(scan.truth->alpha[i]) || skip.count(i)) continue;
    sum += std::abs(WrapAngle(map.alpha[i] - scan.truth->alpha[i]));
    ++count;
  }
  return count ? sum / count * 180.0 / std::numbers::pi : std::numeric_limits<double>::infinity();
}

TEST(Engine, SquareRoomWithRectangularPriorFindsTheWallsAndTheirNormals) {
  const dsl::CompiledPrior prior = Prior("rectangular");
  for (std::uint64_t seed : {1, 2, 3}) {
    SCOPED_TRACE(seed);
    const Scan scan = Simulate("square", "utm30", Se2(0.3, -0.2, 0.4), seed);
    const MapScan map = EstimateMapScan(scan, prior);
    EXPECT_TRUE(map.feasible);
    EXPECT_LT(map.max_violation, 1e-5);
    const std::vector<std::size_t> truth = TrueBorders(scan), found = FoundBorders(map);
    ASSERT_EQ(found.size(), truth.size());
    for (std::size_t c = 0; c < truth.size(); ++c) {
      EXPECT_LE(std::abs(static_cast<long>(found[c]) - static_cast<long>(truth[c])), 1)
          << "corner " << c;
    }
    EXPECT_LT(MeanNormalErrorDeg(scan, map, true), 0.05);
    for (std::size_t i = 0; i < scan.size(); ++i) {
      ASSERT_TRUE(map.inmodel[i]) << i;
      EXPECT_LE(std::abs(map.rho[i] - scan.ranges[i]), 4.0 * scan.sigma[i] + 1e-12) << i;
      EXPECT_GT(map.alpha[i], map.alpha_lower[i]);
      EXPECT_LT(map.alpha[i], map.alpha_upper[i]);
    }
    // Corrected ranges are closer to the truth than the measurements.
    double measured = 0.0, corrected = 0.0;
    for (std::size_t i = 0; i < scan.size(); ++i) {
      measured += std::pow(scan.ranges[i] - scan.truth->range[i], 2);
      corrected += std::pow(map.rho[i] - scan.truth->range[i], 2);
    }
    EXPECT_LT(corrected, 0.1 * measured);
  }
}

// The engine's rays start at one origin; a ring's readings are cones from offset transducers.
TEST(Engine, ASonarRingIsAContractViolation) {
  Scan ring = Simulate("square", "lms200", Se2(), 1);
  ring.sonar.emplace();
  EXPECT_THROW((void)EstimateMapScan(ring, Prior("Polygonal prior")), ContractError);
}

TEST(Engine, TopologyDescribesRegionsAndSurfacesConsistently) {
  const Scan scan = Simulate("l-room", "utm30", Se2(0.0, 0.0, 0.4), 1);
  const MapScan map = EstimateMapScan(scan, Prior("polygonal"));
  ASSERT_EQ(map.links.size() + 1, map.inmodel_beams.size());
  std::size_t in_regions = 0;
  for (const BeamRange& r : map.regions) {
    EXPECT_LE(r.first, r.last);
    for (std::size_t i = r.first; i <= r.last; ++i) in_regions += map.inmodel[i];
  }
  EXPECT_EQ(in_regions, map.inmodel_beams.size());
  const std::size_t breaks = static_cast<std::size_t>(std::count_if(
      map.links.begin(), map.links.end(), [](Link l) { return l != Link::kSameRegion; }));
  EXPECT_EQ(map.regions.size(), breaks + 1);
  EXPECT_LE(map.surfaces.size(), map.regions.size());
  for (std::size_t i = 0; i < scan.size(); ++i) {
    if (!scan.IsValid(i)) {
      EXPECT_FALSE(map.inmodel[i]);
      EXPECT_TRUE(std::isnan(map.alpha[i]));
    }
  }
}

TEST(Engine, WithoutRefinementTheGreedyResultIsKeptAndStillFeasible) {
  const Scan scan = Simulate("rectangle", "utm30", Se2(0.3, -0.2, 0.4), 4);
  EngineOptions options;
  options.refine_borders = false;
  const MapScan greedy = EstimateMapScan(scan, Prior("polygonal"), options);
  EXPECT_TRUE(greedy.feasible);
  EXPECT_EQ(greedy.stats.refinement_trials, 0);
  const MapScan refined = EstimateMapScan(scan, Prior("polygonal"));
  EXPECT_TRUE(refined.feasible);
  // Refinement only accepts changes that keep the scan feasible and fit at least as well.
  EXPECT_LE(refined.regions.size(), greedy.regions.size());
}

TEST(Engine, SameInputGivesTheSameResult) {
  const Scan scan = Simulate("square", "lms200", Se2(0.3, -0.2, 0.4), 7);
  const MapScan a = EstimateMapScan(scan, Prior("rectangular"));
  const MapScan b = EstimateMapScan(scan, Prior("rectangular"));
  EXPECT_EQ(a.rho, b.rho);
  EXPECT_EQ(a.links, b.links);
}

// The indices of the valid beams.
std::vector<std::size_t> ValidBeams(const Scan& scan) {
  std::vector<std::size_t> beams;
  for (std::size_t i = 0; i < scan.size(); ++i) {
    if (scan.IsValid(i)) beams.push_back(i);
  }
  return beams;
}

TEST(Engine, CircularPriorTakesTheWholeCircularWallAsOneRegion) {
  const dsl::CompiledPrior prior = Prior("circular");
  for (std::uint64_t seed : {1, 2, 3, 4}) {
    SCOPED_TRACE(seed);
    const Scan scan = Simulate("circle", "utm30", Se2(0.3, -0.2, 0.4), seed);
    const MapScan map = EstimateMapScan(scan, prior);
    EXPECT_TRUE(map.feasible);
    EXPECT_LT(map.max_violation, 1e-5);
    const std::vector<std::size_t> valid = ValidBeams(scan);
    ASSERT_FALSE(valid.empty());
    EXPECT_EQ(map.inmodel_beams, valid) << "every reading of the wall is in the model";
    ASSERT_EQ(map.regions.size(), 1u);
    EXPECT_EQ(map.regions[0].first, valid.front());
    EXPECT_EQ(map.regions[0].last, valid.back());
    EXPECT_LT(MeanNormalErrorDeg(scan, map, false), 0.2);
  }
}

TEST(Engine, CircularPriorGivesEachOfTwoPillarsItsOwnRegions) {
  const dsl::CompiledPrior prior = Prior("circular");
  const Scene scene = BuiltinScene("two-circles").value();
  ASSERT_TRUE(scene.default_pose.has_value());
  for (std::uint64_t seed : {1, 2, 3, 4}) {
    SCOPED_TRACE(seed);
    const Scan scan = Simulate("two-circles", "utm30", *scene.default_pose, seed);
    const MapScan map = EstimateMapScan(scan, prior);
    EXPECT_TRUE(map.feasible);
    EXPECT_LT(map.max_violation, 1e-5);
    // No region mixes the pillars, and each pillar has a region.
    std::set<int> pillars_with_a_region;
    for (const BeamRange& r : map.regions) {
      std::set<int> surfaces;
      for (std::size_t i = r.first; i <= r.last; ++i) {
        if (map.inmodel[i]) surfaces.insert(scan.truth->surface[i]);
      }
      EXPECT_EQ(surfaces.size(), 1u) << "region " << r.first << ".." << r.last;
      pillars_with_a_region.insert(surfaces.begin(), surfaces.end());
    }
    EXPECT_EQ(pillars_with_a_region.size(), 2u);
    // Next to no reading of a pillar is left out.
    const std::vector<std::size_t> valid = ValidBeams(scan);
    EXPECT_GE(map.inmodel_beams.size() + 2, valid.size());
    EXPECT_LT(MeanNormalErrorDeg(scan, map, false), 0.5);
  }
}

TEST(Engine, SquareRoomSeenByAnLms200FindsItsFourWallsAndTheirCorners) {
  const dsl::CompiledPrior prior = Prior("rectangular");
  // From near a corner, looking at the opposite one: all four walls are in the 180-degree view.
  for (std::uint64_t seed : {1, 2, 3, 4}) {
    SCOPED_TRACE(seed);
    const Scan scan = Simulate("square", "lms200", Se2(-1.0, -1.0, std::numbers::pi / 4), seed);
    const std::vector<std::size_t> truth = TrueBorders(scan);
    ASSERT_EQ(truth.size(), 3u) << "the pose sees four walls";
    const MapScan map = EstimateMapScan(scan, prior);
    EXPECT_TRUE(map.feasible);
    EXPECT_LT(map.max_violation, 1e-5);
    ASSERT_EQ(map.regions.size(), 4u);
    const std::vector<std::size_t> found = FoundBorders(map);
    for (std::size_t c = 0; c < truth.size(); ++c) {
      EXPECT_LE(std::abs(static_cast<long>(found[c]) - static_cast<long>(truth[c])), 1)
          << "corner " << c;
    }
    EXPECT_EQ(map.inmodel_beams, ValidBeams(scan));
    EXPECT_LT(MeanNormalErrorDeg(scan, map, true), 0.1);
  }
}

TEST(Engine, StatsAccountForTheWork) {
  const Scan scan = Simulate("square", "lms200", Se2(0.3, -0.2, 0.4), 1);
  const MapScan map = EstimateMapScan(scan, Prior("rectangular"));
  const EngineStats& s = map.stats;
  EXPECT_GE(s.outer_rounds, 1);
  EXPECT_GE(s.inner_solves, s.outer_rounds + s.refinement_trials);
  EXPECT_GT(s.newton_steps, 0);
  EXPECT_GE(s.seconds_total, s.seconds_outer + s.seconds_refine);
}

// Spurious short readings (uniform between the sensor and the wall) that land a few sigmas in
// front of a wall, within reach of no range bound but too near for a geometric break, are
// outliers, not borders: before, each cost a different_region break that split the straight
// wall into regions of alternating normals (6-16 regions for 4 walls on these seeds, range RMS
// error 3-5 mm). Tolerance: at most two extra regions in one scan and two in all, for a residual
// spike the up-front test cannot judge (one next to a border or another outlier): 4 of the 80
// scans of rectangle and square at 2 and 5 % outliers, seeds 1-20.
TEST(Engine, SpuriousShortReadingsAreOutliersNotExtraRegions) {
  constexpr double kMinSpikeRecall = 0.9;
  constexpr std::size_t kMaxGenuineDropped = 40;  // of 1081 beams; 5-33 on these scans
  const dsl::CompiledPrior prior = Prior("rectangular");
  struct Case {
    const char* scene;
    double outliers;
    std::uint64_t seed;
  };
  long excess = 0;
  for (const Case& c :
       {Case{"rectangle", 0.02, 2}, Case{"rectangle", 0.02, 4}, Case{"square", 0.05, 3},
        Case{"square", 0.05, 4}, Case{"square", 0.05, 5}}) {
    SCOPED_TRACE(std::string(c.scene) + " seed " + std::to_string(c.seed));
    const Scene scene = BuiltinScene(c.scene).value();
    RangeSensor sensor = RangeSensor::Preset("utm30").value();
    sensor.outlier_probability = c.outliers;
    const Scan scan = testing::SimulateScene(scene, sensor, scene.default_pose.value(), c.seed);
    const MapScan map = EstimateMapScan(scan, prior);
    EXPECT_TRUE(map.feasible);
    // The spikes leave INMODEL (not merely the regions' count falls), and the walls keep their
    // genuine readings.
    const std::vector<int> label =
        testing::TrueInModel(scan, /*unscored_surface=*/-1, EngineOptions{}.rho_bound_sigmas);
    std::size_t spurious = 0, flagged = 0, genuine_dropped = 0;
    for (std::size_t i = 0; i < scan.size(); ++i) {
      spurious += label[i] == 0;
      flagged += label[i] == 0 && !map.inmodel[i];
      genuine_dropped += label[i] == 1 && !map.inmodel[i];
    }
    ASSERT_GT(spurious, 0u);
    EXPECT_GE(static_cast<double>(flagged), kMinSpikeRecall * static_cast<double>(spurious))
        << flagged << " of " << spurious << " spurious readings out of the model";
    EXPECT_LE(genuine_dropped, kMaxGenuineDropped);
    const auto truth = static_cast<long>(TrueRegionCount(scan, 4));
    const auto found = static_cast<long>(map.regions.size());
    EXPECT_GE(found, truth);
    EXPECT_LE(found, truth + 2);
    excess += std::max(0L, found - truth);
  }
  EXPECT_LE(excess, 2);
}

// Border refinement moved borders into a region until one or two beams were left of it: a region
// below min_region_points, which the greedy rounds never keep, with a normal no constraint holds
// (rectangle without outliers, seed 20: a 4-beam region the greedy rounds left in the middle of
// a wall became 1 beam, and the wall stayed in 3 regions; 11 of the 240 scans of square,
// rectangle, corridor and l-room at 0/2/5 % spurious readings, seeds 1-20). A move that would
// leave fewer points merges the region into both its neighbours instead, kept when feasible.
TEST(Engine, RefinementLeavesNoRegionBelowTheMinimum) {
  const dsl::CompiledPrior prior = Prior("rectangular");
  const EngineOptions options;
  struct Case {
    const char* scene;
    double outliers;
    std::uint64_t seed;
    // false: a spike at the end of an initial region (a geometric break on one side of it
    // only), which the up-front test does not judge, leaves a wall in many regions; settling
    // corners made some of them 1-2 beams.
    bool region_per_wall = true;
  };
  for (const Case& c :
       {Case{"rectangle", 0.0, 20}, Case{"rectangle", 0.05, 1}, Case{"square", 0.05, 2},
        Case{"rectangle", 0.02, 1}, Case{"square", 0.02, 15, false}}) {
    SCOPED_TRACE(std::string(c.scene) + " " + std::to_string(c.outliers) + " seed " +
                 std::to_string(c.seed));
    const Scene scene = BuiltinScene(c.scene).value();
    RangeSensor sensor = RangeSensor::Preset("utm30").value();
    sensor.outlier_probability = c.outliers;
    const Scan scan = testing::SimulateScene(scene, sensor, scene.default_pose.value(), c.seed);
    const MapScan map = EstimateMapScan(scan, prior, options);
    ASSERT_TRUE(map.feasible);
    for (const BeamRange& region : map.regions) {
      long points = 0;
      for (std::size_t i = region.first; i <= region.last; ++i) points += map.inmodel[i];
      EXPECT_GE(points, options.min_region_points) << region.first << ".." << region.last;
    }
    if (c.region_per_wall) {
      EXPECT_EQ(map.regions.size(), TrueRegionCount(scan, 4));
    }
  }
}

}  // namespace
}  // namespace priormap::priorlets
