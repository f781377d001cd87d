#pragma once
/// One range scan: where the sensor was, where each beam pointed, what it measured, how noisy
/// that is, and which readings are usable. Optionally the simulator's ground truth.

#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <priormap/core/banded_matrix.hpp>
#include <priormap/core/se2.hpp>

namespace priormap {

/// What a reading is. Only kValid readings are distances to a surface.
enum class BeamStatus : std::uint8_t {
  kValid = 0,     ///< a return from a surface
  kMaxRange = 1,  ///< no return within range (the sensor's sentinel, or reading >= max_range)
  kInvalid = 2,   ///< not a measurement: NaN, infinite, <= 0, below min_range, or flagged
};

[[nodiscard]] const char* ToString(BeamStatus status);

/// The status a reading gets from its value alone.
[[nodiscard]] BeamStatus ClassifyReading(double range, double min_range, double max_range);

/// Ground truth of a simulated scan, per beam (NaN / -1 where the beam hit nothing).
struct ScanTruth {
  std::vector<double> range;          ///< true distance, m
  std::vector<double> alpha;          ///< normal angle in the sensor frame, towards the sensor, rad
  std::vector<int> surface;           ///< Scene surface id
  std::vector<int> region;            ///< Scene region (primitive) id
  std::vector<std::uint8_t> outlier;  ///< 1 when the simulator replaced the reading (outlier)
};

/// Fields of a CARMEN laser record that priormap does not interpret, kept so that a log read
/// from CARMEN is written back unchanged.
struct CarmenLaserFields {
  bool has_timestamps = true;  ///< some logs end right after the odometry pose
  std::string host = "nohost";
  double logger_timestamp = 0.0;
  // ROBOTLASER1 only (the beam angles are start_angle + i * angular_resolution):
  int laser_type = 0;
  double start_angle = 0.0;
  double fov = 0.0;
  double angular_resolution = 0.0;
  /// The record's maximum_range field as read (≤ 0 or NaN: none; the scan's max_range then
  /// comes from detection), written back as read so that a rewritten log parses the same.
  std::optional<double> maximum_range;
  double accuracy = 0.0;
  int remission_mode = 0;
  std::vector<double> remissions;
  double tv = 0.0, rv = 0.0, forward_safety_dist = 0.0, side_safety_dist = 0.0, turn_axis = 0.0;
};

/// What caused a sonar reading, in a simulated ring's ground truth.
enum class SonarEcho : std::uint8_t {
  kNone = 0,       ///< no echo: a max-range reading
  kSurface = 1,    ///< a surface seen close to perpendicular
  kCorner = 2,     ///< a corner or the free end of a wall
  kMultipath = 3,  ///< an echo off a surface, returned by another one: too long
  kSpurious = 4,   ///< unrelated to the scene (crosstalk, noise)
};

[[nodiscard]] const char* ToString(SonarEcho echo);
/// Inverse of ToString; nullopt for an unknown name.
[[nodiscard]] std::optional<SonarEcho> SonarEchoFromString(std::string_view name);

/// A sonar ring's readings are cones, not rays: reading i is the distance to the first echo
/// from anywhere in the cone of full angle `spread` around angles[i] (docs/sonar.md).
struct SonarFields {
  double spread = 0.3490658503988659;  ///< full cone angle, rad, in (0, pi); 20 deg by default
  /// Where each transducer sits in the sensor frame, one per reading; empty when all sit at
  /// the sensor's origin.
  std::vector<Vec2> origins;
  /// Ground truth of a simulated ring (else empty): what caused each reading, and which
  /// feature: for a surface or a multipath echo the region (Scene::Primitives index) it left
  /// from, for a corner its index in SceneCorners(scene); -1 otherwise.
  std::vector<SonarEcho> true_echo;
  std::vector<int> true_feature;

  /// Where reading i's cone starts, in the sensor frame.
  [[nodiscard]] Vec2 Origin(std::size_t i) const {
    return origins.empty() ? Vec2::Zero() : origins[i];
  }
};

struct Scan {
  std::string channel = "FLASER";  ///< origin: FLASER, RLASER, ROBOTLASER1, SIM, ...
  double timestamp = 0.0;          ///< s
  Se2 pose;                        ///< T_world_sensor at the time of the scan
  std::optional<Se2> robot_pose;   ///< T_world_robot, when the log gives it apart from `pose`
  std::optional<Se2> odom_pose;    ///< the robot's odometry pose, when known

  std::vector<double> angles;  ///< phi_i, rad, relative to the sensor x axis, increasing
  std::vector<double> ranges;  ///< measured ranges, m (as read; check `status` before use)
  std::vector<double> sigma;   ///< standard deviation of each reading's noise, m
  std::vector<BeamStatus> status;
  /// Information matrix of the range noise when neighbouring readings are correlated
  /// (its inverse's diagonal equals sigma^2); nullopt for independent noise.
  std::optional<SymmetricBandedMatrix> precision;
  double min_range = 0.0;                                      ///< m
  double max_range = std::numeric_limits<double>::infinity();  ///< m

  std::optional<ScanTruth> truth;
  std::optional<CarmenLaserFields> carmen;
  /// Set for a sonar ring (its readings are cones; angles need not increase), unset for a laser.
  std::optional<SonarFields> sonar;

  [[nodiscard]] std::size_t size() const { return ranges.size(); }
  [[nodiscard]] bool IsValid(std::size_t i) const { return status[i] == BeamStatus::kValid; }
  [[nodiscard]] std::size_t NumValid() const;
  /// Where reading i starts, in the sensor frame: a sonar reading at its transducer, a laser
  /// beam at the sensor's origin.
  [[nodiscard]] Vec2 ReadingOrigin(std::size_t i) const {
    return sonar ? sonar->Origin(i) : Vec2::Zero();
  }
  /// Reading i as a point in the sensor frame (meaningful for valid readings): for a sonar
  /// reading, the point on its cone's axis, from its transducer's origin.
  [[nodiscard]] Vec2 PointInSensorFrame(std::size_t i) const;
  /// Reading i as a point in the world frame.
  [[nodiscard]] Vec2 PointInWorld(std::size_t i) const;
  /// The first return (a valid reading) longer than kMaxWorldCoordinate (IsReturnWithinWorld,
  /// world_bounds.hpp), if any: readers refuse it at its field. Readings of other status are
  /// never one: a no-return reading is kept whatever its value.
  [[nodiscard]] std::optional<std::size_t> FirstReturnBeyondWorld() const;
  /// The same for the ground truth: the first finite true range longer than the bound.
  [[nodiscard]] std::optional<std::size_t> FirstTrueRangeBeyondWorld() const;
  /// The first value of the scan beyond the world's bound, named ("pose x = 1e+300", "reading 4
  /// = 1e+300 m, a return (below max_range inf m)"): poses, sonar origins, returns
  /// (FirstReturnBeyondWorld), then true ranges; nullopt when there is none. Writers refuse such a
  /// scan.
  [[nodiscard]] std::optional<std::string> FirstBeyondWorld() const;
  /// Sets every status from the reading's value (ClassifyReading).
  void ClassifyAll();
  /// Empty when consistent; otherwise what is wrong (sizes differ, angles not increasing,
  /// sigma not positive, precision of the wrong size, non-finite pose, ...).
  [[nodiscard]] std::vector<std::string> Problems() const;
};

/// `n` angles evenly spaced from `first` to `last` inclusive: first + i * (last - first) / (n - 1).
[[nodiscard]] std::vector<double> EvenlySpacedAngles(std::size_t n, double first, double last);

}  // namespace priormap
