#pragma once
/// A uniform grid of cells over a window, and the walk of a segment through it (Amanatides &
/// Woo's DDA). The edge index of a coloring, the local recolor move and the beam index of the
/// laser likelihood all walk segments through such a grid.

#include <algorithm>
#include <cmath>
#include <limits>

#include <priormap/core/map_server.hpp>
#include <priormap/core/types.hpp>

namespace priormap::prf {

struct CellGrid {
  Vec2 origin = Vec2::Zero();
  Vec2 cell = Vec2::Ones();  ///< cell width and height
  int nx = 1;
  int ny = 1;

  /// Cells of about `cell_size` covering [min, max] exactly.
  static CellGrid Covering(const Vec2& min, const Vec2& max, double cell_size);

  [[nodiscard]] int NumCells() const { return nx * ny; }
  // Clamped as doubles first: casting a huge or NaN quotient to int is undefined.
  [[nodiscard]] int ClampX(double x) const { return Clamp((x - origin.x()) / cell.x(), nx); }
  [[nodiscard]] int ClampY(double y) const { return Clamp((y - origin.y()) / cell.y(), ny); }
  [[nodiscard]] int CellOf(const Vec2& p) const { return ClampY(p.y()) * nx + ClampX(p.x()); }
  [[nodiscard]] Vec2 Centre(int index) const {
    return origin + Vec2((index % nx + 0.5) * cell.x(), (index / nx + 0.5) * cell.y());
  }

 private:
  static int Clamp(double index, int n) {
    if (!(index >= 0.0)) return 0;  // also NaN
    return index >= n - 1 ? n - 1 : static_cast<int>(std::floor(index));
  }
};

/// `values` over `grid`'s cells (row 0 at the bottom) as a raster of square cells of side
/// grid.cell.x(), as map_server and the figures take it: where the grid's cells are not square
/// (they fit the window exactly), the rows are resampled at the nearest cell.
[[nodiscard]] OccupancyRaster SquareCellRaster(const Eigen::MatrixXd& values, const CellGrid& grid);

/// Calls visit(cell) for each cell that the bounding box of `points` overlaps (clamped to the
/// grid): the cells that can hold a point of the polygon they span.
template <class Points, class Visit>
void ForEachCellUnder(const CellGrid& grid, const Points& points, Visit&& visit) {
  Box2 box;
  for (const Vec2& p : points) box.extend(p);
  if (box.isEmpty()) return;
  const int x0 = grid.ClampX(box.min().x());
  const int x1 = grid.ClampX(box.max().x());
  const int y0 = grid.ClampY(box.min().y());
  const int y1 = grid.ClampY(box.max().y());
  for (int iy = y0; iy <= y1; ++iy)
    for (int ix = x0; ix <= x1; ++ix) visit(iy * grid.nx + ix);
}

/// Calls visit(cell, t_enter, t_exit) for each cell that the segment a + t (b - a), t in [0, 1],
/// passes through, in order from a, with the parameter interval spent in the cell; stops early
/// when visit returns false. Points outside the grid are clamped to its border cells. Where the
/// segment passes exactly through a grid corner, both cells beside the corner are visited, and
/// an end point on a grid line reaches the cell that holds it, so that segments that touch
/// always share a visited cell.
template <class Visit>
void WalkCells(const CellGrid& grid, const Vec2& a, const Vec2& b, Visit&& visit) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const Vec2 d = b - a;
  int ix = grid.ClampX(a.x());
  int iy = grid.ClampY(a.y());
  const int end_x = grid.ClampX(b.x());
  const int end_y = grid.ClampY(b.y());
  const int step_x = d.x() > 0.0 ? 1 : (d.x() < 0.0 ? -1 : 0);
  const int step_y = d.y() > 0.0 ? 1 : (d.y() < 0.0 ? -1 : 0);
  auto first_crossing = [](int step, int i, double origin, double size, double start,
                           double delta) {
    if (step == 0) return std::numeric_limits<double>::infinity();
    const double boundary = origin + (step > 0 ? i + 1 : i) * size;
    return std::max(0.0, (boundary - start) / delta);
  };
  double t_max_x = first_crossing(step_x, ix, grid.origin.x(), grid.cell.x(), a.x(), d.x());
  double t_max_y = first_crossing(step_y, iy, grid.origin.y(), grid.cell.y(), a.y(), d.y());
  const double t_delta_x = step_x != 0 ? grid.cell.x() / std::abs(d.x()) : kInf;
  const double t_delta_y = step_y != 0 ? grid.cell.y() / std::abs(d.y()) : kInf;
  double t = 0.0;
  for (;;) {
    const bool at_end = ix == end_x && iy == end_y;
    const double t_next = at_end ? 1.0 : std::min({t_max_x, t_max_y, 1.0});
    if (!visit(iy * grid.nx + ix, t, t_next)) return;
    // Past b's cell, or the next cell boundary lies beyond b: done. (A boundary exactly at b
    // still leads into the cell holding b.)
    if (at_end || std::min(t_max_x, t_max_y) > 1.0) return;
    if (t_max_x == t_max_y && step_x != 0 && step_y != 0) {
      // Through a corner: the cell beside it along x too, before stepping on along y.
      const int side_x = ix + step_x;
      if (side_x >= 0 && side_x < grid.nx && !visit(iy * grid.nx + side_x, t_max_x, t_max_x))
        return;
    }
    if (t_max_x < t_max_y) {
      ix += step_x;
      t = t_max_x;
      t_max_x += t_delta_x;
    } else {
      iy += step_y;
      t = t_max_y;
      t_max_y += t_delta_y;
    }
    if (ix < 0 || ix >= grid.nx || iy < 0 || iy >= grid.ny) return;
  }
}

}  // namespace priormap::prf
