#pragma once
/// The standard log-odds occupancy grid (Paskin & Thrun, Sec. 1.2; Thrun, Burgard & Fox, ch. 9)
/// with the laser inverse sensor model: each beam lowers the log-odds of the cells it crosses
/// before its end point and raises that of the end point's cell; max-range readings, and returns
/// at or beyond the insertion range (the PRF's R, which takes those for max readings too), clear
/// the cells up to it. Log-odds are 8-bit fixed point (±l_max is ±127, a step of
/// l_max/127 = 0.03 at the default l_max = 4), saturated (LogOddsCells), so that a grid at 5 cm
/// of a building floor stays in cache and an update is a table lookup.

#include <vector>

#include <priormap/core/log.hpp>
#include <priormap/core/map_server.hpp>
#include <priormap/grid/log_odds_cells.hpp>

namespace priormap::grid {

struct GridOptions {
  double resolution = 0.05;  ///< m
  double log_odds_hit = 0.85;
  double log_odds_miss = -0.4;
  double log_odds_limit = 4.0;  ///< |log-odds| saturates here
  /// Beams are inserted up to this range (finite); max-range readings and returns at or beyond
  /// it clear cells up to it.
  double max_range = 20.0;
  /// Off: max-range readings, and returns at or beyond max_range (max readings for the PRF
  /// too), are left out instead of clearing cells.
  bool max_readings_clear = true;
  double margin = 1.0;  ///< m around the data, for the grid's extent
  /// Every k-th beam of each scan (the PRF's --beam-step, for comparisons at equal data).
  std::size_t beam_step = 1;
  /// The grid may have at most this many cells (CellsCovering).
  double max_cells = kMaxGridCells;
};

class OccupancyGrid {
 public:
  /// A grid covering `extent`. Throws std::invalid_argument on bad options (a resolution or an
  /// insertion range that is not a positive finite length, a negative or NaN margin, ...) or an
  /// extent that is not finite.
  OccupancyGrid(const Box2& extent, GridOptions options);

  /// The box holding every sensor and every beam end point (capped at the insertion range) of
  /// the laser scans among scans [first, end) of the log, grown by options.margin; empty when
  /// they have no beam to insert.
  [[nodiscard]] static Box2 ExtentOf(const Log& log, std::size_t first, std::size_t end,
                                     const GridOptions& options);

  /// Inserts every usable beam of a laser scan (invalid readings are skipped; a sonar ring is
  /// left out whole: SonarGrid maps those). Returns the number of beams inserted.
  std::size_t Insert(const Scan& scan);
  /// One beam from `origin` to `end`: the cells of Bresenham's line from the origin's cell to
  /// the end's (8-connected, one per step along the major axis) are free, the end's cell is
  /// occupied when `hit`.
  void InsertBeam(const Vec2& origin, const Vec2& end, bool hit);

  [[nodiscard]] int width() const { return cells_.width(); }
  [[nodiscard]] int height() const { return cells_.height(); }
  [[nodiscard]] const GridOptions& options() const { return options_; }
  [[nodiscard]] Vec2 origin() const { return origin_; }
  /// Log-odds of a cell (0 when never observed).
  [[nodiscard]] double LogOdds(int ix, int iy) const;
  [[nodiscard]] bool Observed(int ix, int iy) const {
    return cells_.Get(ix, iy) != LogOddsCells::kUnobserved;
  }
  /// P(occupied) per cell, NaN where never observed, row 0 at the bottom.
  [[nodiscard]] OccupancyRaster Raster() const;
  /// The fixed-point cells: the log-odds of cell (ix, iy) is cells().Get(ix, iy) / scale().
  [[nodiscard]] const LogOddsCells& cells() const { return cells_; }
  /// Fixed-point steps per unit of log-odds.
  [[nodiscard]] double scale() const { return scale_; }

 private:
  /// A beam from cell (ix, iy) to the point (x1, y1) in cell units (metres from origin_ over
  /// the resolution): every beam of a scan shares its first cell.
  void TraceBeam(int ix, int iy, double x1, double y1, bool hit);

  GridOptions options_;
  Vec2 origin_;
  double scale_ = 1.0;
  LogOddsCells cells_;
  CellUpdate miss_;
  CellUpdate hit_;
  std::vector<double> beam_angles_;  ///< of the last scan inserted
  std::vector<Vec2> beam_directions_;
};

}  // namespace priormap::grid
