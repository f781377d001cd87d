#include <fmt/format.h>

#include <priormap/core/world_bounds.hpp>

namespace priormap {

std::string ExpectedWorldCoordinate(std::string_view what, std::string_view got) {
  return fmt::format("expected {} in metres of a local frame, at most {:.0e} in magnitude, got {}",
                     what, kMaxWorldCoordinate, got);
}

}  // namespace priormap
