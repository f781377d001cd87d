#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include <priormap/core/check.hpp>
#include <priormap/core/scan.hpp>
#include <priormap/core/world_bounds.hpp>

namespace priormap {

const char* ToString(BeamStatus status) {
  switch (status) {
    case BeamStatus::kValid:
      return "valid";
    case BeamStatus::kMaxRange:
      return "max_range";
    case BeamStatus::kInvalid:
      return "invalid";
  }
  return "?";
}

const char* ToString(SonarEcho echo) {
  switch (echo) {
    case SonarEcho::kNone:
      return "none";
    case SonarEcho::kSurface:
      return "surface";
    case SonarEcho::kCorner:
      return "corner";
    case SonarEcho::kMultipath:
      return "multipath";
    case SonarEcho::kSpurious:
      return "spurious";
  }
  return "?";
}

std::optional<SonarEcho> SonarEchoFromString(std::string_view name) {
  for (const SonarEcho echo : {SonarEcho::kNone, SonarEcho::kSurface, SonarEcho::kCorner,
                               SonarEcho::kMultipath, SonarEcho::kSpurious})
    if (name == ToString(echo)) return echo;
  return std::nullopt;
}

BeamStatus ClassifyReading(double range, double min_range, double max_range) {
  if (std::isnan(range) || range <= 0.0 || range < min_range) return BeamStatus::kInvalid;
  // +inf is how some drivers say "no echo"; it is as uninformative as NaN about where the
  // surface is, but not about free space, so it is not a max-range reading either.
  if (std::isinf(range)) return BeamStatus::kInvalid;
  if (range >= max_range) return BeamStatus::kMaxRange;
  return BeamStatus::kValid;
}

std::size_t Scan::NumValid() const {
  return static_cast<std::size_t>(std::count(status.begin(), status.end(), BeamStatus::kValid));
}

Vec2 Scan::PointInSensorFrame(std::size_t i) const {
  PRIORMAP_DCHECK(i < size(), "beam index out of range");
  return ReadingOrigin(i) + ranges[i] * UnitVector(angles[i]);
}

Vec2 Scan::PointInWorld(std::size_t i) const {
  return pose.Transform(PointInSensorFrame(i));
}

std::optional<std::string> Scan::FirstBeyondWorld() const {
  const auto pose_beyond = [](std::string_view field, const std::optional<Se2>& p) {
    return p ? CoordinateBeyondWorld(field, p->x(), p->y()) : std::nullopt;
  };
  if (auto beyond = pose_beyond("pose", pose)) return beyond;
  if (auto beyond = pose_beyond("robot_pose", robot_pose)) return beyond;
  if (auto beyond = pose_beyond("odom_pose", odom_pose)) return beyond;
  if (sonar) {
    for (std::size_t i = 0; i < sonar->origins.size(); ++i) {
      const Vec2& o = sonar->origins[i];
      if (auto beyond = CoordinateBeyondWorld(fmt::format("sonar origin {}", i), o.x(), o.y()))
        return beyond;
    }
  }
  if (const std::optional<std::size_t> i = FirstReturnBeyondWorld())
    return fmt::format("reading {} = {} m, a return (below max_range {} m)", *i, ranges[*i],
                       max_range);
  if (const std::optional<std::size_t> i = FirstTrueRangeBeyondWorld())
    return fmt::format("true_range {} = {} m", *i, truth->range[*i]);
  return std::nullopt;
}

std::optional<std::size_t> Scan::FirstReturnBeyondWorld() const {
  for (std::size_t i = 0; i < std::min(size(), status.size()); ++i)
    if (status[i] == BeamStatus::kValid && !IsReturnWithinWorld(ranges[i])) return i;
  return std::nullopt;
}

std::optional<std::size_t> Scan::FirstTrueRangeBeyondWorld() const {
  if (!truth) return std::nullopt;
  for (std::size_t i = 0; i < truth->range.size(); ++i)
    if (std::isfinite(truth->range[i]) && !IsReturnWithinWorld(truth->range[i])) return i;
  return std::nullopt;
}

void Scan::ClassifyAll() {
  status.resize(ranges.size());
  for (std::size_t i = 0; i < ranges.size(); ++i) {
    status[i] = ClassifyReading(ranges[i], min_range, max_range);
  }
}

std::vector<std::string> Scan::Problems() const {
  std::vector<std::string> problems;
  const std::size_t n = ranges.size();
  const auto require_size = [&](std::size_t size, const char* what) {
    if (size != n)
      problems.push_back(fmt::format("{} has {} entries for {} readings", what, size, n));
  };
  require_size(angles.size(), "angles");
  require_size(sigma.size(), "sigma");
  require_size(status.size(), "status");
  // A ring's transducers point where they are mounted, in no particular order.
  for (std::size_t i = 0; !sonar && i + 1 < angles.size(); ++i) {
    if (!(angles[i + 1] > angles[i])) {
      problems.push_back(fmt::format("angles must increase (beam {} to {})", i, i + 1));
      break;
    }
  }
  if (std::any_of(angles.begin(), angles.end(), [](double a) { return !std::isfinite(a); })) {
    problems.push_back("angles must be finite");
  }
  if (std::any_of(sigma.begin(), sigma.end(),
                  [](double s) { return !(s > 0.0 && std::isfinite(s)); })) {
    problems.push_back("sigma must be positive and finite");
  }
  if (precision && precision->size() != n) {
    problems.push_back(fmt::format("precision is {0}x{0} for {1} readings", precision->size(), n));
  } else if (precision && n > 0 && !BandedCholesky::Factor(*precision)) {
    // An information matrix is positive definite (and finite): anything else is no noise model,
    // and would make NaN objectives downstream.
    problems.push_back("precision is not a finite positive definite matrix");
  }
  for (std::size_t i = 0; i < std::min(n, status.size()); ++i) {
    if (status[i] == BeamStatus::kValid &&
        ClassifyReading(ranges[i], min_range, max_range) != BeamStatus::kValid) {
      problems.push_back(fmt::format(
          "status of reading {} is valid, but its range is {} (valid needs a finite range > 0, "
          "at least min_range {} and below max_range {})",
          i, ranges[i], min_range, max_range));
      break;
    }
  }
  if (!pose.IsFinite()) problems.push_back("pose must be finite");
  if (!(min_range >= 0.0) || !(max_range > min_range)) {
    problems.push_back(
        fmt::format("need 0 <= min_range < max_range (got {} and {})", min_range, max_range));
  }
  if (truth) {
    require_size(truth->range.size(), "true_range");
    require_size(truth->alpha.size(), "true_alpha");
    require_size(truth->surface.size(), "true_surface");
    require_size(truth->region.size(), "true_region");
    require_size(truth->outlier.size(), "true_outlier");
  }
  if (sonar) {
    if (!(sonar->spread > 0.0 && sonar->spread < std::numbers::pi))
      problems.push_back(
          fmt::format("the sonar cone's spread must be in (0, pi) rad (got {})", sonar->spread));
    if (!sonar->origins.empty()) require_size(sonar->origins.size(), "the sonar origins");
    if (std::any_of(sonar->origins.begin(), sonar->origins.end(),
                    [](const Vec2& o) { return !o.allFinite(); }))
      problems.push_back("the sonar origins must be finite");
    if (!sonar->true_echo.empty() || !sonar->true_feature.empty()) {
      require_size(sonar->true_echo.size(), "true_echo");
      require_size(sonar->true_feature.size(), "true_feature");
    }
  }
  return problems;
}

std::vector<double> EvenlySpacedAngles(std::size_t n, double first, double last) {
  std::vector<double> angles(n);
  if (n == 1) angles[0] = first;
  const double step = n > 1 ? (last - first) / static_cast<double>(n - 1) : 0.0;
  for (std::size_t i = 0; i < n; ++i) angles[i] = first + static_cast<double>(i) * step;
  return angles;
}

}  // namespace priormap
