// The sonar simulator of docs/sonar.md: a ring of cones, each hearing the first echo of the
// surfaces it sees close to perpendicular and of the corners it sees.
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include <tbb/parallel_for.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/check.hpp>
#include <priormap/core/sonar_simulate.hpp>

namespace priormap {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// A feature that would echo, in the cone of one transducer.
struct Echo {
  double range = 0.0;
  double probability = 0.0;
  SonarEcho kind = SonarEcho::kSurface;
  int feature = -1;            // region, or corner index
  double normal_angle = kNaN;  // world frame, surfaces only
  int surface = -1;
  int region = -1;
};

// One transducer: its cone's apex, axis and half-angle.
struct Cone {
  Vec2 origin;
  double axis = 0.0;
  double half = 0.0;
  double max_range = 0.0;

  [[nodiscard]] bool Contains(const Vec2& p) const {
    const Vec2 d = p - origin;
    const double r = d.norm();
    return r > 0.0 && r <= max_range &&
           std::abs(AngleDifference(std::atan2(d.y(), d.x()), axis)) <= half;
  }
};

// True when nothing stands between the cone's apex and p (p itself lies on what it belongs to).
bool Visible(const SceneRayCaster& caster, const Vec2& origin, const Vec2& p) {
  const Vec2 d = p - origin;
  const double r = d.norm();
  const auto hit = caster.Cast({origin, std::atan2(d.y(), d.x())}, kInf);
  return !hit || hit->range >= r * (1.0 - 1e-9);
}

// The point of a primitive the wave meets at normal incidence (the foot of the perpendicular
// from the apex; towards a circle's centre), if it exists.
std::optional<Vec2> NormalFoot(const ScenePrimitive& primitive, const Vec2& origin) {
  if (const auto* s = std::get_if<Segment>(&primitive.shape)) {
    const Vec2 along = s->b - s->a;
    const double t = (origin - s->a).dot(along) / along.squaredNorm();
    if (t < 0.0 || t > 1.0) return std::nullopt;
    return s->PointAt(t);
  }
  const Circle& c = std::get<Circle>(primitive.shape);
  const Vec2 out = origin - c.center;
  const double distance = out.norm();
  if (distance <= c.radius) return std::nullopt;  // inside: every point is at normal incidence
  return Vec2(c.center + c.radius * out / distance);
}

// Echo probability of a surface whose least incidence in the cone is `incidence`: a logistic
// fall-off past the critical angle, equal to surface_return at normal incidence.
double SurfaceEchoProbability(const SonarSensor& sensor, double incidence) {
  const auto logistic = [&](double x) {
    return 1.0 / (1.0 + std::exp((x - sensor.critical_incidence) / sensor.incidence_softness));
  };
  return sensor.surface_return * logistic(incidence) / logistic(0.0);
}

// The surfaces the cone sees (sampled by rays), each at its least incidence, and its corners.
std::vector<Echo> EchoesInCone(const SonarScene& scene, const SonarSensor& sensor,
                               const Cone& cone) {
  struct Seen {
    double incidence;
    double range;
    double normal_angle;
    int surface;
  };
  std::map<int, Seen> seen;  // by region: ordered, so that ties resolve the same way each time
  const int n = sensor.rays_per_cone;
  for (int j = 0; j < n; ++j) {
    const double angle = cone.axis - cone.half + 2.0 * cone.half * j / (n - 1);
    const auto hit = scene.caster.Cast({cone.origin, angle}, cone.max_range);
    if (!hit) continue;
    const double incidence =
        std::acos(std::clamp(-UnitVector(angle).dot(UnitVector(hit->normal_angle)), -1.0, 1.0));
    auto [it, inserted] =
        seen.try_emplace(hit->region, Seen{incidence, hit->range, hit->normal_angle, hit->surface});
    if (!inserted && incidence < it->second.incidence)
      it->second = {incidence, hit->range, hit->normal_angle, hit->surface};
  }
  std::vector<Echo> echoes;
  const auto& primitives = scene.caster.primitives();
  for (auto& [region, s] : seen) {
    const auto foot = NormalFoot(primitives[static_cast<std::size_t>(region)], cone.origin);
    if (foot && cone.Contains(*foot) && Visible(scene.caster, cone.origin, *foot)) {
      const Vec2 back = cone.origin - *foot;
      s = {0.0, back.norm(), std::atan2(back.y(), back.x()), s.surface};
    }
    echoes.push_back({.range = s.range,
                      .probability = SurfaceEchoProbability(sensor, s.incidence),
                      .kind = SonarEcho::kSurface,
                      .feature = region,
                      .normal_angle = s.normal_angle,
                      .surface = s.surface,
                      .region = region});
  }
  for (std::size_t k = 0; k < scene.corners.size(); ++k) {
    const SceneCorner& corner = scene.corners[k];
    if (!cone.Contains(corner.point) || !Visible(scene.caster, cone.origin, corner.point)) continue;
    echoes.push_back({.range = (corner.point - cone.origin).norm(),
                      .probability = corner.IsConcaveFrom(cone.origin)
                                         ? sensor.concave_corner_return
                                         : sensor.convex_corner_return,
                      .kind = SonarEcho::kCorner,
                      .feature = static_cast<int>(k),
                      .surface = corner.surface,
                      .region = corner.regions[0]});
  }
  return echoes;
}

// The wave along the axis, mirrored by the first surface and heard back from the next one:
// the echo of the retraced path, or nullopt when it leaves unheard.
std::optional<Echo> MultipathEcho(const SceneRayCaster& caster, const Cone& cone) {
  const auto first = caster.Cast({cone.origin, cone.axis}, cone.max_range);
  if (!first) return std::nullopt;
  const Vec2 d = UnitVector(cone.axis);
  const Vec2 normal = UnitVector(first->normal_angle);
  const Vec2 mirrored = d - 2.0 * d.dot(normal) * normal;
  const Vec2 at = cone.origin + first->range * d;
  // Start a hair off the mirror so that it is not hit again.
  const auto second =
      caster.Cast({at + 1e-6 * mirrored, std::atan2(mirrored.y(), mirrored.x())}, kInf);
  if (!second) return std::nullopt;
  return Echo{.range = first->range + 1e-6 + second->range,
              .probability = 1.0,
              .kind = SonarEcho::kMultipath,
              .feature = first->region,
              .normal_angle = first->normal_angle,
              .surface = first->surface,
              .region = first->region};
}

}  // namespace

Scan SimulateSonarRing(const SonarScene& scene, const SonarSensor& sensor, const Se2& T_world_robot,
                       Rng& rng) {
  std::string why;
  PRIORMAP_CHECK(sensor.IsValid(&why), why);
  const std::size_t n = sensor.bearings.size();
  Scan scan;
  scan.channel = "SONAR";
  scan.pose = T_world_robot;
  scan.angles = sensor.bearings;
  scan.min_range = sensor.min_range;
  scan.max_range = sensor.max_range;
  scan.ranges.assign(n, sensor.max_range);
  scan.sigma.assign(n, sensor.Sigma(sensor.max_range));
  ScanTruth& truth = scan.truth.emplace();
  truth.range.assign(n, kNaN);
  truth.alpha.assign(n, kNaN);
  truth.surface.assign(n, -1);
  truth.region.assign(n, -1);
  truth.outlier.assign(n, 0);
  SonarFields& sonar = scan.sonar.emplace();
  sonar.spread = sensor.spread;
  sonar.origins = sensor.offsets;
  sonar.true_echo.assign(n, SonarEcho::kNone);
  sonar.true_feature.assign(n, -1);

  for (std::size_t i = 0; i < n; ++i) {
    // The same draws whatever happens to the reading, so that changing one probability does
    // not reshuffle the other readings' noise.
    const double u_spurious = rng.Uniform();
    const double u_spurious_range = rng.Uniform();
    const double u_multipath = rng.Uniform();
    const double noise = rng.Normal();
    const Cone cone{.origin = T_world_robot.Transform(sonar.Origin(i)),
                    .axis = T_world_robot.theta() + sensor.bearings[i],
                    .half = sensor.spread / 2.0,
                    .max_range = sensor.max_range};

    std::vector<Echo> echoes = EchoesInCone(scene, sensor, cone);
    std::sort(echoes.begin(), echoes.end(), [](const Echo& a, const Echo& b) {
      return std::tie(a.range, a.kind, a.feature) < std::tie(b.range, b.kind, b.feature);
    });
    // The first echo heard: each feature in depth order echoes independently, and the ones
    // closer than the blanking distance are not heard.
    std::optional<Echo> heard;
    for (const Echo& echo : echoes) {
      const bool echoes_back = rng.Uniform() < echo.probability;
      if (!heard && echoes_back && echo.range >= sensor.min_range) heard = echo;
    }
    if (!heard && u_multipath < sensor.multipath_probability)
      heard = MultipathEcho(scene.caster, cone);

    // An echo that comes back after the sensor stops listening (a multipath leg, or a feature
    // near the max range pushed past it by the noise) is not heard: a max-range reading, with
    // no feature to credit.
    const double heard_range =
        heard ? heard->range + sensor.Sigma(heard->range) * noise : sensor.max_range;
    if (u_spurious < sensor.spurious_probability) {
      scan.ranges[i] = sensor.min_range + u_spurious_range * (sensor.max_range - sensor.min_range);
      sonar.true_echo[i] = SonarEcho::kSpurious;
      truth.outlier[i] = 1;
    } else if (heard && heard_range < sensor.max_range) {
      scan.ranges[i] = heard_range;
      scan.sigma[i] = sensor.Sigma(heard->range);
      sonar.true_echo[i] = heard->kind;
      sonar.true_feature[i] = heard->feature;
      truth.range[i] = heard->range;
      truth.alpha[i] = WrapAngle(heard->normal_angle - T_world_robot.theta());
      truth.surface[i] = heard->surface;
      truth.region[i] = heard->region;
      truth.outlier[i] = heard->kind == SonarEcho::kMultipath ? 1 : 0;
    }
  }
  scan.ClassifyAll();
  return scan;
}

Log SimulateSonarLog(const Scene& scene, const SonarSensor& sensor,
                     const std::vector<TimedPose>& trajectory, std::uint64_t seed,
                     const LogSimulationOptions& options) {
  std::string why;
  PRIORMAP_CHECK(sensor.IsValid(&why), why);
  // SimulateLog writes the odometry and true poses; its one-beam scans are then replaced by
  // the rings, each simulated from the true pose with the stream SimulateLog gave that scan.
  RangeSensor one_beam;
  one_beam.num_beams = 1;
  one_beam.fov = 1e-3;
  one_beam.max_range = sensor.max_range;
  Log log = SimulateLog(scene, one_beam, trajectory, seed, options);
  const SonarScene sonar_scene(scene);
  tbb::parallel_for(std::size_t{0}, log.scans.size(), [&](std::size_t k) {
    Rng rng = Rng::ForStream(seed, k + 1);
    Scan ring = SimulateSonarRing(sonar_scene, sensor, trajectory[k].pose, rng);
    ring.timestamp = log.scans[k].timestamp;
    ring.odom_pose = log.scans[k].odom_pose;
    log.scans[k] = std::move(ring);
  });
  return log;
}

}  // namespace priormap
