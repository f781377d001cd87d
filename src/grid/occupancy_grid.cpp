#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

#include <fmt/format.h>

#include <priormap/grid/occupancy_grid.hpp>

namespace priormap::grid {
namespace {

// Log-odds units per 1.0 of log-odds: fine enough that 0.85 and -0.4 keep three digits.
constexpr double kScale = 1000.0;

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
  if (!(options_.resolution > 0.0))
    throw std::invalid_argument(fmt::format("resolution {} is not positive", options_.resolution));
  if (!(options_.log_odds_hit > 0.0 && options_.log_odds_miss < 0.0))
    throw std::invalid_argument("log-odds of a hit must be positive and of a miss negative");
  if (!(options_.log_odds_limit > 0.0 && options_.log_odds_limit * kScale < 32000.0))
    throw std::invalid_argument("the log-odds limit must be in (0, 32)");
  if (extent.isEmpty()) throw std::invalid_argument("the grid's extent is empty");
  origin_ = extent.min();
  const Vec2 size = extent.sizes() / options_.resolution;
  if (size.x() * size.y() > 4e9) throw std::invalid_argument("the grid would exceed 4e9 cells");
  nx_ = std::max(1, static_cast<int>(std::ceil(size.x())));
  ny_ = std::max(1, static_cast<int>(std::ceil(size.y())));
  hit_ = static_cast<int>(std::lround(options_.log_odds_hit * kScale));
  miss_ = static_cast<int>(std::lround(options_.log_odds_miss * kScale));
  limit_ = static_cast<int>(std::lround(options_.log_odds_limit * kScale));
  cells_.assign(static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_), kUnobserved);
}

Box2 OccupancyGrid::ExtentOf(const Log& log, std::size_t first, std::size_t end,
                             const GridOptions& options) {
  Box2 box;
  for (std::size_t k = first; k < std::min(end, log.scans.size()); ++k) {
    const Scan& scan = log.scans[k];
    if (!scan.pose.IsFinite()) continue;
    box.extend(scan.pose.translation());
    for (std::size_t i = 0; i < scan.size(); ++i)
      if (const auto beam = ToInsert(scan, i, options))
        box.extend(scan.pose.Transform(beam->range * UnitVector(scan.angles[i])));
  }
  if (box.isEmpty()) return box;
  const Vec2 grow = Vec2::Constant(options.margin);
  return {box.min() - grow, box.max() + grow};
}

std::size_t OccupancyGrid::Insert(const Scan& scan) {
  if (!scan.pose.IsFinite()) return 0;
  const Vec2 origin = scan.pose.translation();
  std::size_t inserted = 0;
  for (std::size_t i = 0; i < scan.size(); ++i) {
    const auto beam = ToInsert(scan, i, options_);
    if (!beam) continue;
    InsertBeam(origin, origin + beam->range * UnitVector(scan.pose.theta() + scan.angles[i]),
               beam->hit);
    ++inserted;
  }
  return inserted;
}

void OccupancyGrid::InsertBeam(const Vec2& origin, const Vec2& end, bool hit) {
  // Cell coordinates (continuous), then an integer DDA (Amanatides & Woo) from the origin's cell
  // to the end's; cells outside the grid are skipped.
  const double inv = 1.0 / options_.resolution;
  const double x0 = (origin.x() - origin_.x()) * inv;
  const double y0 = (origin.y() - origin_.y()) * inv;
  const double x1 = (end.x() - origin_.x()) * inv;
  const double y1 = (end.y() - origin_.y()) * inv;
  if (!(std::isfinite(x0) && std::isfinite(y0) && std::isfinite(x1) && std::isfinite(y1))) return;
  int ix = static_cast<int>(std::floor(x0));
  int iy = static_cast<int>(std::floor(y0));
  const int end_x = static_cast<int>(std::floor(x1));
  const int end_y = static_cast<int>(std::floor(y1));
  const double dx = x1 - x0;
  const double dy = y1 - y0;
  const int step_x = dx > 0 ? 1 : -1;
  const int step_y = dy > 0 ? 1 : -1;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const double delta_x = dx != 0.0 ? std::abs(1.0 / dx) : kInf;
  const double delta_y = dy != 0.0 ? std::abs(1.0 / dy) : kInf;
  double t_x = dx != 0.0 ? ((dx > 0 ? ix + 1 - x0 : x0 - ix) * delta_x) : kInf;
  double t_y = dy != 0.0 ? ((dy > 0 ? iy + 1 - y0 : y0 - iy) * delta_y) : kInf;
  const int steps = std::abs(end_x - ix) + std::abs(end_y - iy);
  const auto inside = [&](int x, int y) { return x >= 0 && y >= 0 && x < nx_ && y < ny_; };
  for (int n = 0; n < steps; ++n) {
    if (inside(ix, iy)) Add(Index(ix, iy), miss_);
    if (t_x < t_y) {
      ix += step_x;
      t_x += delta_x;
    } else {
      iy += step_y;
      t_y += delta_y;
    }
  }
  // The end cell (the DDA may stop one cell off when rounding swaps two steps; use the end's own
  // cell for the hit).
  if (inside(end_x, end_y)) Add(Index(end_x, end_y), hit ? hit_ : miss_);
}

double OccupancyGrid::LogOdds(int ix, int iy) const {
  const std::int16_t cell = cells_[Index(ix, iy)];
  return cell == kUnobserved ? 0.0 : cell / kScale;
}

OccupancyRaster OccupancyGrid::Raster() const {
  OccupancyRaster raster;
  raster.origin = origin_;
  raster.resolution = options_.resolution;
  raster.probability.resize(ny_, nx_);
  for (int iy = 0; iy < ny_; ++iy)
    for (int ix = 0; ix < nx_; ++ix) {
      const std::int16_t cell = cells_[Index(ix, iy)];
      raster.probability(iy, ix) = cell == kUnobserved ? std::numeric_limits<double>::quiet_NaN()
                                                       : 1.0 / (1.0 + std::exp(-cell / kScale));
    }
  return raster;
}

}  // namespace priormap::grid
