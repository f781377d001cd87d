#include <algorithm>
#include <cmath>

#include <priormap/core/check.hpp>
#include <priormap/prf/cell_grid.hpp>

namespace priormap::prf {

CellGrid CellGrid::Covering(const Vec2& min, const Vec2& max, double cell_size) {
  PRIORMAP_CHECK(cell_size > 0.0 && (max - min).minCoeff() > 0.0,
                 "a cell grid needs a positive cell size and a non-empty box");
  CellGrid grid;
  grid.origin = min;
  const Vec2 extent = max - min;
  grid.nx = std::max(1, static_cast<int>(std::ceil(extent.x() / cell_size - 1e-9)));
  grid.ny = std::max(1, static_cast<int>(std::ceil(extent.y() / cell_size - 1e-9)));
  grid.cell = {extent.x() / grid.nx, extent.y() / grid.ny};
  return grid;
}

}  // namespace priormap::prf
