#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

#include <fmt/format.h>

#include <priormap/grid/occupancy_grid.hpp>

namespace priormap::grid {
namespace {

// Log-odds units per 1.0 of log-odds: fine enough that 0.85 and -0.4 keep three digits.

struct BeamToInsert {
  double range;
  bool hit;
};

// How far beam i is inserted and whether its end is a hit; nullopt for beams left out.
std::optional<BeamToInsert> ToInsert(const Scan& scan, std::size_t i, const GridOptions& options) {
  switch (scan.status[i]) {
    case BeamStatus::kInvalid:
      return std::nullopt;
    case BeamStatus::kMaxRange:
      if (!options.max_readings_clear) return std::nullopt;
      return BeamToInsert{.range = options.max_range, .hit = false};
    case BeamStatus::kValid:
      break;
  }
  // A return beyond the insertion range clears up to it.
  if (scan.ranges[i] > options.max_range)
    return BeamToInsert{.range = options.max_range, .hit = false};
  return BeamToInsert{.range = scan.ranges[i], .hit = true};
}

}  // namespace

OccupancyGrid::OccupancyGrid(const Box2& extent, GridOptions options) : options_(options) {
  if (options_.beam_step == 0) throw std::invalid_argument("the beam step must be positive");
  if (!(options_.resolution > 0.0))
    throw std::invalid_argument(fmt::format("resolution {} is not positive", options_.resolution));
  if (!(options_.log_odds_hit > 0.0 && options_.log_odds_miss < 0.0))
    throw std::invalid_argument("log-odds of a hit must be positive and of a miss negative");
  if (!(options_.log_odds_hit <= options_.log_odds_limit &&
        -options_.log_odds_miss <= options_.log_odds_limit))
    throw std::invalid_argument("log-odds of a hit or a miss must not exceed the limit");
  if (!(options_.log_odds_limit > 0.0 && options_.log_odds_limit <= 100.0))
    throw std::invalid_argument("the log-odds limit must be in (0, 100]");
  if (extent.isEmpty()) throw std::invalid_argument("the grid's extent is empty");
  origin_ = extent.min();
  const Vec2 size = extent.sizes() / options_.resolution;
  if (size.x() * size.y() > 4e9) throw std::invalid_argument("the grid would exceed 4e9 cells");
  nx_ = std::max(1, static_cast<int>(std::ceil(size.x())));
  ny_ = std::max(1, static_cast<int>(std::ceil(size.y())));
  // ±limit spans the 8-bit range; an update is at least one step.
  scale_ = kLimit / options_.log_odds_limit;
  limit_ = kLimit;
  hit_ = std::max(1, static_cast<int>(std::lround(options_.log_odds_hit * scale_)));
  miss_ = std::min(-1, static_cast<int>(std::lround(options_.log_odds_miss * scale_)));
  cells_.assign(static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_), kUnobserved);
}

Box2 OccupancyGrid::ExtentOf(const Log& log, std::size_t first, std::size_t end,
                             const GridOptions& options) {
  Box2 box;
  for (std::size_t k = first; k < std::min(end, log.scans.size()); ++k) {
    const Scan& scan = log.scans[k];
    if (!scan.pose.IsFinite()) continue;
    box.extend(scan.pose.translation());
    for (std::size_t i = 0; i < scan.size(); i += std::max<std::size_t>(1, options.beam_step))
      if (const auto beam = ToInsert(scan, i, options))
        box.extend(scan.pose.Transform(beam->range * UnitVector(scan.angles[i])));
  }
  if (box.isEmpty()) return box;
  const Vec2 grow = Vec2::Constant(options.margin);
  return {box.min() - grow, box.max() + grow};
}

std::size_t OccupancyGrid::Insert(const Scan& scan) {
  if (!scan.pose.IsFinite()) return 0;
  // A log's scans share their beam angles: their unit vectors are computed once, and each
  // scan only rotates them.
  if (scan.angles != beam_angles_) {
    beam_angles_ = scan.angles;
    beam_directions_.resize(beam_angles_.size());
    for (std::size_t i = 0; i < beam_angles_.size(); ++i)
      beam_directions_[i] = UnitVector(beam_angles_[i]);
  }
  const Vec2 origin = scan.pose.translation();
  const double c = std::cos(scan.pose.theta());
  const double s = std::sin(scan.pose.theta());
  std::size_t inserted = 0;
  for (std::size_t i = 0; i < scan.size(); i += options_.beam_step) {
    const auto beam = ToInsert(scan, i, options_);
    if (!beam) continue;
    const Vec2& u = beam_directions_[i];
    const Vec2 direction(c * u.x() - s * u.y(), s * u.x() + c * u.y());
    InsertBeam(origin, origin + beam->range * direction, beam->hit);
    ++inserted;
  }
  return inserted;
}

template <bool kChecked>
void OccupancyGrid::TraceCells(int ix, int iy, int end_x, int end_y, bool hit) {
  // Bresenham's line over cell indices: one cell per step along the major axis, the minor one
  // advanced by the error term's sign (branch-free: the steps are not predictable).
  const int adx = std::abs(end_x - ix);
  const int ady = std::abs(end_y - iy);
  const int sx = end_x > ix ? 1 : -1;
  const int sy = end_y > iy ? 1 : -1;
  const bool x_major = adx >= ady;
  const int major = x_major ? adx : ady;
  const int minor = x_major ? ady : adx;
  const auto nx = static_cast<std::ptrdiff_t>(nx_);
  const std::ptrdiff_t major_step = x_major ? sx : sy * nx;
  const std::ptrdiff_t minor_step = x_major ? sy * nx : sx;
  const int major_dx = x_major ? sx : 0, major_dy = x_major ? 0 : sy;
  const int minor_dx = x_major ? 0 : sx, minor_dy = x_major ? sy : 0;
  auto index = static_cast<std::ptrdiff_t>(Index(kChecked ? 0 : ix, kChecked ? 0 : iy));
  int error = major / 2;
  for (int n = 0; n < major; ++n) {
    if constexpr (kChecked) {
      if (ix >= 0 && iy >= 0 && ix < nx_ && iy < ny_) AddMiss(Index(ix, iy));
    } else {
      AddMiss(static_cast<std::size_t>(index));
    }
    error -= minor;
    const int below = error >> 31;  // -1 when the minor coordinate advances, else 0
    error += major & below;
    if constexpr (kChecked) {
      ix += major_dx + (minor_dx & below);
      iy += major_dy + (minor_dy & below);
    } else {
      index += major_step + (minor_step & static_cast<std::ptrdiff_t>(below));
    }
  }
  // The loop ends on the end cell.
  if constexpr (kChecked) {
    if (ix >= 0 && iy >= 0 && ix < nx_ && iy < ny_) Add(Index(ix, iy), hit ? hit_ : miss_);
  } else {
    Add(static_cast<std::size_t>(index), hit ? hit_ : miss_);
  }
}

void OccupancyGrid::InsertBeam(const Vec2& origin, const Vec2& end, bool hit) {
  const double inv = 1.0 / options_.resolution;
  const double x0 = (origin.x() - origin_.x()) * inv;
  const double y0 = (origin.y() - origin_.y()) * inv;
  const double x1 = (end.x() - origin_.x()) * inv;
  const double y1 = (end.y() - origin_.y()) * inv;
  // Far outside the grid (or not finite): nothing to do, and the cell indices must fit an int.
  constexpr double kFar = 1 << 29;
  if (!(std::abs(x0) < kFar && std::abs(y0) < kFar && std::abs(x1) < kFar && std::abs(y1) < kFar))
    return;
  const int ix = static_cast<int>(std::floor(x0));
  const int iy = static_cast<int>(std::floor(y0));
  const int end_x = static_cast<int>(std::floor(x1));
  const int end_y = static_cast<int>(std::floor(y1));
  const auto inside = [&](int x, int y) { return x >= 0 && y >= 0 && x < nx_ && y < ny_; };
  // The grid is a rectangle: with both ends inside, so is every cell between.
  if (inside(ix, iy) && inside(end_x, end_y))
    TraceCells<false>(ix, iy, end_x, end_y, hit);
  else
    TraceCells<true>(ix, iy, end_x, end_y, hit);
}

double OccupancyGrid::LogOdds(int ix, int iy) const {
  const std::int8_t cell = cells_[Index(ix, iy)];
  return cell == kUnobserved ? 0.0 : cell / scale_;
}

OccupancyRaster OccupancyGrid::Raster() const {
  OccupancyRaster raster;
  raster.origin = origin_;
  raster.resolution = options_.resolution;
  raster.probability.resize(ny_, nx_);
  for (int iy = 0; iy < ny_; ++iy)
    for (int ix = 0; ix < nx_; ++ix) {
      const std::int8_t cell = cells_[Index(ix, iy)];
      raster.probability(iy, ix) = cell == kUnobserved ? std::numeric_limits<double>::quiet_NaN()
                                                       : 1.0 / (1.0 + std::exp(-cell / scale_));
    }
  return raster;
}

}  // namespace priormap::grid
