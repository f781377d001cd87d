// The sonar simulator against hand-worked geometry: a wall across the cone echoes at its
// perpendicular distance with 1 % noise; an oblique wall alone is a specular miss (max range or
// multipath); a corner seen from inside echoes at its distance; presets and scenes are sound;
// spurious readings are as frequent as stated and uniform between the min and max range.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>
#include <vector>

#include <gtest/gtest.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/polygon.hpp>
#include <priormap/core/sonar_simulate.hpp>

namespace priormap {
namespace {

Scene WallsScene(std::vector<Polyline> walls) {
  Scene scene;
  scene.name = "test";
  for (Polyline& w : walls) scene.surfaces.push_back({std::move(w), false, "wall"});
  return scene;
}

// One transducer at the robot's origin looking along +x.
SonarSensor OneTransducer() {
  SonarSensor sensor;
  sensor.bearings = {0.0};
  sensor.spurious_probability = 0.0;
  return sensor;
}

TEST(SonarSimulator, AWallAcrossTheConeEchoesAtItsDistanceWithOnePercentNoise) {
  const SonarScene scene(WallsScene({Polyline{{Vec2(3, -2), Vec2(3, 2)}, false}}));
  SonarSensor sensor = OneTransducer();
  Rng rng(1);
  double sum = 0.0, sum_squares = 0.0;
  int echoes = 0;
  const int rings = 4000;
  for (int k = 0; k < rings; ++k) {
    const Scan ring = SimulateSonarRing(scene, sensor, Se2(0, 0, 0), rng);
    ASSERT_TRUE(ring.Problems().empty());
    ASSERT_TRUE(ring.sonar);
    if (ring.sonar->true_echo[0] != SonarEcho::kSurface) continue;
    ++echoes;
    EXPECT_EQ(ring.sonar->true_feature[0], 0);
    EXPECT_NEAR(ring.truth->range[0], 3.0, 1e-12);
    EXPECT_NEAR(ring.truth->alpha[0], std::numbers::pi, 1e-12);
    const double error = ring.ranges[0] - 3.0;
    sum += error;
    sum_squares += error * error;
  }
  // Echo probability surface_return at normal incidence (the wall's ends are outside the cone).
  const double p = sensor.surface_return;
  EXPECT_NEAR(echoes / static_cast<double>(rings), p, 4.0 * std::sqrt(p * (1 - p) / rings));
  const double sigma = 0.03;  // 1 % of 3 m
  EXPECT_NEAR(sum / echoes, 0.0, 4.0 * sigma / std::sqrt(echoes));
  EXPECT_NEAR(std::sqrt(sum_squares / echoes), sigma, 0.1 * sigma);
}

TEST(SonarSimulator, AnObliqueWallAloneIsASpecularMiss) {
  // At 45 deg to the axis: every incidence in the 20 deg cone is 35 deg or more.
  const SonarScene scene(WallsScene({Polyline{{Vec2(1, -2), Vec2(5, 2)}, false},
                                     Polyline{{Vec2(-5, 1.5), Vec2(5, 1.5)}, false}}));
  SonarSensor sensor = OneTransducer();
  sensor.multipath_probability = 0.0;
  Rng rng(2);
  for (int k = 0; k < 200; ++k) {
    const Scan ring = SimulateSonarRing(scene, sensor, Se2(0, 0, 0), rng);
    ASSERT_EQ(ring.sonar->true_echo[0], SonarEcho::kNone);
    EXPECT_EQ(ring.status[0], BeamStatus::kMaxRange);
  }
  // With multipath, the wave mirrored up to the other wall comes back too late: the axis
  // meets the mirror at (3, 0), then goes straight up to y = 1.5, 3 + 1.5 m in all.
  sensor.multipath_probability = 1.0;
  const Scan ring = SimulateSonarRing(scene, sensor, Se2(0, 0, 0), rng);
  ASSERT_EQ(ring.sonar->true_echo[0], SonarEcho::kMultipath);
  EXPECT_EQ(ring.truth->outlier[0], 1);
  EXPECT_NEAR(ring.truth->range[0], 4.5, 1e-5);
  EXPECT_EQ(ring.sonar->true_feature[0], 0);
}

// docs/sonar.md, step 3: a surface whose least incidence in the cone is ι echoes with
// probability surface_return · σ((ι_c − ι)/s) / σ(ι_c/s). A wall too long for its ends to be in
// the cone, the axis turned φ from its normal: ι = 0 while the foot of the perpendicular is in
// the cone (φ <= 10°), else φ − 10° (the cone's edge ray). Without multipath and spurious
// readings, the share of surface echoes at each φ is binomial around that probability: within 4
// standard deviations (and 0.002, for the probabilities near 0) of it.
TEST(SonarSimulator, TheShareOfSpecularMissesFollowsTheDocumentedLogistic) {
  const SonarScene scene(WallsScene({Polyline{{Vec2(3, -100), Vec2(3, 100)}, false}}));
  SonarSensor sensor = OneTransducer();
  sensor.multipath_probability = 0.0;
  const double half = sensor.spread / 2.0;
  const auto sigma = [](double x) { return 1.0 / (1.0 + std::exp(-x)); };
  const auto documented = [&](double incidence) {
    return sensor.surface_return *
           sigma((sensor.critical_incidence - incidence) / sensor.incidence_softness) /
           sigma(sensor.critical_incidence / sensor.incidence_softness);
  };
  Rng rng(21);
  const int rings = 4000;
  for (const double degrees : {0.0, 9.0, 12.0, 14.0, 15.0, 16.0, 17.0, 18.0, 20.0, 25.0, 35.0}) {
    const double phi = DegToRad(degrees);
    int surface = 0;
    for (int k = 0; k < rings; ++k) {
      const Scan ring = SimulateSonarRing(scene, sensor, Se2(0, 0, phi), rng);
      const SonarEcho echo = ring.sonar->true_echo[0];
      ASSERT_TRUE(echo == SonarEcho::kSurface || echo == SonarEcho::kNone) << degrees;
      surface += echo == SonarEcho::kSurface;
    }
    const double p = documented(std::max(0.0, phi - half));
    EXPECT_NEAR(surface / static_cast<double>(rings), p,
                std::max(0.002, 4.0 * std::sqrt(p * (1 - p) / rings)))
        << "axis " << degrees << " deg off the wall's normal";
  }
}

// docs/sonar.md, step 5: after a specular miss, with multipath_probability the reading is the
// mirrored path (here 3 m to the oblique wall, then 1.5 m up to the other one) with the 1 %
// range noise, and otherwise max range; the share of multipath readings is binomial around it.
TEST(SonarSimulator, ASpecularMissIsMultipathAsOftenAsStated) {
  const SonarScene scene(WallsScene({Polyline{{Vec2(1, -2), Vec2(5, 2)}, false},
                                     Polyline{{Vec2(-5, 1.5), Vec2(5, 1.5)}, false}}));
  SonarSensor sensor = OneTransducer();
  Rng rng(22);
  const int rings = 8000;
  int multipath = 0;
  double sum = 0.0, sum_squares = 0.0;
  for (int k = 0; k < rings; ++k) {
    const Scan ring = SimulateSonarRing(scene, sensor, Se2(0, 0, 0), rng);
    const SonarEcho echo = ring.sonar->true_echo[0];
    ASSERT_TRUE(echo == SonarEcho::kMultipath || echo == SonarEcho::kNone);
    if (echo == SonarEcho::kNone) {
      EXPECT_EQ(ring.status[0], BeamStatus::kMaxRange);
      continue;
    }
    ++multipath;
    EXPECT_EQ(ring.sonar->true_feature[0], 0);  // the oblique wall mirrored the axis
    EXPECT_NEAR(ring.truth->range[0], 4.5, 1e-5);
    const double error = ring.ranges[0] - ring.truth->range[0];
    sum += error;
    sum_squares += error * error;
  }
  const double p = sensor.multipath_probability;
  EXPECT_NEAR(multipath / static_cast<double>(rings), p, 4.0 * std::sqrt(p * (1 - p) / rings));
  const double sigma = sensor.Sigma(4.5);
  EXPECT_NEAR(sum / multipath, 0.0, 4.0 * sigma / std::sqrt(multipath));
  EXPECT_NEAR(std::sqrt(sum_squares / multipath), sigma, 0.1 * sigma);
}

TEST(SonarSimulator, ACornerSeenFromInsideEchoesAtItsDistance) {
  // Two walls meeting at (3, 0) at 90 deg, each at 45 deg to the axis: no surface echoes.
  const Scene walls = WallsScene({Polyline{{Vec2(1, 2), Vec2(3, 0), Vec2(1, -2)}, false}});
  const SonarScene scene(walls);
  ASSERT_EQ(scene.corners.size(), 3u);
  const SceneCorner& corner = scene.corners[1];
  EXPECT_EQ(corner.point, Vec2(3, 0));
  EXPECT_TRUE(corner.IsConcaveFrom(Vec2::Zero()));
  EXPECT_FALSE(corner.IsConcaveFrom(Vec2(5, 0)));
  EXPECT_TRUE(scene.corners[0].IsFreeEnd());
  SonarSensor sensor = OneTransducer();
  sensor.multipath_probability = 0.0;
  Rng rng(3);
  int corner_echoes = 0;
  const int rings = 2000;
  for (int k = 0; k < rings; ++k) {
    const Scan ring = SimulateSonarRing(scene, sensor, Se2(0, 0, 0), rng);
    const SonarEcho echo = ring.sonar->true_echo[0];
    ASSERT_TRUE(echo == SonarEcho::kCorner || echo == SonarEcho::kNone);
    if (echo != SonarEcho::kCorner) continue;
    ++corner_echoes;
    EXPECT_EQ(ring.sonar->true_feature[0], 1);
    EXPECT_NEAR(ring.ranges[0], 3.0, 0.2);
  }
  const double p = sensor.concave_corner_return;
  EXPECT_NEAR(corner_echoes / static_cast<double>(rings), p, 4.0 * std::sqrt(p * (1 - p) / rings));
}

TEST(SonarSimulator, AVertexInTheMiddleOfAStraightWallIsNoCorner) {
  // The wall of the first test, split in two where the axis meets it.
  const SonarScene scene(WallsScene({Polyline{{Vec2(3, -2), Vec2(3, 0), Vec2(3, 2)}, false}}));
  ASSERT_EQ(scene.corners.size(), 2u);  // its free ends
  EXPECT_TRUE(scene.corners[0].IsFreeEnd() && scene.corners[1].IsFreeEnd());
  SonarSensor sensor = OneTransducer();
  Rng rng(4);
  int echoes = 0;
  for (int k = 0; k < 2000; ++k) {
    const Scan ring = SimulateSonarRing(scene, sensor, Se2(0, 0, 0), rng);
    const SonarEcho echo = ring.sonar->true_echo[0];
    ASSERT_TRUE(echo == SonarEcho::kSurface || echo == SonarEcho::kNone);
    if (echo == SonarEcho::kSurface) {
      ++echoes;
      EXPECT_NEAR(ring.truth->range[0], 3.0, 1e-12);  // at the foot of the axis, not the vertex
    }
  }
  // Each half echoes on its own (probability surface_return at normal incidence, both at 3 m),
  // so a ring echoes unless both halves are silent: 1 - 0.05^2 = 0.9975 of the rings. One echo
  // chance per ring would give 0.95, over 40 binomial standard deviations (of 0.9975) away; the
  // test allows 4 of them (about 9 rings).
  const double p = 1.0 - std::pow(1.0 - sensor.surface_return, 2);
  EXPECT_NEAR(echoes / 2000.0, p, 4.0 * std::sqrt(p * (1 - p) / 2000.0));
}

TEST(SonarSimulator, AnEchoPastTheMaxRangeIsAMaxRangeReadingWithNoFeature) {
  // A wall 1 cm short of the max range, with 5 cm of noise: 42 % of its echoes arrive late.
  const SonarScene scene(WallsScene({Polyline{{Vec2(4.99, -2), Vec2(4.99, 2)}, false}}));
  SonarSensor sensor = OneTransducer();
  Rng rng(5);
  int on_time = 0;
  const int rings = 4000;
  for (int k = 0; k < rings; ++k) {
    const Scan ring = SimulateSonarRing(scene, sensor, Se2(0, 0, 0), rng);
    const SonarEcho echo = ring.sonar->true_echo[0];
    if (ring.status[0] == BeamStatus::kMaxRange) {
      ASSERT_EQ(echo, SonarEcho::kNone);
      EXPECT_EQ(ring.sonar->true_feature[0], -1);
      EXPECT_TRUE(std::isnan(ring.truth->range[0]));
      EXPECT_EQ(ring.truth->outlier[0], 0);
    } else if (echo == SonarEcho::kSurface) {
      EXPECT_LT(ring.ranges[0], sensor.max_range);
      ++on_time;
    }
  }
  const double sigma = sensor.Sigma(4.99);
  const double p = sensor.surface_return * 0.5 * std::erfc(-(5.0 - 4.99) / sigma / std::sqrt(2.0));
  EXPECT_NEAR(on_time / static_cast<double>(rings), p, 4.0 * std::sqrt(p * (1 - p) / rings));
  // The oblique wall's multipath reading (4.5 m) with a 4 m sensor: never heard.
  const SonarScene oblique(WallsScene({Polyline{{Vec2(1, -2), Vec2(5, 2)}, false},
                                       Polyline{{Vec2(-5, 1.5), Vec2(5, 1.5)}, false}}));
  sensor.multipath_probability = 1.0;
  sensor.max_range = 4.0;
  for (int k = 0; k < 50; ++k) {
    const Scan ring = SimulateSonarRing(oblique, sensor, Se2(0, 0, 0), rng);
    ASSERT_EQ(ring.sonar->true_echo[0], SonarEcho::kNone);
    EXPECT_EQ(ring.status[0], BeamStatus::kMaxRange);
  }
}

TEST(SonarSimulator, RingsCarryTheTransducersOffsetsAndSameSeedSameLog) {
  const Scene scene = *BuiltinScene("office");
  const SonarSensor sensor = *SonarSensor::Preset("pioneer16");
  ASSERT_EQ(sensor.bearings.size(), 16u);
  std::string why;
  EXPECT_TRUE(sensor.IsValid(&why)) << why;
  const auto trajectory = TrajectoryFromWaypoints(scene.waypoints, 0.5, 2.0);
  const Log a = SimulateSonarLog(scene, sensor, trajectory, 9);
  const Log b = SimulateSonarLog(scene, sensor, trajectory, 9);
  ASSERT_EQ(a.scans.size(), trajectory.size());
  EXPECT_TRUE(a.Problems().empty());
  for (std::size_t k = 0; k < a.scans.size(); ++k) {
    EXPECT_EQ(a.scans[k].ranges, b.scans[k].ranges);
    EXPECT_EQ(a.scans[k].sonar->origins, sensor.offsets);
  }
  // The laser log of the same run has the same odometry.
  RangeSensor laser = *RangeSensor::Preset("lms200");
  const Log l = SimulateLog(scene, laser, trajectory, 9);
  for (std::size_t k = 0; k < a.odometry.size(); ++k)
    EXPECT_EQ(a.odometry[k].pose.translation(), l.odometry[k].pose.translation());
  // In a building, most readings are surface or corner echoes or max range.
  std::size_t echoes = 0, readings = 0;
  for (const Scan& ring : a.scans) {
    for (std::size_t i = 0; i < ring.size(); ++i) {
      ++readings;
      const SonarEcho e = ring.sonar->true_echo[i];
      echoes += e == SonarEcho::kSurface || e == SonarEcho::kCorner;
    }
  }
  EXPECT_GT(echoes, readings / 3);
}

// A surface echo's point (PointInWorld) lies on the wall that made it: the cone starts at its
// transducer, not at the ring's centre.
TEST(SonarSimulator, AnEchosPointLiesOnItsWallFromTheTransducersOrigin) {
  const SonarScene scene(WallsScene({Polyline{{Vec2(3, -2), Vec2(3, 2)}, false}}));
  SonarSensor sensor = OneTransducer();
  sensor.offsets = {Vec2(0.2, 0.1)};
  Rng rng(3);
  int echoes = 0;
  for (int k = 0; k < 50; ++k) {
    const Scan ring = SimulateSonarRing(scene, sensor, Se2(0, 0.5, 0), rng);
    if (ring.sonar->true_echo[0] != SonarEcho::kSurface) continue;
    ++echoes;
    EXPECT_NEAR(ring.PointInWorld(0).x(), 3.0, 0.1);  // 1 % noise on 2.8 m: sigma 2.8 cm
    EXPECT_NEAR(ring.PointInWorld(0).y(), 0.6, 1e-12);
  }
  EXPECT_GT(echoes, 30);
}

TEST(SonarSensor, ReportsBadParameters) {
  SonarSensor sensor = OneTransducer();
  std::string why;
  EXPECT_TRUE(sensor.IsValid(&why)) << why;
  sensor.spread = std::numbers::pi;
  EXPECT_FALSE(sensor.IsValid(&why));
  sensor = OneTransducer();
  sensor.offsets = {Vec2(0, 0), Vec2(1, 0)};
  EXPECT_FALSE(sensor.IsValid(&why));
  EXPECT_NE(why.find("offsets"), std::string::npos);
  sensor = OneTransducer();
  sensor.multipath_probability = 1.5;
  EXPECT_FALSE(sensor.IsValid(&why));
  // A spurious reading is uniform below the max range: beyond priormap's bound on returns
  // (1e9 m) the log could not be written.
  sensor = OneTransducer();
  sensor.max_range = 1e10;
  EXPECT_FALSE(sensor.IsValid(&why));
  EXPECT_NE(why.find("max_range 1e+10 m is beyond 1e+09 m"), std::string::npos) << why;
  sensor.max_range = 1e9;
  EXPECT_TRUE(sensor.IsValid(&why)) << why;
  EXPECT_FALSE(SonarSensor::Preset("nonesuch"));
  for (const std::string& name : SonarSensor::PresetNames())
    EXPECT_TRUE(SonarSensor::Preset(name)->IsValid(&why)) << name << ": " << why;
}

// Whether two segments of a closed polyline that are not neighbours touch.
bool SelfIntersects(const Polyline& p) {
  const std::size_t n = p.NumSegments();
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;
      if (IntersectSegments(p.segment(i), p.segment(j))) return true;
    }
  return false;
}

TEST(BuiltinScenes, OfficesAreOneSimpleWallLoopWithThePathInsideClearOfWalls) {
  for (const char* name : {"office", "l-office"}) {
    const auto scene = BuiltinScene(name);
    ASSERT_TRUE(scene) << name;
    EXPECT_TRUE(scene->Problems().empty()) << name;
    ASSERT_EQ(scene->surfaces.size(), 1u);
    const Polyline& walls = std::get<Polyline>(scene->surfaces[0].shape);
    ASSERT_TRUE(walls.closed);
    EXPECT_FALSE(SelfIntersects(walls)) << name;
    // Every trajectory pose is inside the free space and at least 0.3 m from a wall, so that a
    // Pioneer's transducers (0.26 m from its centre at most) are inside too.
    const auto trajectory = TrajectoryFromWaypoints(scene->waypoints, 0.2, 1.0);
    for (const TimedPose& pose : trajectory) {
      EXPECT_TRUE(RingContains(walls.points, pose.pose.translation())) << name;
      EXPECT_GE(walls.Distance(pose.pose.translation()), 0.3) << name;
    }
    // Every doorway is a passage through a 0.2 m wall: four corners each.
    const auto corners = SceneCorners(*scene);
    EXPECT_EQ(corners.size(), walls.points.size());
  }
}

// --- spurious readings -------------------------------------------------------------------------

struct SpuriousReadings {
  std::vector<double> ranges;  // of the readings marked kSpurious
};

// `rings` rings of `sensor` (one transducer) facing a wall at 3 m.
SpuriousReadings SimulateSpurious(const SonarSensor& sensor, int rings, std::uint64_t seed) {
  const SonarScene scene(WallsScene({Polyline{{Vec2(3, -2), Vec2(3, 2)}, false}}));
  Rng rng(seed);
  SpuriousReadings out;
  for (int k = 0; k < rings; ++k) {
    const Scan ring = SimulateSonarRing(scene, sensor, Se2(0, 0, 0), rng);
    if (ring.sonar->true_echo[0] != SonarEcho::kSpurious) continue;
    EXPECT_EQ(ring.truth->outlier[0], 1);
    out.ranges.push_back(ring.ranges[0]);
  }
  return out;
}

SonarSensor WithSpurious(double p) {
  SonarSensor sensor = OneTransducer();
  sensor.spurious_probability = p;
  return sensor;
}

// A reading is spurious with probability p whatever the transducer hears: the share of
// kSpurious readings is binomial(N, p)/N, within 4 standard deviations sqrt(p(1 - p)/N).
TEST(SonarSimulator, SpuriousReadingsAreAsFrequentAsStated) {
  for (const double p : {0.01, 0.2}) {
    const int rings = 20000;
    const SpuriousReadings spurious = SimulateSpurious(WithSpurious(p), rings, 11);
    const double share = static_cast<double>(spurious.ranges.size()) / rings;
    EXPECT_NEAR(share, p, 4.0 * std::sqrt(p * (1 - p) / rings)) << "p = " << p;
  }
}

// Spurious ranges are uniform on [min_range, max_range): all inside it, their mean within 4
// standard errors (max - min)/sqrt(12 m) of the middle, and the counts in 10 equal bins pass
// Pearson's chi-square test at the 0.999 quantile of chi-square with 9 degrees of freedom
// (27.88), so a correct simulator fails it once in a thousand seeds.
TEST(SonarSimulator, SpuriousRangesAreUniformBetweenMinAndMaxRange) {
  const SonarSensor sensor = WithSpurious(0.5);
  const SpuriousReadings spurious = SimulateSpurious(sensor, 20000, 12);
  const double lo = sensor.min_range, hi = sensor.max_range;
  const auto m = static_cast<double>(spurious.ranges.size());
  ASSERT_GT(m, 9000.0);
  constexpr int kBins = 10;
  std::vector<int> counts(kBins, 0);
  double sum = 0.0;
  for (const double r : spurious.ranges) {
    ASSERT_GE(r, lo);
    ASSERT_LT(r, hi);
    sum += r;
    ++counts[static_cast<std::size_t>(
        std::min(kBins - 1, static_cast<int>((r - lo) / (hi - lo) * kBins)))];
  }
  EXPECT_NEAR(sum / m, (lo + hi) / 2, 4.0 * (hi - lo) / std::sqrt(12.0 * m));
  const double expected = m / kBins;
  double chi_square = 0.0;
  for (const int count : counts) chi_square += (count - expected) * (count - expected) / expected;
  EXPECT_LT(chi_square, 27.88) << ::testing::PrintToString(counts);
}

}  // namespace
}  // namespace priormap
