#include <cmath>

#include <fmt/format.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/range_sensor.hpp>
#include <priormap/core/scan.hpp>

namespace priormap {

bool RangeSensor::IsValid(std::string* why) const {
  std::string reason;
  if (num_beams < 1) {
    reason = fmt::format("num_beams must be at least 1 (got {})", num_beams);
  } else if (!(fov > 0.0 && fov <= kTwoPi)) {
    reason = fmt::format("fov must be in (0, 2 pi] rad (got {})", fov);
  } else if (!(sigma >= 1e-100 && sigma <= 1e100)) {
    // Beyond these, the noise's information matrix (1 / sigma^2) is no longer a finite double.
    reason = fmt::format("sigma must be in [1e-100, 1e100] m (got {})", sigma);
  } else if (!(correlation >= 0.0 && correlation < 1.0)) {
    reason = fmt::format("correlation must be in [0, 1) (got {})", correlation);
  } else if (!(min_range >= 0.0 && max_range > min_range && std::isfinite(max_range))) {
    reason =
        fmt::format("need 0 <= min_range < max_range < inf (got {} and {})", min_range, max_range);
  } else if (!(outlier_probability >= 0.0 && outlier_probability <= 1.0)) {
    reason = fmt::format("outlier probability must be in [0, 1] (got {})", outlier_probability);
  } else if (!(dropout_probability >= 0.0 && dropout_probability <= 1.0)) {
    reason = fmt::format("dropout probability must be in [0, 1] (got {})", dropout_probability);
  }
  if (why) *why = reason;
  return reason.empty();
}

std::vector<double> RangeSensor::BeamAngles() const {
  const auto n = static_cast<std::size_t>(num_beams);
  if (n == 1) return {0.0};
  // A full circle's two ends are one direction: n beams split it into n equal steps.
  if (fov >= kTwoPi) return EvenlySpacedAngles(n, -kPi, kPi - kTwoPi / static_cast<double>(n));
  return EvenlySpacedAngles(n, -fov / 2, fov / 2);
}

std::optional<RangeSensor> RangeSensor::Preset(std::string_view name) {
  RangeSensor sensor;
  if (name == "utm30") {
    sensor.name = "utm30";
    sensor.num_beams = 1081;
    sensor.fov = DegToRad(270.0);
    sensor.sigma = 0.01;
    sensor.min_range = 0.1;
    sensor.max_range = 30.0;
    return sensor;
  }
  if (name == "lms200") {
    sensor.name = "lms200";
    sensor.num_beams = 181;
    sensor.fov = DegToRad(180.0);
    sensor.sigma = 0.01;
    sensor.min_range = 0.0;
    sensor.max_range = 8.0;
    return sensor;
  }
  return std::nullopt;
}

std::vector<std::string> RangeSensor::PresetNames() {
  return {"utm30", "lms200"};
}

}  // namespace priormap
