#include <algorithm>
#include <cmath>
#include <limits>

#include <tbb/parallel_for.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/check.hpp>
#include <priormap/core/simulate.hpp>

namespace priormap {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Zero-mean Gaussian range noise with correlation c^|i-j| between beams i and j.
std::vector<double> SampleNoise(std::size_t n, double sigma, double c, Rng& rng) {
  std::vector<double> noise(n);
  const double innovation = sigma * std::sqrt(1.0 - c * c);
  for (std::size_t i = 0; i < n; ++i) {
    noise[i] = i == 0 ? sigma * rng.Normal() : c * noise[i - 1] + innovation * rng.Normal();
  }
  return noise;
}

}  // namespace

Scan SimulateScan(const SceneRayCaster& caster, const RangeSensor& sensor, const Se2& pose,
                  Rng& rng) {
  std::string why;
  PRIORMAP_CHECK(sensor.IsValid(&why), why);
  Scan scan;
  scan.channel = "SIM";
  scan.pose = pose;
  scan.angles = sensor.BeamAngles();
  scan.min_range = sensor.min_range;
  scan.max_range = sensor.max_range;
  const std::size_t n = scan.angles.size();
  scan.sigma.assign(n, sensor.sigma);
  if (sensor.correlation > 0.0) {
    scan.precision = SymmetricBandedMatrix::Ar1Precision(scan.sigma, sensor.correlation);
  }
  scan.ranges.resize(n);
  ScanTruth& truth = scan.truth.emplace();
  truth.range.assign(n, kNaN);
  truth.alpha.assign(n, kNaN);
  truth.surface.assign(n, -1);
  truth.region.assign(n, -1);
  truth.outlier.assign(n, 0);

  // Every random number is drawn whatever happens to the beam, so that changing one
  // probability does not reshuffle the noise of the other beams.
  const std::vector<double> noise = SampleNoise(n, sensor.sigma, sensor.correlation, rng);
  for (std::size_t i = 0; i < n; ++i) {
    const double u_dropout = rng.Uniform();
    const double u_outlier = rng.Uniform();
    const double u_outlier_range = rng.Uniform();
    const Ray ray{pose.translation(), pose.theta() + scan.angles[i]};
    const std::optional<SceneHit> hit = caster.Cast(ray, std::numeric_limits<double>::infinity());
    if (hit) {
      truth.range[i] = hit->range;
      truth.alpha[i] = WrapAngle(hit->normal_angle - pose.theta());
      truth.surface[i] = hit->surface;
      truth.region[i] = hit->region;
    }
    if (!hit || hit->range >= sensor.max_range || u_dropout < sensor.dropout_probability) {
      scan.ranges[i] = sensor.max_range;
    } else if (u_outlier < sensor.outlier_probability) {
      scan.ranges[i] = sensor.min_range + u_outlier_range * (hit->range - sensor.min_range);
      truth.outlier[i] = 1;
    } else {
      scan.ranges[i] = hit->range + noise[i];
    }
  }
  scan.ClassifyAll();
  return scan;
}

double WaypointPathLength(const std::vector<Vec2>& waypoints) {
  double length = 0.0;
  for (std::size_t i = 0; i + 1 < waypoints.size(); ++i)
    length += (waypoints[i + 1] - waypoints[i]).norm();
  return length;
}

double TrajectoryPoseCount(const std::vector<Vec2>& waypoints, double speed, double rate) {
  return std::floor(WaypointPathLength(waypoints) / (speed / rate) + 1e-9) + 1.0;
}

std::vector<TimedPose> TrajectoryFromWaypoints(const std::vector<Vec2>& waypoints, double speed,
                                               double rate) {
  PRIORMAP_CHECK(speed > 0.0 && rate > 0.0, "speed and rate must be positive");
  std::vector<Segment> legs;
  for (std::size_t i = 0; i + 1 < waypoints.size(); ++i) {
    if ((waypoints[i + 1] - waypoints[i]).norm() > 0.0)
      legs.push_back({waypoints[i], waypoints[i + 1]});
  }
  PRIORMAP_CHECK(!legs.empty(), "a trajectory needs at least two distinct waypoints");
  double total = 0.0;
  for (const Segment& leg : legs) total += leg.Length();
  const double step = speed / rate;
  const auto num_poses = static_cast<std::size_t>(TrajectoryPoseCount(waypoints, speed, rate));

  std::vector<TimedPose> poses;
  poses.reserve(num_poses);
  std::size_t leg = 0;
  double leg_start = 0.0;  // arc length at the start of `leg`
  for (std::size_t k = 0; k < num_poses; ++k) {
    const double s = std::min(static_cast<double>(k) * step, total);
    while (leg + 1 < legs.size() && s > leg_start + legs[leg].Length()) {
      leg_start += legs[leg].Length();
      ++leg;
    }
    const Segment& l = legs[leg];
    const double t = std::clamp((s - leg_start) / l.Length(), 0.0, 1.0);
    const Vec2 d = l.b - l.a;
    poses.push_back({static_cast<double>(k) / rate, Se2(l.PointAt(t), std::atan2(d.y(), d.x()))});
  }
  return poses;
}

Log SimulateLog(const Scene& scene, const RangeSensor& sensor,
                const std::vector<TimedPose>& trajectory, std::uint64_t seed,
                const LogSimulationOptions& options) {
  const SceneRayCaster caster(scene);
  Log log;
  log.pose_source = PoseSource::kGroundTruth;
  const std::size_t n = trajectory.size();

  // Odometry: the true increments with noise proportional to the motion, integrated.
  Rng odom_rng = Rng::ForStream(seed, 0);
  std::vector<Se2> odom(n);
  for (std::size_t k = 0; k < n; ++k) {
    if (k == 0) {
      odom[k] = trajectory[k].pose;
      continue;
    }
    const Se2 delta = trajectory[k - 1].pose.Between(trajectory[k].pose);
    const double distance = delta.translation().norm();
    const double sigma_t = options.odom_sigma_per_meter * distance;
    const double sigma_r = options.odom_sigma_rad_per_rad * std::abs(delta.theta()) +
                           options.odom_sigma_rad_per_meter * distance;
    const Se2 noisy(delta.x() + sigma_t * odom_rng.Normal(),
                    delta.y() + sigma_t * odom_rng.Normal(),
                    delta.theta() + sigma_r * odom_rng.Normal());
    odom[k] = odom[k - 1].Compose(noisy);
  }

  log.scans.resize(n);
  tbb::parallel_for(std::size_t{0}, n, [&](std::size_t k) {
    Rng rng = Rng::ForStream(seed, k + 1);
    Scan scan = SimulateScan(caster, sensor, trajectory[k].pose, rng);
    scan.timestamp = trajectory[k].time;
    scan.odom_pose = odom[k];
    log.scans[k] = std::move(scan);
  });

  for (std::size_t k = 0; k < n; ++k) {
    const double t = trajectory[k].time;
    OdometryRecord record{t, odom[k], 0.0, 0.0, 0.0, std::nullopt};
    if (k > 0) {
      const double dt = t - trajectory[k - 1].time;
      const Se2 delta = odom[k - 1].Between(odom[k]);
      record.tv = delta.translation().norm() / dt;
      record.rv = delta.theta() / dt;
    }
    log.odometry.push_back(record);
    log.true_poses.push_back({t, trajectory[k].pose, odom[k], std::nullopt});
    log.order.push_back({Log::RecordKind::kOdometry, k});
    log.order.push_back({Log::RecordKind::kTruePose, k});
    log.order.push_back({Log::RecordKind::kScan, k});
  }
  return log;
}

}  // namespace priormap
