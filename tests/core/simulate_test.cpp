#include <cmath>
#include <set>
#include <vector>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/simulate.hpp>

namespace priormap {
namespace {

Scan Simulate(const std::string& scene_name, const RangeSensor& sensor, std::uint64_t seed) {
  const Scene scene = *BuiltinScene(scene_name);
  Rng rng(seed);
  return SimulateScan(SceneRayCaster(scene), sensor, *scene.default_pose, rng);
}

TEST(RangeSensor, AFullCircleSweepsEachDirectionOnceAndASingleBeamLooksAhead) {
  RangeSensor sensor = *RangeSensor::Preset("utm30");
  sensor.fov = kTwoPi;
  sensor.num_beams = 8;
  const std::vector<double> angles = sensor.BeamAngles();
  ASSERT_EQ(angles.size(), 8U);
  for (std::size_t i = 0; i < angles.size(); ++i)
    EXPECT_NEAR(angles[i], -kPi + static_cast<double>(i) * kPi / 4, 1e-12) << i;
  sensor.num_beams = 1;
  EXPECT_EQ(sensor.BeamAngles(), std::vector<double>{0.0});
  sensor.fov = DegToRad(270.0);
  sensor.num_beams = 3;
  EXPECT_NEAR(sensor.BeamAngles().back(), DegToRad(135.0), 1e-12);
}

RangeSensor Utm30() {
  return *RangeSensor::Preset("utm30");
}

TEST(RangeSensor, PresetsAreAsSpecified) {
  const RangeSensor utm = Utm30();
  EXPECT_EQ(utm.num_beams, 1081);
  EXPECT_NEAR(utm.fov, DegToRad(270), 1e-12);
  EXPECT_DOUBLE_EQ(utm.sigma, 0.01);
  EXPECT_DOUBLE_EQ(utm.max_range, 30.0);
  const RangeSensor lms = *RangeSensor::Preset("lms200");
  EXPECT_EQ(lms.num_beams, 181);
  EXPECT_NEAR(lms.fov, kPi, 1e-12);
  EXPECT_DOUBLE_EQ(lms.max_range, 8.0);
  const std::vector<double> angles = lms.BeamAngles();
  EXPECT_DOUBLE_EQ(angles.front(), -kPi / 2);
  EXPECT_NEAR(angles.back(), kPi / 2, 1e-12);
  EXPECT_NEAR(angles[1] - angles[0], DegToRad(1.0), 1e-12);
  EXPECT_FALSE(RangeSensor::Preset("sonar-9000"));
}

TEST(RangeSensor, InvalidParametersAreExplained) {
  RangeSensor s = Utm30();
  std::string why;
  s.correlation = 1.0;
  EXPECT_FALSE(s.IsValid(&why));
  EXPECT_NE(why.find("correlation"), std::string::npos);
  s = Utm30();
  s.max_range = s.min_range;
  EXPECT_FALSE(s.IsValid(&why));
  EXPECT_NE(why.find("max_range"), std::string::npos);
}

TEST(SimulateScan, TruthMatchesTheRayCaster) {
  const Scene scene = *BuiltinScene("l-room");
  const SceneRayCaster caster(scene);
  const Scan scan = Simulate("l-room", Utm30(), 1);
  ASSERT_TRUE(scan.truth);
  EXPECT_TRUE(scan.Problems().empty());
  for (std::size_t i = 0; i < scan.size(); ++i) {
    const auto hit =
        caster.Cast(Ray{scan.pose.translation(), scan.pose.theta() + scan.angles[i]}, 1e9);
    ASSERT_TRUE(hit);
    EXPECT_EQ(scan.truth->range[i], hit->range);
    EXPECT_NEAR(AngleDifference(scan.truth->alpha[i] + scan.pose.theta(), hit->normal_angle), 0.0,
                1e-12);
    EXPECT_EQ(scan.truth->region[i], hit->region);
    EXPECT_EQ(scan.truth->surface[i], hit->surface);
  }
}

// The residuals over several scans are N(0, sigma^2): mean within 4 standard errors, variance
// within 4 standard deviations of its sampling distribution (chi-square, normal approximation).
TEST(SimulateScan, NoiseHasTheStatedSigma) {
  for (double sigma : {0.01, 0.05}) {
    RangeSensor sensor = Utm30();
    sensor.sigma = sigma;
    double sum = 0.0, sum_sq = 0.0;
    std::size_t n = 0;
    for (std::uint64_t seed = 1; seed <= 10; ++seed) {
      const Scan scan = Simulate("l-room", sensor, seed);
      for (std::size_t i = 0; i < scan.size(); ++i) {
        if (!scan.IsValid(i)) continue;
        const double e = scan.ranges[i] - scan.truth->range[i];
        sum += e;
        sum_sq += e * e;
        ++n;
      }
    }
    ASSERT_GT(n, 10000u);
    const double mean = sum / static_cast<double>(n);
    const double variance = (sum_sq - n * mean * mean) / static_cast<double>(n - 1);
    EXPECT_NEAR(mean, 0.0, 4 * sigma / std::sqrt(static_cast<double>(n)));
    EXPECT_NEAR(variance / (sigma * sigma), 1.0, 4 * std::sqrt(2.0 / static_cast<double>(n - 1)));
  }
}

TEST(SimulateScan, CorrelatedNoiseHasTheStatedNeighbourCorrelation) {
  RangeSensor sensor = Utm30();
  sensor.correlation = 0.6;
  double sum_xy = 0.0, sum_xx = 0.0;
  std::size_t n = 0;
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    const Scan scan = Simulate("square", sensor, seed);
    ASSERT_TRUE(scan.precision);
    EXPECT_EQ(scan.precision->bandwidth(), 1u);
    for (std::size_t i = 0; i + 1 < scan.size(); ++i) {
      const double a = scan.ranges[i] - scan.truth->range[i],
                   b = scan.ranges[i + 1] - scan.truth->range[i + 1];
      sum_xy += a * b;
      sum_xx += a * a;
      ++n;
    }
  }
  const double rho = sum_xy / sum_xx;
  // Standard error of a lag-1 autocorrelation estimate of an AR(1) series: sqrt((1 - c^2) / n);
  // the series are 10 independent scans, so this is conservative.
  EXPECT_NEAR(rho, 0.6, 4 * std::sqrt((1 - 0.36) / static_cast<double>(n)));
}

TEST(SimulateScan, OutliersAreShortAndAsFrequentAsStated) {
  RangeSensor sensor = Utm30();
  sensor.outlier_probability = 0.1;
  std::size_t outliers = 0, beams = 0;
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const Scan scan = Simulate("square", sensor, seed);
    for (std::size_t i = 0; i < scan.size(); ++i) {
      ++beams;
      if (!scan.truth->outlier[i]) continue;
      ++outliers;
      EXPECT_LT(scan.ranges[i], scan.truth->range[i]);
      EXPECT_GE(scan.ranges[i], sensor.min_range);
    }
  }
  const double p = 0.1;
  EXPECT_NEAR(static_cast<double>(outliers) / beams, p, 4 * std::sqrt(p * (1 - p) / beams));
}

TEST(SimulateScan, DropoutsAndFarSurfacesGiveMaxRangeReadings) {
  RangeSensor sensor = Utm30();
  sensor.dropout_probability = 0.2;
  const Scan scan = Simulate("square", sensor, 3);
  std::size_t max_range = 0;
  for (std::size_t i = 0; i < scan.size(); ++i) {
    if (scan.status[i] != BeamStatus::kMaxRange) continue;
    ++max_range;
    EXPECT_EQ(scan.ranges[i], sensor.max_range);
  }
  EXPECT_NEAR(static_cast<double>(max_range) / scan.size(), 0.2,
              4 * std::sqrt(0.2 * 0.8 / scan.size()));

  // Through the corridor's doorway nothing is within range.
  const Scan corridor = Simulate("corridor", Utm30(), 1);
  std::size_t no_hit = 0;
  for (std::size_t i = 0; i < corridor.size(); ++i) {
    if (std::isnan(corridor.truth->range[i])) {
      ++no_hit;
      EXPECT_EQ(corridor.status[i], BeamStatus::kMaxRange);
      EXPECT_EQ(corridor.truth->region[i], -1);
    }
  }
  EXPECT_GT(no_hit, 0u);
}

TEST(SimulateScan, ReadingsBelowMinRangeAreInvalid) {
  RangeSensor sensor = Utm30();
  sensor.min_range = 2.5;  // the l-room default pose is closer than that to several walls
  const Scan scan = Simulate("l-room", sensor, 1);
  std::size_t invalid = 0;
  for (std::size_t i = 0; i < scan.size(); ++i) {
    if (scan.ranges[i] < 2.5) {
      EXPECT_EQ(scan.status[i], BeamStatus::kInvalid);
      ++invalid;
    }
  }
  EXPECT_GT(invalid, 0u);
}

TEST(SimulateScan, SameSeedSameScanOtherSeedOtherScan) {
  EXPECT_EQ(Simulate("circle", Utm30(), 5).ranges, Simulate("circle", Utm30(), 5).ranges);
  EXPECT_NE(Simulate("circle", Utm30(), 5).ranges, Simulate("circle", Utm30(), 6).ranges);
}

// "A pose that sees all of a room scene": every wall region is hit from the default pose (the
// back faces of clutter cannot be).
TEST(SimulateScan, DefaultPoseSeesEveryRegion) {
  for (const std::string& name : BuiltinSceneNames()) {
    // Rooms behind doorways: no single pose sees every wall of the offices.
    if (name == "office" || name == "l-office") continue;
    const Scene scene = *BuiltinScene(name);
    const Scan scan = Simulate(name, Utm30(), 1);
    const std::set<int> seen(scan.truth->region.begin(), scan.truth->region.end());
    for (const ScenePrimitive& p : scene.Primitives()) {
      if (p.clutter) continue;
      EXPECT_TRUE(seen.count(p.region)) << name << ": region " << p.region << " not seen";
    }
  }
}

TEST(Trajectory, FollowsWaypointsAtConstantSpeed) {
  const std::vector<TimedPose> poses = TrajectoryFromWaypoints({{0, 0}, {2, 0}, {2, 1}}, 0.5, 5.0);
  ASSERT_EQ(poses.size(), 31u);  // 3 m at 0.1 m per pose
  EXPECT_DOUBLE_EQ(poses[1].time, 0.2);
  EXPECT_TRUE(poses[10].pose.translation().isApprox(Vec2(1, 0)));
  EXPECT_NEAR(poses[10].pose.theta(), 0.0, 1e-12);
  EXPECT_TRUE(poses[25].pose.translation().isApprox(Vec2(2, 0.5)));
  EXPECT_NEAR(poses[25].pose.theta(), kPi / 2, 1e-12);
  EXPECT_TRUE(poses.back().pose.translation().isApprox(Vec2(2, 1)));
}

TEST(Trajectory, ItsPoseCountIsKnownBeforeThePosesAreMade) {
  const std::vector<Vec2> path = {{0, 0}, {2, 0}, {2, 0}, {2, 1}, {-0.3, 1.7}};
  EXPECT_DOUBLE_EQ(WaypointPathLength(path), 3.0 + std::hypot(2.3, 0.7));
  for (const double speed : {0.07, 0.25, 0.5, 1.0, 3.0})
    for (const double rate : {0.5, 2.0, 5.0, 18.0})
      EXPECT_EQ(TrajectoryPoseCount(path, speed, rate),
                static_cast<double>(TrajectoryFromWaypoints(path, speed, rate).size()))
          << speed << " m/s, " << rate << " per s";
  EXPECT_EQ(TrajectoryPoseCount(path, 0.5, 5.0), 31.0 + std::floor(std::hypot(2.3, 0.7) / 0.1));
  EXPECT_GT(TrajectoryPoseCount(path, 1e-300, 1e300), 1e300);  // refusable, not wrapped round
}

TEST(SimulateLog, IsLocalizedReproducibleAndIndependentOfThreads) {
  const Scene scene = *BuiltinScene("l-room");
  const RangeSensor sensor = *RangeSensor::Preset("lms200");
  const std::vector<TimedPose> trajectory = TrajectoryFromWaypoints(scene.waypoints, 0.5, 5.0);
  const Log log = SimulateLog(scene, sensor, trajectory, 7);
  ASSERT_EQ(log.scans.size(), trajectory.size());
  EXPECT_EQ(log.odometry.size(), trajectory.size());
  EXPECT_EQ(log.true_poses.size(), trajectory.size());
  EXPECT_EQ(log.pose_source, PoseSource::kGroundTruth);
  EXPECT_TRUE(log.Problems().empty());
  for (std::size_t k = 0; k < log.scans.size(); ++k) {
    EXPECT_TRUE(IsApprox(log.scans[k].pose, trajectory[k].pose, 0.0));
    EXPECT_EQ(log.scans[k].timestamp, trajectory[k].time);
  }
  // Odometry starts at the truth and drifts away from it.
  EXPECT_TRUE(IsApprox(*log.scans.front().odom_pose, trajectory.front().pose, 0.0));
  EXPECT_GT(
      (log.scans.back().odom_pose->translation() - trajectory.back().pose.translation()).norm(),
      1e-4);

  Log single_threaded;
  {
    tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
    single_threaded = SimulateLog(scene, sensor, trajectory, 7);
  }
  for (std::size_t k = 0; k < log.scans.size(); ++k)
    EXPECT_EQ(log.scans[k].ranges, single_threaded.scans[k].ranges);
  EXPECT_NE(SimulateLog(scene, sensor, trajectory, 8).scans[3].ranges, log.scans[3].ranges);
}

// --- correlated noise: marginal variance and lag-2 autocorrelation ---------------------------

constexpr double kCorrelation = 0.6;
constexpr std::uint64_t kCorrelatedScans = 20;  // 20 x 1081 beams

// The residuals (range - true range) of kCorrelatedScans scans with neighbour correlation 0.6,
// one vector per scan (an AR(1) series each, started in its stationary distribution).
std::vector<std::vector<double>> CorrelatedResiduals() {
  RangeSensor sensor = Utm30();
  sensor.correlation = kCorrelation;
  std::vector<std::vector<double>> residuals;
  for (std::uint64_t seed = 101; seed < 101 + kCorrelatedScans; ++seed) {
    const Scan scan = Simulate("square", sensor, seed);
    std::vector<double>& e = residuals.emplace_back();
    for (std::size_t i = 0; i < scan.size(); ++i) {
      EXPECT_TRUE(scan.IsValid(i)) << "beam " << i;  // no dropouts or outliers in utm30
      e.push_back(scan.ranges[i] - scan.truth->range[i]);
    }
  }
  return residuals;
}

// The innovations are scaled by sqrt(1 - c^2) so that correlating the noise leaves each beam's
// variance at sigma^2. The estimate mean(e^2) (the mean is known to be 0) has variance
// 2 sigma^4 (1 + 2 sum_k c^(2k)) / n = 2 sigma^4 (1 + c^2) / ((1 - c^2) n) for an AR(1) series;
// the test allows 4 of those standard errors. Without the sqrt(1 - c^2) the variance would be
// sigma^2 / (1 - c^2) = 1.56 sigma^2.
TEST(SimulateScan, CorrelatedNoiseKeepsTheStatedMarginalVariance) {
  const double sigma = Utm30().sigma, c = kCorrelation;
  double sum_squares = 0.0;
  std::size_t n = 0;
  for (const std::vector<double>& e : CorrelatedResiduals()) {
    for (double x : e) sum_squares += x * x;
    n += e.size();
  }
  ASSERT_GT(n, 20000u);
  const double variance = sum_squares / static_cast<double>(n);
  const double standard_error =
      sigma * sigma * std::sqrt(2 * (1 + c * c) / ((1 - c * c) * static_cast<double>(n)));
  EXPECT_NEAR(variance, sigma * sigma, 4 * standard_error);
}

// Beams two apart have correlation c^2 = 0.36 (the AR(1) structure, not just the neighbour
// correlation). Bartlett's formula for the lag-k autocorrelation estimate of an AR(1) series,
// var(r_k) = ((1 + c^2)(1 - c^(2k)) / (1 - c^2) - 2k c^(2k)) / n, gives for k = 2
// (1 + 2c^2 - 3c^4) / n = 1.33 / n: a little more than the (1 - c^4) / n = 0.87 / n of the
// simpler rule of thumb, so the test uses Bartlett's (4 standard errors = 0.032 here). The
// scans are independent series of 1081 beams each, so n counts the pairs within a scan only.
TEST(SimulateScan, CorrelatedNoiseHasLagTwoAutocorrelationCSquared) {
  const double c = kCorrelation;
  double sum_lag2 = 0.0, sum_squares = 0.0;
  std::size_t n = 0;
  for (const std::vector<double>& e : CorrelatedResiduals()) {
    for (std::size_t i = 0; i + 2 < e.size(); ++i) {
      sum_lag2 += e[i] * e[i + 2];
      sum_squares += e[i] * e[i];
      ++n;
    }
  }
  const double r2 = sum_lag2 / sum_squares;
  const double c2 = c * c, c4 = c2 * c2;
  EXPECT_NEAR(r2, c2, 4 * std::sqrt((1 + 2 * c2 - 3 * c4) / static_cast<double>(n)));
}

}  // namespace
}  // namespace priormap
