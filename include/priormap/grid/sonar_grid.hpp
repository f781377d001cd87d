#pragma once
/// The standard sonar occupancy grid (Paskin & Thrun, Sec. 1.2; Elfes 1989; Thrun, Burgard &
/// Fox, Table 9.2): a reading of range z from a cone of full angle β updates the cells whose
/// centres lie in the cone: those nearer than z − α/2 are free, those within α/2 of z (the arc)
/// are occupied, those beyond are not observed. An echo whose arc holds no centre (an arc
/// thinner or narrower than a cell) occupies the cell holding its point on the axis instead, as
/// a laser beam's end does. A max-range reading, and an echo at or beyond the insertion range
/// (the PRF's R, which takes those for max readings too), clears its cone up to the insertion
/// range. Same 8-bit log-odds cells and outputs as the laser grid (log_odds_cells.hpp).

#include <cstddef>

#include <priormap/core/log.hpp>
#include <priormap/core/map_server.hpp>
#include <priormap/grid/log_odds_cells.hpp>

namespace priormap::grid {

struct SonarGridOptions {
  double resolution = 0.05;         ///< m
  double log_odds_occupied = 0.85;  ///< a cell on the arc
  double log_odds_free = -0.4;      ///< a cell inside the cone before the arc
  double log_odds_limit = 4.0;      ///< |log-odds| saturates here
  double arc_thickness = 0.1;       ///< α: the arc's depth, m
  /// Readings are inserted up to this range; max-range readings (and echoes at or beyond it)
  /// clear their cones up to it, or up to the ring's own max range where that is shorter.
  double max_range = 5.0;
  /// Off: max readings, and echoes at or beyond max_range (max readings for the PRF too), are
  /// left out instead of clearing their cones.
  bool max_readings_clear = true;
  double margin = 1.0;  ///< m around the data, for the grid's extent
  /// The grid may have at most this many cells (CellsCovering).
  double max_cells = kMaxGridCells;
};

class SonarGrid {
 public:
  /// A grid covering `extent`. Throws std::invalid_argument on bad options (lengths that are
  /// not positive and finite, a negative or NaN margin, ...) or an extent that is not finite.
  SonarGrid(const Box2& extent, SonarGridOptions options);

  /// The box holding every transducer and every inserted cone of the sonar rings among scans
  /// [first, end) of the log (other scans are passed over), grown by options.margin.
  [[nodiscard]] static Box2 ExtentOf(const Log& log, std::size_t first, std::size_t end,
                                     const SonarGridOptions& options);

  /// Inserts every usable reading of a sonar ring (invalid readings and scans that are not
  /// rings are skipped). Returns the number of readings inserted.
  std::size_t Insert(const Scan& ring);
  /// One cone from `origin` around direction `axis` (rad) of half-angle `half_spread`: the
  /// cells whose centres lie in it are free up to `range` − α/2 and, when `hit`, occupied
  /// within α/2 of `range` (or, when no centre lies there, the cell holding the point at
  /// `range` on the axis). A half-angle of pi or more is the whole disc. Throws
  /// std::invalid_argument for an apex or axis that is not finite, a negative or NaN
  /// half-angle, or a range that is negative or not finite.
  void InsertCone(const Vec2& origin, double axis, double half_spread, double range, bool hit);

  [[nodiscard]] int width() const { return cells_.width(); }
  [[nodiscard]] int height() const { return cells_.height(); }
  [[nodiscard]] const SonarGridOptions& options() const { return options_; }
  [[nodiscard]] Vec2 origin() const { return origin_; }
  /// Log-odds of a cell (0 when never observed).
  [[nodiscard]] double LogOdds(int ix, int iy) const;
  [[nodiscard]] bool Observed(int ix, int iy) const {
    return cells_.Get(ix, iy) != LogOddsCells::kUnobserved;
  }
  /// P(occupied) per cell, NaN where never observed, row 0 at the bottom.
  [[nodiscard]] OccupancyRaster Raster() const;

 private:
  SonarGridOptions options_;
  Vec2 origin_;
  double scale_;  ///< fixed-point steps per unit of log-odds
  LogOddsCells cells_;
  CellUpdate occupied_;
  CellUpdate free_;
};

}  // namespace priormap::grid
