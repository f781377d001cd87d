#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

#include <fmt/format.h>

#include <priormap/grid/occupancy_grid.hpp>

namespace priormap::grid {
namespace {

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
      // Nothing within the sensor's range, and nothing said of what lies beyond it.
      return BeamToInsert{.range = std::min(options.max_range, scan.max_range), .hit = false};
    case BeamStatus::kValid:
      break;
  }
  if (scan.ranges[i] < options.max_range) return BeamToInsert{.range = scan.ranges[i], .hit = true};
  // A return at or beyond the insertion range is a max reading: R is the PRF's, whose data
  // (SelectBeams) takes a reading at R for a max reading, as Scan::ClassifyAll does at the
  // sensor's own max range. It clears up to R, unless max readings are off.
  if (!options.max_readings_clear) return std::nullopt;
  return BeamToInsert{.range = options.max_range, .hit = false};
}

constexpr int kLimit = INT8_MAX;
// Far outside the grid (or not finite): nothing to do, and the cell indices must fit an int.
constexpr double kFar = 1 << 29;

bool Near(double x, double y) {
  return std::abs(x) < kFar && std::abs(y) < kFar;
}

// std::floor for |x| < kFar, without its branches for values beyond 2^52.
int FloorToInt(double x) {
  const int truncated = static_cast<int>(x);
  return truncated - (x < truncated ? 1 : 0);
}

const GridOptions& Validated(const GridOptions& options) {
  if (options.beam_step == 0) throw std::invalid_argument("the beam step must be positive");
  if (!(options.resolution > 0.0 && std::isfinite(options.resolution)))
    throw std::invalid_argument(
        fmt::format("resolution {} is not a positive size", options.resolution));
  // Non-positive, it would draw returns backwards or as misses at the sensor; NaN, it would
  // insert every return whatever its length; infinite, a max reading would clear without end.
  if (!(options.max_range > 0.0 && std::isfinite(options.max_range)))
    throw std::invalid_argument(
        fmt::format("the insertion range {} is not a positive length", options.max_range));
  if (!(options.margin >= 0.0 && std::isfinite(options.margin)))
    throw std::invalid_argument(fmt::format("the margin {} is not a length", options.margin));
  if (!(options.log_odds_hit > 0.0 && options.log_odds_miss < 0.0))
    throw std::invalid_argument("log-odds of a hit must be positive and of a miss negative");
  if (!(options.log_odds_hit <= options.log_odds_limit &&
        -options.log_odds_miss <= options.log_odds_limit))
    throw std::invalid_argument("log-odds of a hit or a miss must not exceed the limit");
  if (!(options.log_odds_limit > 0.0 && options.log_odds_limit <= 100.0))
    throw std::invalid_argument("the log-odds limit must be in (0, 100]");
  return options;
}

}  // namespace

// ±limit spans the 8-bit range; an update is at least one step.
OccupancyGrid::OccupancyGrid(const Box2& extent, GridOptions options)
    : options_(Validated(options)),
      origin_(extent.min()),
      scale_(kLimit / options_.log_odds_limit),
      cells_(CellsCovering(extent, options_.resolution, options_.max_cells)),
      miss_(std::min(-1, static_cast<int>(std::lround(options_.log_odds_miss * scale_))), kLimit),
      hit_(std::max(1, static_cast<int>(std::lround(options_.log_odds_hit * scale_))), kLimit) {}

Box2 OccupancyGrid::ExtentOf(const Log& log, std::size_t first, std::size_t end,
                             const GridOptions& options) {
  Box2 box;
  bool any_beam = false;
  for (std::size_t k = first; k < std::min(end, log.scans.size()); ++k) {
    const Scan& scan = log.scans[k];
    // A sonar ring's readings are cones, which the laser model would read as rays.
    if (!scan.pose.IsFinite() || scan.sonar) continue;
    box.extend(scan.pose.translation());
    for (std::size_t i = 0; i < scan.size(); i += std::max<std::size_t>(1, options.beam_step)) {
      if (const auto beam = ToInsert(scan, i, options)) {
        box.extend(scan.pose.Transform(beam->range * UnitVector(scan.angles[i])));
        any_beam = true;
      }
    }
  }
  // Poses alone make no map: empty, as for a log without scans.
  if (!any_beam) return {};
  const Vec2 grow = Vec2::Constant(options.margin);
  return {box.min() - grow, box.max() + grow};
}

inline void OccupancyGrid::TraceBeam(int ix, int iy, double x1, double y1, bool hit) {
  if (!Near(x1, y1)) return;
  cells_.TraceLine(ix, iy, FloorToInt(x1), FloorToInt(y1), miss_, hit ? hit_ : miss_);
}

std::size_t OccupancyGrid::Insert(const Scan& scan) {
  if (!scan.pose.IsFinite() || scan.sonar) return 0;
  // A log's scans share their beam angles: their unit vectors are computed once, and each
  // scan only rotates them.
  if (scan.angles != beam_angles_) {
    beam_angles_ = scan.angles;
    beam_directions_.resize(beam_angles_.size());
    for (std::size_t i = 0; i < beam_angles_.size(); ++i)
      beam_directions_[i] = UnitVector(beam_angles_[i]);
  }
  // Every beam of the scan starts in the same cell.
  const Vec2 origin = scan.pose.translation();
  const double inv = 1.0 / options_.resolution;
  const double x0 = (origin.x() - origin_.x()) * inv;
  const double y0 = (origin.y() - origin_.y()) * inv;
  const bool near = Near(x0, y0);
  const int ix = near ? FloorToInt(x0) : 0;
  const int iy = near ? FloorToInt(y0) : 0;
  const double c = std::cos(scan.pose.theta());
  const double s = std::sin(scan.pose.theta());
  std::size_t inserted = 0;
  for (std::size_t i = 0; i < scan.size(); i += options_.beam_step) {
    const auto beam = ToInsert(scan, i, options_);
    if (!beam) continue;
    const Vec2& u = beam_directions_[i];
    const Vec2 direction(c * u.x() - s * u.y(), s * u.x() + c * u.y());
    const Vec2 end = origin + beam->range * direction;
    if (near)
      TraceBeam(ix, iy, (end.x() - origin_.x()) * inv, (end.y() - origin_.y()) * inv, beam->hit);
    ++inserted;
  }
  return inserted;
}

void OccupancyGrid::InsertBeam(const Vec2& origin, const Vec2& end, bool hit) {
  const double inv = 1.0 / options_.resolution;
  const double x0 = (origin.x() - origin_.x()) * inv;
  const double y0 = (origin.y() - origin_.y()) * inv;
  if (!Near(x0, y0)) return;
  TraceBeam(FloorToInt(x0), FloorToInt(y0), (end.x() - origin_.x()) * inv,
            (end.y() - origin_.y()) * inv, hit);
}

double OccupancyGrid::LogOdds(int ix, int iy) const {
  return LogOddsOf(cells_.Get(ix, iy), scale_);
}

OccupancyRaster OccupancyGrid::Raster() const {
  return RasterOf(cells_, origin_, options_.resolution, scale_);
}

}  // namespace priormap::grid
