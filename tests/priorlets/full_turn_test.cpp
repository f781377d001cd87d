// Scans that cover a full turn (the 360-degree rule, engine.hpp): their last reading and their
// first are neighbours, so a wall across the seam (where the scan's indices start) is one region,
// and the segmentation, outliers and degrees of freedom do not depend on where the seam falls.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <priormap/core/angles.hpp>
#include <priormap/core/range_sensor.hpp>
#include <priormap/core/scene.hpp>
#include <priormap/dsl/prior_library.hpp>
#include <priormap/priorlets/engine.hpp>
#include <priormap/priorlets/line_segments.hpp>
#include <priormap/priorlets/map_scan_json.hpp>
#include <priormap/priorlets/posterior.hpp>

#include "testing/scan_truth.hpp"

namespace priormap::priorlets {
namespace {

dsl::CompiledPrior Prior(const std::string& name) {
  return dsl::PriorLibrary().Load(name).value();
}

// A full-circle laser: 720 beams of 0.5 deg from -pi (RangeSensor::BeamAngles), utm30 noise.
RangeSensor FullCircleSensor(double outlier_probability = 0.0) {
  RangeSensor sensor = RangeSensor::Preset("utm30").value();
  sensor.num_beams = 720;
  sensor.fov = kTwoPi;
  sensor.outlier_probability = outlier_probability;
  return sensor;
}

// The scan as seen by the same sensor turned by `k` beams: beam i of the result is beam i + k
// (mod n) of `scan`, at the angle of beam i; the truth goes along.
Scan Rotated(const Scan& scan, std::size_t k) {
  const std::size_t n = scan.size();
  Scan out = scan;
  const auto rotate = [&](const auto& from, auto& to) {
    for (std::size_t i = 0; i < n; ++i) to[i] = from[(i + k) % n];
  };
  rotate(scan.ranges, out.ranges);
  rotate(scan.sigma, out.sigma);
  rotate(scan.status, out.status);
  if (scan.truth) {
    rotate(scan.truth->range, out.truth->range);
    rotate(scan.truth->alpha, out.truth->alpha);
    rotate(scan.truth->surface, out.truth->surface);
    rotate(scan.truth->region, out.truth->region);
    rotate(scan.truth->outlier, out.truth->outlier);
    // Normals are in the sensor frame, which turned by k beams.
    const double turn = scan.angles[k] - scan.angles[0];
    for (double& a : out.truth->alpha) a = WrapAngle(a - turn);
  }
  out.pose = scan.pose.Compose(Se2(0.0, 0.0, scan.angles[k] - scan.angles[0]));
  return out;
}

// The true regions of a full-turn scan counted round the ring: runs of one true region over the
// valid, genuine readings, of at least `min_points` readings.
std::size_t TrueRegionsRoundTheRing(const Scan& scan, std::size_t min_points) {
  std::vector<int> regions;
  for (std::size_t i = 0; i < scan.size(); ++i) {
    if (scan.IsValid(i) && !scan.truth->outlier[i]) regions.push_back(scan.truth->region[i]);
  }
  // Start after a change of region, so that no run is cut at the seam.
  std::size_t start = 0;
  while (start < regions.size() &&
         regions[start] == regions[(start + regions.size() - 1) % regions.size()])
    ++start;
  if (start == regions.size()) return 1;
  std::size_t count = 0, run = 0;
  for (std::size_t t = 0; t <= regions.size(); ++t) {
    const std::size_t i = (start + t) % regions.size();
    if (t == regions.size() ||
        (t > 0 && regions[i] != regions[(i + regions.size() - 1) % regions.size()])) {
      count += run >= min_points ? 1 : 0;
      run = 0;
    }
    ++run;
  }
  return count;
}

// The borders of a map scan as the beam after each non-same_region link (closing link too).
std::set<std::size_t> Borders(const MapScan& map) {
  std::set<std::size_t> borders;
  for (std::size_t j = 0; j < map.links.size(); ++j) {
    if (map.links[j] != Link::kSameRegion) borders.insert(map.inmodel_beams[j + 1]);
  }
  if (map.closed && map.closing_link != Link::kSameRegion) borders.insert(map.inmodel_beams[0]);
  return borders;
}

std::set<std::size_t> Shifted(const std::set<std::size_t>& beams, std::size_t k, std::size_t n) {
  std::set<std::size_t> out;
  for (std::size_t b : beams) out.insert((b + k) % n);
  return out;
}

std::set<std::size_t> Outliers(const MapScan& map) {
  std::set<std::size_t> out;
  for (std::size_t i = 0; i < map.inmodel.size(); ++i) {
    if (!map.inmodel[i]) out.insert(i);
  }
  return out;
}

// The region of `map` that holds beam b (NaN-free regions only), as an index into map.regions.
std::size_t RegionOf(const MapScan& map, std::size_t b) {
  for (std::size_t r = 0; r < map.regions.size(); ++r) {
    const BeamRange& region = map.regions[r];
    const bool inside = region.first <= region.last ? b >= region.first && b <= region.last
                                                    : b >= region.first || b <= region.last;
    if (inside) return r;
  }
  return map.regions.size();
}

TEST(FullTurn, TheRuleIsAGapOfOneBeamStep) {
  const auto scan_of = [](std::vector<double> angles) {
    Scan scan;
    scan.angles = std::move(angles);
    scan.ranges.assign(scan.angles.size(), 1.0);
    return scan;
  };
  // A full-circle sensor, any number of beams; the angles as floats.
  for (int beams : {3, 360, 720, 1440}) {
    RangeSensor sensor = FullCircleSensor();
    sensor.num_beams = beams;
    EXPECT_TRUE(CoversFullTurn(scan_of(sensor.BeamAngles()))) << beams;
    std::vector<double> as_float;
    for (double a : sensor.BeamAngles()) as_float.push_back(static_cast<float>(a));
    EXPECT_TRUE(CoversFullTurn(scan_of(as_float))) << beams;
  }
  // 360 beams of 1 deg from 0 to 359 deg: a full turn (fov 359 deg + a 1 deg step).
  EXPECT_TRUE(CoversFullTurn(scan_of(EvenlySpacedAngles(360, 0.0, DegToRad(359.0)))));
  // 359 beams of 1 deg from 0 to 358 deg: a gap of 2 deg, not a full turn; nor 270 deg.
  EXPECT_FALSE(CoversFullTurn(scan_of(EvenlySpacedAngles(359, 0.0, DegToRad(358.0)))));
  EXPECT_FALSE(CoversFullTurn(scan_of(RangeSensor::Preset("utm30")->BeamAngles())));
  // More than a turn; a step 20% off.
  EXPECT_FALSE(CoversFullTurn(scan_of(EvenlySpacedAngles(400, 0.0, DegToRad(399.0)))));
  EXPECT_FALSE(CoversFullTurn(scan_of(EvenlySpacedAngles(360, 0.0, DegToRad(359.0 - 0.2)))));
  // A full-circle sensor with its last beam missing (a 359.5 deg scan with a gap).
  std::vector<double> angles = FullCircleSensor().BeamAngles();
  angles.pop_back();
  EXPECT_FALSE(CoversFullTurn(scan_of(angles)));
  EXPECT_FALSE(CoversFullTurn(scan_of({0.0, 1.0})));
}

struct SeamCase {
  const char* prior;
  std::size_t free, extrinsic, intrinsic;
};

// A rectangular room (6 m x 4 m) seen by a full-circle laser whose seam (the beam behind it, at
// -pi) hits the middle of the left wall: that wall is one region, and the region count is the
// room's. The same scan turned so that the seam falls at a corner gives the same segmentation,
// outliers and degrees of freedom (up to the turn). Before the fix the left wall was two
// regions (5 in all) and the rectangular prior's Free had 6 dimensions.
void CheckSeamOnAWall(const SeamCase& c, double outlier_probability, std::uint64_t seed) {
  const Scene scene = BuiltinScene("rectangle").value();
  const RangeSensor sensor = FullCircleSensor(outlier_probability);
  const Scan scan = testing::SimulateScene(scene, sensor, Se2(0.2, 0.1, 0.0), seed);
  ASSERT_TRUE(CoversFullTurn(scan));
  const std::size_t n = scan.size();
  // The seam is on the left wall: the first and last beams hit the same true region.
  ASSERT_EQ(scan.truth->region.front(), scan.truth->region.back());
  const dsl::CompiledPrior prior = Prior(c.prior);
  const MapScan map = EstimateMapScan(scan, prior);
  ASSERT_TRUE(map.feasible);
  EXPECT_TRUE(map.closed);
  EXPECT_EQ(map.closing_link, Link::kSameRegion);
  const std::size_t true_regions = TrueRegionsRoundTheRing(scan, 4);
  EXPECT_EQ(true_regions, 4u);
  EXPECT_EQ(map.regions.size(), true_regions);
  EXPECT_EQ(map.surfaces.size(), 1u);
  // The left wall is one region, across the seam.
  ASSERT_FALSE(map.regions.empty());
  EXPECT_GT(map.regions.back().first, map.regions.back().last);
  EXPECT_EQ(RegionOf(map, map.inmodel_beams.front()), RegionOf(map, map.inmodel_beams.back()));
  // Every border within a beam of a true corner: the true region changes between beams c - 1
  // and c for some c within a beam of it (round the seam).
  const auto changes_before = [&](std::size_t beam) {
    return scan.truth->region[beam % n] != scan.truth->region[(beam + n - 1) % n];
  };
  for (std::size_t b : Borders(map)) {
    EXPECT_TRUE(changes_before(b + n - 1) || changes_before(b) || changes_before(b + 1))
        << "border before beam " << b;
  }
  const Posterior post = AnalysePosterior(scan, prior, map);
  EXPECT_EQ(post.dof.free, c.free) << post.note;
  EXPECT_EQ(post.dof.extrinsic, c.extrinsic);
  EXPECT_EQ(post.dof.intrinsic, c.intrinsic);
  EXPECT_TRUE(post.dof.pose_independent) << post.note;
  EXPECT_TRUE(post.computed) << post.note;

  // Turned so that the seam falls at a corner (the border between the bottom wall and the left
  // one): then the chain would have been right too.
  std::size_t corner = n;
  for (std::size_t i = 0; i + 1 < n && corner == n; ++i) {
    if (scan.truth->region[i] != scan.truth->region[i + 1]) corner = i + 1;
  }
  ASSERT_LT(corner, n);
  const Scan turned = Rotated(scan, corner);
  ASSERT_NE(turned.truth->region.front(), turned.truth->region.back());
  const MapScan other = EstimateMapScan(turned, prior);
  ASSERT_TRUE(other.feasible);
  EXPECT_TRUE(other.closed);
  EXPECT_EQ(other.regions.size(), map.regions.size());
  EXPECT_EQ(other.surfaces.size(), map.surfaces.size());
  // Beam b of `turned` is beam b + corner of `scan`.
  EXPECT_EQ(Shifted(Borders(other), corner, n), Borders(map));
  EXPECT_EQ(Shifted(Outliers(other), corner, n), Outliers(map));
  std::size_t compared = 0;
  double largest = 0.0;
  for (std::size_t b = 0; b < n; ++b) {
    const std::size_t a = (b + corner) % n;
    if (!map.inmodel[a] || !other.inmodel[b]) continue;
    largest = std::max(largest, std::abs(map.rho[a] - other.rho[b]));
    ++compared;
  }
  EXPECT_EQ(compared, map.inmodel_beams.size());
  EXPECT_LT(largest, 1e-4) << "largest difference of the MAP ranges, m";
  const Posterior other_post = AnalysePosterior(turned, prior, other);
  EXPECT_EQ(other_post.dof.free, post.dof.free);
  EXPECT_EQ(other_post.dof.extrinsic, post.dof.extrinsic);
  EXPECT_EQ(other_post.dof.intrinsic, post.dof.intrinsic);
}

TEST(FullTurn, AWallAcrossTheSeamIsOneRegionUnderTheRectangularPrior) {
  CheckSeamOnAWall({"rectangular", 5, 3, 2}, 0.0, 1);
}

TEST(FullTurn, AWallAcrossTheSeamIsOneRegionUnderThePolygonalPrior) {
  CheckSeamOnAWall({"polygonal", 8, 3, 5}, 0.0, 2);
}

TEST(FullTurn, OutliersAroundTheSeamAreTheSameWhereverItFalls) {
  CheckSeamOnAWall({"rectangular", 5, 3, 2}, 0.02, 3);
}

// The same scan without its last beam covers 359.5 deg with a gap of two steps: a chain, whose
// left wall is cut in two where the beam is missing, as before.
TEST(FullTurn, AScanWithAGapAtTheSeamIsNotClosed) {
  const Scene scene = BuiltinScene("rectangle").value();
  Scan scan = testing::SimulateScene(scene, FullCircleSensor(), Se2(0.2, 0.1, 0.0), 1);
  for (auto* v : {&scan.ranges, &scan.sigma, &scan.truth->range, &scan.truth->alpha}) v->pop_back();
  scan.angles.pop_back();
  scan.status.pop_back();
  scan.truth->surface.pop_back();
  scan.truth->region.pop_back();
  scan.truth->outlier.pop_back();
  ASSERT_TRUE(scan.Problems().empty());
  ASSERT_FALSE(CoversFullTurn(scan));
  const MapScan map = EstimateMapScan(scan, Prior("rectangular"));
  ASSERT_TRUE(map.feasible);
  EXPECT_FALSE(map.closed);
  EXPECT_EQ(map.regions.size(), 5u);
  for (const BeamRange& r : map.regions) EXPECT_LE(r.first, r.last);
}

// EngineOptions::close_full_turn = false keeps a full-turn scan a chain (the behaviour before
// the 360-degree rule): the wall across the seam is two regions.
TEST(FullTurn, ClosingCanBeTurnedOff) {
  const Scene scene = BuiltinScene("rectangle").value();
  const Scan scan = testing::SimulateScene(scene, FullCircleSensor(), Se2(0.2, 0.1, 0.0), 1);
  EngineOptions options;
  options.close_full_turn = false;
  const MapScan map = EstimateMapScan(scan, Prior("rectangular"), options);
  ASSERT_TRUE(map.feasible);
  EXPECT_FALSE(map.closed);
  EXPECT_EQ(map.regions.size(), 5u);
}

// A circular room seen whole from off its centre: one region round the ring, with no border at
// all (closing_link same_region), and the paper's degrees of freedom of a circle: its centre and
// radius, of which a sensor motion explains the centre (the rotation is a combination of the
// translations).
TEST(FullTurn, ACircularRoomSeenWholeIsOneRegionWithoutABorder) {
  const Scene scene = BuiltinScene("circle").value();
  const dsl::CompiledPrior prior = Prior("circular");
  for (std::uint64_t seed : {1, 2}) {
    SCOPED_TRACE(seed);
    const Scan scan = testing::SimulateScene(scene, FullCircleSensor(), Se2(0.3, -0.2, 0.4), seed);
    const MapScan map = EstimateMapScan(scan, prior);
    ASSERT_TRUE(map.feasible);
    EXPECT_TRUE(map.closed);
    EXPECT_EQ(map.inmodel_beams.size(), scan.size());
    ASSERT_EQ(map.regions.size(), 1u);
    EXPECT_EQ(map.closing_link, Link::kSameRegion);
    EXPECT_EQ(map.regions[0].first, 0u);
    EXPECT_EQ(map.regions[0].last, scan.size() - 1);
    double worst = 0.0;
    for (std::size_t i = 0; i < scan.size(); ++i)
      worst = std::max(worst, std::abs(WrapAngle(map.alpha[i] - scan.truth->alpha[i])));
    EXPECT_LT(RadToDeg(worst), 2.0) << "largest normal error, deg";
    const Posterior post = AnalysePosterior(scan, prior, map);
    EXPECT_EQ(post.dof.free, 3u) << post.note;
    EXPECT_EQ(post.dof.extrinsic, 2u);
    EXPECT_EQ(post.dof.intrinsic, 1u);
    EXPECT_TRUE(post.dof.pose_independent) << post.note;
  }
}

// A room whose left wall has a doorway behind the sensor, with nothing within range beyond it:
// the ring closes across the doorway with a different_surface link (max-range readings lie
// between), so the segmentation is the chain's: five regions (the wall on each side of the
// doorway, and three more walls). Turned so that the seam falls on the right wall, the same.
TEST(FullTurn, ADoorwayAtTheSeamIsASurfaceBorderWhereverTheSeamFalls) {
  Scene scene;
  scene.surfaces.push_back(
      {Polyline{{{-3.0, 0.5}, {-3.0, 2.0}, {3.0, 2.0}, {3.0, -2.0}, {-3.0, -2.0}, {-3.0, -0.3}},
                false},
       false, "walls"});
  RangeSensor sensor = FullCircleSensor();
  sensor.max_range = 8.0;
  const Scan scan = testing::SimulateScene(scene, sensor, Se2(0.2, 0.1, 0.0), 4);
  const std::size_t n = scan.size();
  ASSERT_EQ(scan.status.front(), BeamStatus::kMaxRange);
  const dsl::CompiledPrior prior = Prior("rectangular");
  const MapScan map = EstimateMapScan(scan, prior);
  ASSERT_TRUE(map.feasible);
  EXPECT_TRUE(map.closed);
  EXPECT_EQ(map.closing_link, Link::kDifferentSurface);
  EXPECT_EQ(map.regions.size(), 5u);
  EXPECT_EQ(map.surfaces.size(), 1u);  // the walls from one side of the doorway to the other
  for (const BeamRange& r : map.regions) EXPECT_LE(r.first, r.last);
  EngineOptions chain;
  chain.close_full_turn = false;
  const MapScan open = EstimateMapScan(scan, prior, chain);
  EXPECT_EQ(Borders(open).size() + 1, Borders(map).size());  // the chain has no closing link
  EXPECT_EQ(Outliers(open), Outliers(map));

  const std::size_t k = n / 2;  // the seam on the right wall
  const Scan turned = Rotated(scan, k);
  ASSERT_EQ(turned.truth->region.front(), turned.truth->region.back());
  const MapScan other = EstimateMapScan(turned, prior);
  ASSERT_TRUE(other.feasible);
  EXPECT_EQ(other.regions.size(), 5u);
  EXPECT_EQ(Shifted(Borders(other), k, n), Borders(map));
  EXPECT_EQ(Shifted(Outliers(other), k, n), Outliers(map));
  const Posterior a = AnalysePosterior(scan, prior, map),
                  b = AnalysePosterior(turned, prior, other);
  EXPECT_EQ(a.dof.free, b.dof.free);
  EXPECT_EQ(a.dof.extrinsic, b.dof.extrinsic);
  EXPECT_EQ(a.dof.intrinsic, b.dof.intrinsic);
}

// The wall across the seam is one line segment, its beams from the end of the scan on to its
// start, and the JSON document says the map scan is closed.
TEST(FullTurn, TheWallAcrossTheSeamIsOneLineSegment) {
  const Scene scene = BuiltinScene("rectangle").value();
  const Scan scan = testing::SimulateScene(scene, FullCircleSensor(), Se2(0.2, 0.1, 0.0), 1);
  const dsl::CompiledPrior prior = Prior("rectangular");
  const MapScan map = EstimateMapScan(scan, prior);
  ASSERT_EQ(map.regions.size(), 4u);
  PosteriorOptions keep;
  keep.keep_range_covariance = true;
  const Posterior post = AnalysePosterior(scan, prior, map, keep);
  const LineSegments lines = ExtractLineSegments(scan, map, &post);
  ASSERT_EQ(lines.segments.size(), 4u);
  const LineSegment& left = lines.segments.back();
  EXPECT_GT(left.beams.first, left.beams.last);
  EXPECT_EQ(left.points, scan.size() - left.beams.first + left.beams.last + 1);
  EXPECT_NEAR(left.radius, 3.0 + 0.2, 0.01);  // the wall x = -3, 3.2 m from the sensor
  EXPECT_NEAR(std::abs(WrapAngle(left.angle - kPi)), 0.0, 0.01);
  // Its ends: the last beam of the scan's first region and the first beam of its last, on the
  // left wall either side of the seam.
  EXPECT_NEAR(left.start.x(), -3.2, 0.01);
  EXPECT_NEAR(left.end.x(), -3.2, 0.01);
  EXPECT_GT(left.start.y(), 0.0);
  EXPECT_LT(left.end.y(), 0.0);
  const nlohmann::json j = nlohmann::json::parse(MapScanToJson(map, {0, "rectangular", "sim"}));
  EXPECT_EQ(j["closed"], true);
  EXPECT_EQ(j["closing_link"], "same_region");
  EXPECT_EQ(j["topology"].size() + 1, j["inmodel_beams"].size());
}

}  // namespace
}  // namespace priormap::priorlets
