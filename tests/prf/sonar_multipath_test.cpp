// The multipath path of a sonar cone: the axis mirrored at the face it meets and followed to the
// next edge, on a hand-worked case, against a brute-force search over every edge of dense Arak
// samples, and against the sonar simulator's own multipath readings in the true map of a
// simulated office.
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include <priormap/core/scene.hpp>
#include <priormap/core/scene_truth.hpp>
#include <priormap/core/simulate.hpp>
#include <priormap/core/sonar_simulate.hpp>
#include <priormap/prf/scene_coloring.hpp>
#include <priormap/prf/sonar_likelihood.hpp>
#include <priormap/prf/sonar_multipath.hpp>

#include "cone_testing.hpp"

namespace priormap::prf {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// In the window [0, 8] x [0, 6]: a face at 45° from (3, 0) up to (6.5, 3.5), then a wall back
// to the left side at y = 3.5. A cone from (1, 1) along +x meets the face at (4, 1), 3 m away;
// mirrored there it goes straight up and meets the wall at (4, 3.5), 2.5 m on: 5.5 m in all.
Coloring FaceAndWall() {
  const Window window{Vec2::Zero(), Vec2(8, 6)};
  const std::vector<NewVertex> vertices = {
      {Vec2(3, 0), 0}, {Vec2(6.5, 3.5), kInterior}, {Vec2(0, 3.5), 3}};
  const std::vector<std::array<int, 2>> edges = {{0, 1}, {1, 2}};
  return std::get<Coloring>(Coloring::FromGraph(window, 0.5, vertices, edges, Colour::kWhite));
}

std::shared_ptr<const SonarData> OneConeFrom(const Vec2& origin, const Vec2& axis,
                                             double max_range) {
  auto data = std::make_shared<SonarData>();
  data->sensors = {origin};
  data->max_range = max_range;
  data->readings = {
      {.cone = {.origin = origin, .axis = axis, .half_spread = 0.17, .max_range = max_range},
       .range = 1.0,
       .max_reading = false,
       .sensor = 0}};
  return data;
}

SonarModel WithMultipath() {
  SonarModel model;
  model.multipath_weight = 0.4;
  return model;
}

double LengthInCase(const Coloring& coloring, const Vec2& origin, const Vec2& axis,
                    double max_range, std::optional<double>* length) {
  SonarLikelihood likelihood(OneConeFrom(origin, axis, max_range), WithMultipath());
  EXPECT_FALSE(likelihood.Reset(coloring));
  *length = likelihood.MultipathLength(coloring, 0);
  return length->value_or(-1.0);
}

TEST(SonarMultipath, TheAxisIsMirroredAtItsFaceAndHeardFromTheNextWall) {
  const Coloring coloring = FaceAndWall();
  ASSERT_EQ(coloring.ColourAt(Vec2(1, 1)), Colour::kWhite);
  ASSERT_EQ(coloring.ColourAt(Vec2(6, 1)), Colour::kBlack);

  const SonarCone cone{
      .origin = Vec2(1, 1), .axis = Vec2::UnitX(), .half_spread = 0.17, .max_range = 6.0};
  std::vector<TaggedSegment> segments;
  for (EdgeId e : coloring.edge_ids()) segments.push_back({coloring.EdgeSegment(e), e});
  ConeSweep sweep;
  SonarView view;
  sweep.Compute(cone, segments, coloring.window(), &view);
  const auto leg = AxisMirror(cone, view, segments, coloring.window());
  ASSERT_TRUE(leg);
  EXPECT_NEAR((leg->from - Vec2(4, 1)).norm(), 0.0, 1e-14);
  EXPECT_NEAR((leg->direction - Vec2(0, 1)).norm(), 0.0, 1e-14);
  EXPECT_NEAR(leg->axis_distance, 3.0, 1e-14);
  EXPECT_NEAR(leg->reach, 3.0, 1e-14);  // R − 3, within the 5 m to the top side
  const auto hit = FirstLegHit(*leg, coloring, nullptr, {});
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, 2.5, 1e-14);
  EXPECT_NE(hit->tag, leg->mirror_tag);  // the wall, not the face it left
  EXPECT_NEAR(MultipathLength(*leg, hit), 5.5, 1e-14);

  std::optional<double> length;
  EXPECT_NEAR(LengthInCase(coloring, Vec2(1, 1), Vec2::UnitX(), 6.0, &length), 5.5, 1e-14);
  // With R = 5 the 5.5 m path is not heard: +inf, a max reading.
  LengthInCase(coloring, Vec2(1, 1), Vec2::UnitX(), 5.0, &length);
  ASSERT_TRUE(length);
  EXPECT_EQ(*length, kInf);
  // An axis that meets nothing (towards the left side) has no mirror.
  LengthInCase(coloring, Vec2(1, 1), -Vec2::UnitX(), 6.0, &length);
  EXPECT_FALSE(length);
  // An axis straight at the wall comes back on itself and leaves through the bottom side of
  // the window: nothing to hear within R.
  LengthInCase(coloring, Vec2(1, 1), Vec2::UnitY(), 6.0, &length);
  ASSERT_TRUE(length);
  EXPECT_EQ(*length, kInf);
}

// The same path found by brute force: the nearest edge along the axis, mirrored, and the nearest
// other edge along the mirrored ray within R − d and the window.
std::optional<double> BruteForceLength(const Coloring& coloring, const SonarCone& cone) {
  double d1 = kInf;
  Segment face;
  EdgeId face_id = kNoEdge;
  for (EdgeId e : coloring.edge_ids()) {
    const Segment s = coloring.EdgeSegment(e);
    const auto t = RaySegmentHit(cone.origin, cone.axis, s.a, s.b, cone.max_range);
    if (t && *t < d1) {
      d1 = *t;
      face = s;
      face_id = e;
    }
  }
  if (face_id == kNoEdge) return std::nullopt;
  const Vec2 n = Perp(face.b - face.a).normalized();
  const Vec2 m = cone.axis - 2.0 * cone.axis.dot(n) * n;
  const Vec2 from = cone.origin + d1 * cone.axis;
  const double reach = std::min(cone.max_range - d1, coloring.window().DistanceToSide(from, m));
  double d2 = kInf;
  for (EdgeId e : coloring.edge_ids()) {
    if (e == face_id) continue;
    const Segment s = coloring.EdgeSegment(e);
    const auto t = RaySegmentHit(from, m, s.a, s.b, reach);
    if (t) d2 = std::min(d2, *t);
  }
  return d1 + d2;
}

TEST(SonarMultipath, MatchesABruteForceSearchOnArakSamples) {
  int mirrored = 0, heard = 0;
  for (std::uint64_t seed : {41, 42}) {
    const Coloring coloring = DenseArakSample(seed);
    std::vector<TaggedSegment> segments;
    for (EdgeId e : coloring.edge_ids()) segments.push_back({coloring.EdgeSegment(e), e});
    std::mt19937_64 random(seed);
    ConeSweep sweep;
    SonarView view;
    for (int trial = 0; trial < 300; ++trial) {
      const SonarCone cone = RandomCone(random, 0.03, 0.3);
      sweep.Compute(cone, segments, coloring.window(), &view);
      const auto leg = AxisMirror(cone, view, segments, coloring.window());
      const std::optional<double> expected = BruteForceLength(coloring, cone);
      SCOPED_TRACE(::testing::Message() << "seed " << seed << ", trial " << trial);
      ASSERT_EQ(leg.has_value(), expected.has_value());
      if (!leg) continue;
      ++mirrored;
      const double length = MultipathLength(*leg, FirstLegHit(*leg, coloring, nullptr, {}));
      if (std::isfinite(*expected)) {
        ++heard;
        EXPECT_NEAR(length, *expected, 1e-9);
      } else {
        EXPECT_EQ(length, kInf);
      }
    }
  }
  // Many cones in these dense samples see a face on their axis (235 of 600), and a third of
  // those hear the path back within R.
  EXPECT_GT(mirrored, 150);
  EXPECT_GT(heard, 50);
}

TEST(SonarMultipath, EqualsTheSimulatorsMultipathReadingsInTheTrueMap) {
  const Scene scene = *BuiltinScene("office");
  const SonarSensor sensor = *SonarSensor::Preset("pioneer16");
  const Log log =
      SimulateSonarLog(scene, sensor, TrajectoryFromWaypoints(scene.waypoints, 0.5, 2.0), 11);
  const auto selected = SelectSonarReadings(
      log, {.first_scan = 0, .end_scan = std::nullopt, .max_range = sensor.max_range});
  ASSERT_TRUE(selected.ok()) << selected.error();
  const auto data = std::make_shared<const SonarData>(selected.value());
  std::vector<Vec2> seeds = scene.waypoints;
  for (const Vec2& s : data->sensors) seeds.push_back(s);
  // A window around the whole building, so that every mirrored path stays inside it.
  const auto truth = SceneColoring(scene, SceneTruth(scene, seeds), WindowAround(*data, 15.0), 0.5);
  ASSERT_TRUE(std::holds_alternative<Coloring>(truth)) << std::get<std::string>(truth);
  const Coloring& coloring = std::get<Coloring>(truth);
  SonarLikelihood likelihood(data, WithMultipath());
  ASSERT_FALSE(likelihood.Reset(coloring));

  // The simulator's readings in the order SelectSonarReadings keeps them (all of them valid).
  std::size_t i = 0;
  int compared = 0, beyond = 0;
  for (const Scan& ring : log.scans) {
    for (std::size_t k = 0; k < ring.ranges.size(); ++k, ++i) {
      ASSERT_LT(i, data->readings.size());
      if (ring.sonar->true_echo[k] != SonarEcho::kMultipath) continue;
      const double path = ring.truth->range[k];
      const std::optional<double> length = likelihood.MultipathLength(coloring, i);
      SCOPED_TRACE(::testing::Message() << "reading " << i << ", path " << path);
      ASSERT_TRUE(length);
      if (path < sensor.max_range) {
        EXPECT_NEAR(*length, path, 1e-5);  // the simulator steps 1e-6 off the mirror
        ++compared;
      } else {
        EXPECT_TRUE(*length >= sensor.max_range - 1e-5) << *length;
        ++beyond;
      }
    }
  }
  EXPECT_EQ(i, data->readings.size());
  EXPECT_GT(compared, 100);
  // A path past R is labelled multipath only where the noise brought its reading back within
  // R (otherwise the reading is a max-range one, with no echo): a few at most.
  EXPECT_LE(beyond, 5);
}

}  // namespace
}  // namespace priormap::prf
