#include "testing/log_equality.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <sstream>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

namespace priormap::testing {
namespace {

bool SameDouble(double a, double b) {
  return (std::isnan(a) && std::isnan(b)) ||
         std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}

// Names the first differences between two values.
class Differences {
 public:
  void Check(bool same, const std::string& what) {
    if (!same && notes_.size() < 10) notes_.push_back(what);
  }
  void Number(const std::string& what, double a, double b) {
    Check(SameDouble(a, b), what + ": " + Str(a) + " vs " + Str(b));
  }
  template <typename T>
  void Value(const std::string& what, const T& a, const T& b) {
    Check(a == b, what + " differs");
  }
  template <typename T>
  void Values(const std::string& what, const std::vector<T>& a, const std::vector<T>& b) {
    if (a.size() != b.size()) {
      Check(false, what + ": size " + std::to_string(a.size()) + " vs " + std::to_string(b.size()));
      return;
    }
    for (std::size_t i = 0; i < a.size(); ++i) {
      if constexpr (std::is_same_v<T, double>) {
        if (!SameDouble(a[i], b[i])) {
          return Number(what + "[" + std::to_string(i) + "]", a[i], b[i]);
        }
      } else if (!(a[i] == b[i])) {
        return Check(false, what + "[" + std::to_string(i) + "] differs");
      }
    }
  }
  void Pose(const std::string& what, const Se2& a, const Se2& b) {
    Number(what + ".x", a.x(), b.x());
    Number(what + ".y", a.y(), b.y());
    Number(what + ".theta", a.theta(), b.theta());
  }
  void Pose(const std::string& what, const std::optional<Se2>& a, const std::optional<Se2>& b) {
    Check(a.has_value() == b.has_value(), what + ": present in one only");
    if (a && b) Pose(what, *a, *b);
  }
  ::testing::AssertionResult Result() const {
    if (notes_.empty()) return ::testing::AssertionSuccess();
    ::testing::AssertionResult result = ::testing::AssertionFailure();
    for (const std::string& note : notes_) result << "\n  " << note;
    return result;
  }

 private:
  static std::string Str(double v) {
    std::ostringstream out;
    out.precision(17);
    out << v;
    return out.str();
  }
  std::vector<std::string> notes_;
};

void CompareCarmen(Differences& d, const std::string& at, const CarmenLaserFields& a,
                   const CarmenLaserFields& b) {
  d.Value(at + "has_timestamps", a.has_timestamps, b.has_timestamps);
  d.Value(at + "host", a.host, b.host);
  d.Number(at + "logger_timestamp", a.logger_timestamp, b.logger_timestamp);
  d.Value(at + "laser_type", a.laser_type, b.laser_type);
  d.Number(at + "start_angle", a.start_angle, b.start_angle);
  d.Number(at + "fov", a.fov, b.fov);
  d.Number(at + "angular_resolution", a.angular_resolution, b.angular_resolution);
  d.Check(a.maximum_range.has_value() == b.maximum_range.has_value(),
          at + "maximum_range: present in one only");
  if (a.maximum_range && b.maximum_range)
    d.Number(at + "maximum_range", *a.maximum_range, *b.maximum_range);
  d.Number(at + "accuracy", a.accuracy, b.accuracy);
  d.Value(at + "remission_mode", a.remission_mode, b.remission_mode);
  d.Values(at + "remissions", a.remissions, b.remissions);
  d.Number(at + "tv", a.tv, b.tv);
  d.Number(at + "rv", a.rv, b.rv);
  d.Number(at + "forward_safety_dist", a.forward_safety_dist, b.forward_safety_dist);
  d.Number(at + "side_safety_dist", a.side_safety_dist, b.side_safety_dist);
  d.Number(at + "turn_axis", a.turn_axis, b.turn_axis);
}

void CompareRecordFields(Differences& d, const std::string& at,
                         const std::optional<CarmenRecordFields>& a,
                         const std::optional<CarmenRecordFields>& b) {
  d.Check(a.has_value() == b.has_value(), at + "carmen: present in one only");
  if (!a || !b) return;
  d.Value(at + "has_timestamps", a->has_timestamps, b->has_timestamps);
  d.Value(at + "host", a->host, b->host);
  d.Number(at + "logger_timestamp", a->logger_timestamp, b->logger_timestamp);
}

void CompareScans(Differences& d, const std::string& at, const Scan& a, const Scan& b) {
  d.Value(at + "channel", a.channel, b.channel);
  d.Number(at + "timestamp", a.timestamp, b.timestamp);
  d.Pose(at + "pose", a.pose, b.pose);
  d.Pose(at + "robot_pose", a.robot_pose, b.robot_pose);
  d.Pose(at + "odom_pose", a.odom_pose, b.odom_pose);
  d.Values(at + "angles", a.angles, b.angles);
  d.Values(at + "ranges", a.ranges, b.ranges);
  d.Values(at + "sigma", a.sigma, b.sigma);
  d.Values(at + "status", a.status, b.status);
  d.Number(at + "min_range", a.min_range, b.min_range);
  d.Number(at + "max_range", a.max_range, b.max_range);
  d.Check(a.precision.has_value() == b.precision.has_value(),
          at + "precision: present in one only");
  if (a.precision && b.precision) {
    d.Value(at + "precision size", a.precision->size(), b.precision->size());
    d.Value(at + "precision bandwidth", a.precision->bandwidth(), b.precision->bandwidth());
    const Eigen::MatrixXd& ba = a.precision->band();
    const Eigen::MatrixXd& bb = b.precision->band();
    if (ba.rows() == bb.rows() && ba.cols() == bb.cols()) {
      d.Values(at + "precision band", std::vector<double>(ba.data(), ba.data() + ba.size()),
               std::vector<double>(bb.data(), bb.data() + bb.size()));
    }
  }
  d.Check(a.truth.has_value() == b.truth.has_value(), at + "truth: present in one only");
  if (a.truth && b.truth) {
    d.Values(at + "truth.range", a.truth->range, b.truth->range);
    d.Values(at + "truth.alpha", a.truth->alpha, b.truth->alpha);
    d.Values(at + "truth.surface", a.truth->surface, b.truth->surface);
    d.Values(at + "truth.region", a.truth->region, b.truth->region);
    d.Values(at + "truth.outlier", a.truth->outlier, b.truth->outlier);
  }
  d.Check(a.carmen.has_value() == b.carmen.has_value(), at + "carmen: present in one only");
  if (a.carmen && b.carmen) CompareCarmen(d, at + "carmen.", *a.carmen, *b.carmen);
  d.Check(a.sonar.has_value() == b.sonar.has_value(), at + "sonar: present in one only");
  if (a.sonar && b.sonar) {
    d.Number(at + "sonar.spread", a.sonar->spread, b.sonar->spread);
    d.Value(at + "number of sonar.origins", a.sonar->origins.size(), b.sonar->origins.size());
    for (std::size_t i = 0; i < std::min(a.sonar->origins.size(), b.sonar->origins.size()); ++i) {
      d.Number(at + "sonar.origins[" + std::to_string(i) + "].x", a.sonar->origins[i].x(),
               b.sonar->origins[i].x());
      d.Number(at + "sonar.origins[" + std::to_string(i) + "].y", a.sonar->origins[i].y(),
               b.sonar->origins[i].y());
    }
    d.Values(at + "sonar.true_echo", a.sonar->true_echo, b.sonar->true_echo);
    d.Values(at + "sonar.true_feature", a.sonar->true_feature, b.sonar->true_feature);
  }
}

}  // namespace

::testing::AssertionResult SameLog(const Log& a, const Log& b) {
  Differences d;
  d.Value("pose_source", a.pose_source, b.pose_source);
  d.Value("number of scans", a.scans.size(), b.scans.size());
  for (std::size_t k = 0; k < std::min(a.scans.size(), b.scans.size()); ++k) {
    CompareScans(d, "scan " + std::to_string(k) + ": ", a.scans[k], b.scans[k]);
  }
  d.Value("number of odometry records", a.odometry.size(), b.odometry.size());
  for (std::size_t k = 0; k < std::min(a.odometry.size(), b.odometry.size()); ++k) {
    const OdometryRecord& ra = a.odometry[k];
    const OdometryRecord& rb = b.odometry[k];
    const std::string at = "odometry " + std::to_string(k) + ": ";
    d.Number(at + "timestamp", ra.timestamp, rb.timestamp);
    d.Pose(at + "pose", ra.pose, rb.pose);
    d.Number(at + "tv", ra.tv, rb.tv);
    d.Number(at + "rv", ra.rv, rb.rv);
    d.Number(at + "accel", ra.accel, rb.accel);
    CompareRecordFields(d, at, ra.carmen, rb.carmen);
  }
  d.Value("number of true poses", a.true_poses.size(), b.true_poses.size());
  for (std::size_t k = 0; k < std::min(a.true_poses.size(), b.true_poses.size()); ++k) {
    const TruePoseRecord& ra = a.true_poses[k];
    const TruePoseRecord& rb = b.true_poses[k];
    const std::string at = "true pose " + std::to_string(k) + ": ";
    d.Number(at + "timestamp", ra.timestamp, rb.timestamp);
    d.Pose(at + "true_pose", ra.true_pose, rb.true_pose);
    d.Pose(at + "odom_pose", ra.odom_pose, rb.odom_pose);
    CompareRecordFields(d, at, ra.carmen, rb.carmen);
  }
  d.Values("params", a.params, b.params);
  // The order the records are in, not how `order` spells it: empty and the default order spelt
  // out mean the same, and readers may give either.
  d.Values("record order", a.RecordOrder(), b.RecordOrder());
  return d.Result();
}

::testing::AssertionResult SameScan(const Scan& a, const Scan& b) {
  Differences d;
  CompareScans(d, "", a, b);
  return d.Result();
}

::testing::AssertionResult SameScene(const Scene& a, const Scene& b) {
  Differences d;
  d.Value("name", a.name, b.name);
  d.Pose("default_pose", a.default_pose, b.default_pose);
  d.Value("number of waypoints", a.waypoints.size(), b.waypoints.size());
  for (std::size_t i = 0; i < std::min(a.waypoints.size(), b.waypoints.size()); ++i) {
    d.Number("waypoint " + std::to_string(i) + " x", a.waypoints[i].x(), b.waypoints[i].x());
    d.Number("waypoint " + std::to_string(i) + " y", a.waypoints[i].y(), b.waypoints[i].y());
  }
  d.Value("number of surfaces", a.surfaces.size(), b.surfaces.size());
  for (std::size_t k = 0; k < std::min(a.surfaces.size(), b.surfaces.size()); ++k) {
    const SceneSurface& sa = a.surfaces[k];
    const SceneSurface& sb = b.surfaces[k];
    const std::string at = "surface " + std::to_string(k) + ": ";
    d.Value(at + "clutter", sa.clutter, sb.clutter);
    d.Value(at + "label", sa.label, sb.label);
    d.Value(at + "shape kind", sa.shape.index(), sb.shape.index());
    if (sa.shape.index() != sb.shape.index()) continue;
    if (const auto* pa = std::get_if<Polyline>(&sa.shape)) {
      const Polyline& pb = std::get<Polyline>(sb.shape);
      d.Value(at + "closed", pa->closed, pb.closed);
      d.Value(at + "number of points", pa->points.size(), pb.points.size());
      for (std::size_t i = 0; i < std::min(pa->points.size(), pb.points.size()); ++i) {
        d.Number(at + "point " + std::to_string(i) + " x", pa->points[i].x(), pb.points[i].x());
        d.Number(at + "point " + std::to_string(i) + " y", pa->points[i].y(), pb.points[i].y());
      }
    } else {
      const Circle& ca = std::get<Circle>(sa.shape);
      const Circle& cb = std::get<Circle>(sb.shape);
      d.Number(at + "centre x", ca.center.x(), cb.center.x());
      d.Number(at + "centre y", ca.center.y(), cb.center.y());
      d.Number(at + "radius", ca.radius, cb.radius);
    }
  }
  return d.Result();
}

}  // namespace priormap::testing
