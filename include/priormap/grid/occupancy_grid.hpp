#pragma once
/// The standard log-odds occupancy grid (Paskin & Thrun, Sec. 1.2; Thrun, Burgard & Fox, ch. 9)
/// with the laser inverse sensor model: each beam lowers the log-odds of the cells it crosses
/// before its end point and raises that of the end point's cell; max-range readings clear the
/// cells up to the insertion range. Log-odds are 8-bit fixed point (±l_max is ±127, a step of
/// l_max/127 = 0.03 at the default l_max = 4), saturated, so that a grid at 5 cm of a building
/// floor stays in cache and updates cost an add and a clamp.

#include <algorithm>
#include <cstdint>
#include <vector>

#include <climits>

#include <priormap/core/log.hpp>
#include <priormap/core/map_server.hpp>

namespace priormap::grid {

struct GridOptions {
  double resolution = 0.05;  // m
  double log_odds_hit = 0.85;
  double log_odds_miss = -0.4;
  double log_odds_limit = 4.0;  // |log-odds| saturates here
  /// Beams are inserted up to this range; max-range readings clear cells up to it.
  double max_range = 20.0;
  bool max_readings_clear = true;
  double margin = 1.0;  // m around the data, for the grid's extent
  /// Every k-th beam of each scan (the PRF's --beam-step, for comparisons at equal data).
  std::size_t beam_step = 1;
};

class OccupancyGrid {
 public:
  /// A grid covering `extent`. Throws std::invalid_argument on bad options.
  OccupancyGrid(const Box2& extent, GridOptions options);

  /// The box holding every sensor and every beam end point (capped at the insertion range) of
  /// scans [first, end) of the log, grown by options.margin.
  [[nodiscard]] static Box2 ExtentOf(const Log& log, std::size_t first, std::size_t end,
                                     const GridOptions& options);

  /// Inserts every usable beam of a scan (invalid readings are skipped). Returns the number of
  /// beams inserted.
  std::size_t Insert(const Scan& scan);
  /// One beam from `origin` to `end`: the cells of Bresenham's line from the origin's cell to
  /// the end's (8-connected, one per step along the major axis) are free, the end's cell is
  /// occupied when `hit`.
  void InsertBeam(const Vec2& origin, const Vec2& end, bool hit);

  [[nodiscard]] int width() const { return nx_; }
  [[nodiscard]] int height() const { return ny_; }
  [[nodiscard]] const GridOptions& options() const { return options_; }
  [[nodiscard]] Vec2 origin() const { return origin_; }
  /// Log-odds of a cell (0 when never observed).
  [[nodiscard]] double LogOdds(int ix, int iy) const;
  [[nodiscard]] bool Observed(int ix, int iy) const { return cells_[Index(ix, iy)] != kUnobserved; }
  /// P(occupied) per cell, NaN where never observed, row 0 at the bottom.
  [[nodiscard]] OccupancyRaster Raster() const;

 private:
  static constexpr std::int8_t kUnobserved = INT8_MIN;
  static constexpr int kLimit = INT8_MAX;
  [[nodiscard]] std::size_t Index(int ix, int iy) const {
    return static_cast<std::size_t>(iy) * static_cast<std::size_t>(nx_) +
           static_cast<std::size_t>(ix);
  }
  template <bool kChecked>
  void TraceCells(int ix, int iy, int end_x, int end_y, bool hit);
  /// A miss: only the lower limit can be reached.
  void AddMiss(std::size_t index) {
    std::int8_t& cell = cells_[index];
    const int current = cell == kUnobserved ? 0 : cell;
    cell = static_cast<std::int8_t>(std::max(current + miss_, -limit_));
  }
  void Add(std::size_t index, int delta) {
    std::int8_t& cell = cells_[index];
    const int current = cell == kUnobserved ? 0 : cell;
    cell = static_cast<std::int8_t>(std::clamp(current + delta, -limit_, limit_));
  }

  GridOptions options_;
  Vec2 origin_;
  int nx_ = 0;
  int ny_ = 0;
  int hit_ = 0;
  int miss_ = 0;
  int limit_ = 0;
  double scale_ = 1.0;  // fixed-point steps per unit of log-odds
  std::vector<std::int8_t> cells_;
  std::vector<double> beam_angles_;  // of the last scan inserted
  std::vector<Vec2> beam_directions_;
};

}  // namespace priormap::grid
