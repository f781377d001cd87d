#include <cmath>
#include <limits>

#include <fmt/format.h>

#include <priormap/core/world_bounds.hpp>

namespace priormap {

std::string ExpectedWorldCoordinate(std::string_view what, std::string_view got) {
  return fmt::format("expected {} in metres of a local frame, at most {:.0e} in magnitude, got {}",
                     what, kMaxWorldCoordinate, got);
}

std::string ExpectedReturnWithinWorld(std::string_view what, std::string_view got,
                                      double max_range) {
  return fmt::format(
      "expected {} in metres, at most {:.0e} for a return or at or above the max range ({} m) "
      "for no return, got {}",
      what, kMaxWorldCoordinate, max_range, got);
}

std::optional<std::string> CircleBeyondWorld(double x, double y, double radius) {
  const double room = LargestRadiusWithinWorld(x, y);
  if (radius <= room) return std::nullopt;
  // A centre on the bound leaves no positive radius to ask for: the centre must move.
  if (room <= 0.0)
    return fmt::format(
        "the circle about ({}, {}) cannot lie within ±{:.0e} m in x and y with any radius, as its "
        "centre is on that bound: move the centre inwards by at least the radius {}",
        x, y, kMaxWorldCoordinate, radius);
  return fmt::format(
      "expected a radius of at most {} m, which keeps x and y of every point of the circle "
      "about ({}, {}) within ±{:.0e} m, got {}",
      room, x, y, kMaxWorldCoordinate, radius);
}

std::optional<std::string> HeadingNotFinite(std::string_view field, double theta) {
  if (std::isfinite(theta)) return std::nullopt;
  // One NaN, whatever its sign: Se2 wraps an infinity to -nan, which says nothing more.
  return fmt::format("{} theta = {}, not a finite angle", field,
                     std::isnan(theta) ? std::numeric_limits<double>::quiet_NaN() : theta);
}

std::optional<std::string> CoordinateBeyondWorld(std::string_view field, double x, double y) {
  if (!IsWithinWorld(x)) return fmt::format("{} x = {}", field, x);
  if (!IsWithinWorld(y)) return fmt::format("{} y = {}", field, y);
  return std::nullopt;
}

std::string CannotWriteBeyondWorld(std::string_view what, std::string_view beyond) {
  return fmt::format(
      "cannot write {}: {}, beyond {:.0e} m in magnitude, the bound priormap's readers put on "
      "positions and returns (docs/formats.md)",
      what, beyond, kMaxWorldCoordinate);
}

std::string CannotWriteRefused(std::string_view what, std::string_view refused) {
  return fmt::format("cannot write {}: {}; priormap's readers refuse it (docs/formats.md)", what,
                     refused);
}

}  // namespace priormap
