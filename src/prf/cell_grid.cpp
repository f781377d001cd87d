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

OccupancyRaster SquareCellRaster(const Eigen::MatrixXd& values, const CellGrid& grid) {
  PRIORMAP_CHECK(values.rows() == grid.ny && values.cols() == grid.nx,
                 "the values must be the grid's cells");
  OccupancyRaster raster{.probability = values, .origin = grid.origin, .resolution = grid.cell.x()};
  if (grid.cell.y() == grid.cell.x()) return raster;
  const double height = grid.ny * grid.cell.y();
  const auto rows = std::max<Eigen::Index>(1, std::lround(height / grid.cell.x()));
  raster.probability.resize(rows, values.cols());
  for (Eigen::Index r = 0; r < rows; ++r) {
    const double y = (static_cast<double>(r) + 0.5) * grid.cell.x();
    const auto source =
        std::min<Eigen::Index>(values.rows() - 1, static_cast<Eigen::Index>(y / grid.cell.y()));
    raster.probability.row(r) = values.row(source);
  }
  return raster;
}

}  // namespace priormap::prf
