#pragma once
/// The storage and the update primitives of 8-bit log-odds occupancy grids, shared by their
/// inverse sensor models (the laser's rays and the sonar's cones): cells are
/// saturated fixed-point log-odds, updated through a table over the cell's 256 states, and kept
/// in 8x8 tiles of 64 bytes (one cache line) so that a line in any direction touches few lines
/// (a few per cent faster than rows on the real logs of docs/benchmarks.md).

#include <array>
#include <cstdint>
#include <vector>

#include <climits>

#include <priormap/core/map_server.hpp>

namespace priormap::grid {

namespace detail {
struct Line;
}  // namespace detail

/// One kind of log-odds update of a cell, e.g. "a beam went through it": the cell's next state
/// for each of its 256 states, clamp((unobserved ? 0 : cell) + delta, -limit, limit). A table
/// turns the sentinel test and the clamp into one load.
class CellUpdate {
 public:
  static constexpr std::int8_t kUnobserved = INT8_MIN;

  /// `delta` in fixed-point steps; 0 < limit <= 127 and |delta| <= limit.
  CellUpdate(int delta, int limit);

  [[nodiscard]] std::int8_t operator()(std::int8_t cell) const {
    return next_[static_cast<std::uint8_t>(cell)];
  }

 private:
  std::array<std::int8_t, 256> next_{};
};

/// A width x height raster of 8-bit log-odds, kUnobserved until first updated. Cell (ix, iy)
/// lives at offset column_offset_[ix] + row_offset_[iy] in 8x8 tiles; the two small tables
/// make the address of any cell two loads and an add.
class LogOddsCells {
 public:
  static constexpr std::int8_t kUnobserved = CellUpdate::kUnobserved;
  static constexpr int kTile = 8;  ///< cells per tile side: 64 cells, one cache line

  /// Throws std::invalid_argument unless both sizes are positive and the cells fit in memory
  /// addressed by 32-bit offsets.
  LogOddsCells(int width, int height);

  [[nodiscard]] int width() const { return width_; }
  [[nodiscard]] int height() const { return height_; }
  [[nodiscard]] bool Contains(int ix, int iy) const {
    return ix >= 0 && iy >= 0 && ix < width_ && iy < height_;
  }

  /// The raw state of a cell inside the raster (kUnobserved or within ±limit).
  [[nodiscard]] std::int8_t Get(int ix, int iy) const { return cells_[Offset(ix, iy)]; }
  /// Updates a cell inside the raster.
  void Apply(int ix, int iy, const CellUpdate& update) {
    std::int8_t& cell = cells_[Offset(ix, iy)];
    cell = update(cell);
  }

  /// Bresenham's line over cells from (x0, y0) to (x1, y1), 8-connected, one cell per step
  /// along the major axis: `along` on every cell before the end, then `last` on (x1, y1).
  /// Cells outside the raster are skipped; any int coordinates are allowed.
  void TraceLine(int x0, int y0, int x1, int y1, const CellUpdate& along, const CellUpdate& last);

 private:
  [[nodiscard]] std::uint32_t Offset(int ix, int iy) const {
    return column_offset_[static_cast<std::size_t>(ix)] + row_offset_[static_cast<std::size_t>(iy)];
  }
  void TraceExact(const detail::Line& line, const CellUpdate& along);
  template <bool kChecked>
  void TraceStepwise(const detail::Line& line, const CellUpdate& along);

  int width_ = 0;
  int height_ = 0;
  std::vector<std::uint32_t> column_offset_;  ///< per ix
  std::vector<std::uint32_t> row_offset_;     ///< per iy
  std::vector<std::int8_t> cells_;
};

/// The most cells a grid may have by default (GridOptions::max_cells): a grid and its raster
/// take about 17 bytes a cell at their peak, so this is some 1.7 GB (a 500 m square at 5 cm).
inline constexpr double kMaxGridCells = 1e8;

/// The cells of `resolution` m that cover `extent` from its lower-left corner, at least one per
/// side. Throws std::invalid_argument for an empty or non-finite extent, a resolution that is not
/// positive and finite, more than `max_cells` cells (at most
/// 4e9, what the cells' 32-bit offsets address) or a side longer than an int counts.
[[nodiscard]] LogOddsCells CellsCovering(const Box2& extent, double resolution,
                                         double max_cells = kMaxGridCells);

/// A cell's log-odds: its fixed-point state over `scale`, 0 (even odds) where never observed.
[[nodiscard]] double LogOddsOf(std::int8_t cell, double scale);

/// P(occupied) = 1 / (1 + exp(-state / scale)) per cell, NaN where never observed, row 0 at the
/// bottom; cell (0, 0)'s lower-left corner at `origin`, `resolution` m per cell.
[[nodiscard]] OccupancyRaster RasterOf(const LogOddsCells& cells, const Vec2& origin,
                                       double resolution, double scale);

}  // namespace priormap::grid
