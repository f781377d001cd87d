#include <algorithm>
#include <cmath>
#include <span>

#include <fmt/format.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/sonar_sensor.hpp>
#include <priormap/core/world_bounds.hpp>

namespace priormap {
namespace {

bool Probability(double p) {
  return p >= 0.0 && p <= 1.0;
}

bool PositiveFinite(double x) {
  return x > 0.0 && std::isfinite(x);
}

// Transducers of a Pioneer 2 DX (Player's p2os robot parameters): position in the robot frame,
// mm, and bearing, deg.
struct Transducer {
  double x_mm, y_mm, bearing_deg;
};
constexpr Transducer kPioneerFront[] = {{69, 136, 90},    {114, 119, 50},  {148, 78, 30},
                                        {166, 27, 10},    {166, -27, -10}, {148, -78, -30},
                                        {114, -119, -50}, {69, -136, -90}};
constexpr Transducer kPioneerRear[] = {{-157, -136, -90}, {-203, -119, -130}, {-237, -78, -150},
                                       {-255, -27, -170}, {-255, 27, 170},    {-237, 78, 150},
                                       {-203, 119, 130},  {-157, 136, 90}};

void AddTransducers(SonarSensor& sensor, std::span<const Transducer> ring) {
  for (const Transducer& t : ring) {
    sensor.bearings.push_back(DegToRad(t.bearing_deg));
    sensor.offsets.emplace_back(t.x_mm / 1000.0, t.y_mm / 1000.0);
  }
}

}  // namespace

bool SonarSensor::IsValid(std::string* why) const {
  std::string reason;
  const bool finite_bearings =
      std::all_of(bearings.begin(), bearings.end(), [](double b) { return std::isfinite(b); });
  const bool finite_offsets =
      std::all_of(offsets.begin(), offsets.end(), [](const Vec2& o) { return o.allFinite(); });
  if (bearings.empty() || !finite_bearings) {
    reason = "a sonar ring needs at least one transducer, with finite bearings";
  } else if (!offsets.empty() && (offsets.size() != bearings.size() || !finite_offsets)) {
    reason = fmt::format("{} offsets for {} transducers (give one finite offset each, or none)",
                         offsets.size(), bearings.size());
  } else if (!(spread > 0.0 && spread < kPi)) {
    reason = fmt::format("spread must be in (0, pi) rad (got {})", spread);
  } else if (!(min_range >= 0.0 && max_range > min_range && std::isfinite(max_range))) {
    reason =
        fmt::format("need 0 <= min_range < max_range < inf (got {} and {})", min_range, max_range);
  } else if (!(max_range <= kMaxWorldCoordinate)) {
    // A spurious reading is uniform below the max range: beyond the bound, the log it is in
    // could not be written (docs/formats.md).
    reason = fmt::format(
        "max_range {:g} m is beyond {:g} m, the bound priormap puts on returns (a spurious "
        "reading could be that long)",
        max_range, kMaxWorldCoordinate);
  } else if (!(sigma_relative >= 0.0 && std::isfinite(sigma_relative)) ||
             !PositiveFinite(sigma_min)) {
    reason = fmt::format("need sigma_relative >= 0 and sigma_min > 0 (got {} and {})",
                         sigma_relative, sigma_min);
  } else if (!Probability(surface_return) || !Probability(concave_corner_return) ||
             !Probability(convex_corner_return) || !Probability(multipath_probability) ||
             !Probability(spurious_probability)) {
    reason = "the echo, multipath and spurious probabilities must be in [0, 1]";
  } else if (!(critical_incidence >= 0.0 && critical_incidence < kPi / 2) ||
             !PositiveFinite(incidence_softness)) {
    reason = fmt::format(
        "need critical_incidence in [0, pi/2) and incidence_softness > 0 (got {} "
        "and {})",
        critical_incidence, incidence_softness);
  } else if (rays_per_cone < 2) {
    reason = fmt::format("rays_per_cone must be at least 2 (got {})", rays_per_cone);
  }
  if (why) *why = reason;
  return reason.empty();
}

double SonarSensor::Sigma(double range) const {
  return std::max(sigma_min, sigma_relative * range);
}

std::optional<SonarSensor> SonarSensor::Preset(std::string_view name) {
  SonarSensor sensor;
  sensor.name = std::string(name);
  if (name == "pioneer8") {
    AddTransducers(sensor, kPioneerFront);
    return sensor;
  }
  if (name == "pioneer16") {
    AddTransducers(sensor, kPioneerFront);
    AddTransducers(sensor, kPioneerRear);
    return sensor;
  }
  if (name == "robond") {
    for (double b : {-90.0, -37.5, -22.5, -7.5, 7.5, 22.5, 37.5, 90.0})
      sensor.bearings.push_back(DegToRad(b));
    sensor.max_range = 5.11;
    return sensor;
  }
  return std::nullopt;
}

std::vector<std::string> SonarSensor::PresetNames() {
  return {"pioneer8", "pioneer16", "robond"};
}

}  // namespace priormap
