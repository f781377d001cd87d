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

}  // namespace priormap
