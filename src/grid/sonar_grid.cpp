#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include <fmt/format.h>

#include <priormap/grid/sonar_grid.hpp>

namespace priormap::grid {
namespace {

constexpr int kLimit = INT8_MAX;

const SonarGridOptions& Validated(const SonarGridOptions& o) {
  if (!(o.resolution > 0.0))
    throw std::invalid_argument(fmt::format("resolution {} is not positive", o.resolution));
  if (!(o.log_odds_occupied > 0.0 && o.log_odds_free < 0.0))
    throw std::invalid_argument("log-odds of the arc must be positive and of the cone negative");
  if (!(o.log_odds_limit > 0.0 && o.log_odds_limit <= 100.0))
    throw std::invalid_argument("the log-odds limit must be in (0, 100]");
  if (!(o.log_odds_occupied <= o.log_odds_limit && -o.log_odds_free <= o.log_odds_limit))
    throw std::invalid_argument("log-odds of the arc or the cone must not exceed the limit");
  if (!(o.arc_thickness > 0.0 && o.max_range > 0.0 && std::isfinite(o.max_range)))
    throw std::invalid_argument("the arc's thickness and the max range must be positive");
  return o;
}

int Steps(double log_odds, double scale) {
  const int steps = static_cast<int>(std::lround(log_odds * scale));
  return log_odds > 0.0 ? std::clamp(steps, 1, kLimit) : std::clamp(steps, -kLimit, -1);
}

struct ConeToInsert {
  Vec2 origin;
  double axis;
  double range;
  bool hit;
};

// Reading i of a ring as a cone to insert; nullopt for readings left out.
std::optional<ConeToInsert> ToInsert(const Scan& ring, std::size_t i,
                                     const SonarGridOptions& options) {
  ConeToInsert cone{.origin = ring.pose.Transform(ring.sonar->Origin(i)),
                    .axis = ring.pose.theta() + ring.angles[i],
                    // A max-range reading says nothing lies within the sensor's range, and
                    // nothing of what lies beyond it.
                    .range = std::min(options.max_range, ring.max_range),
                    .hit = false};
  switch (ring.status[i]) {
    case BeamStatus::kInvalid:
      return std::nullopt;
    case BeamStatus::kMaxRange:
      if (!options.max_readings_clear) return std::nullopt;
      return cone;
    case BeamStatus::kValid:
      break;
  }
  // An echo beyond the insertion range clears up to it.
  if (ring.ranges[i] <= options.max_range) {
    cone.range = ring.ranges[i];
    cone.hit = true;
  }
  return cone;
}

// The bounding box of a cone (apex, axis angle, half-angle) up to `reach`.
Box2 ConeBounds(const Vec2& origin, double axis, double half, double reach) {
  Box2 box;
  box.extend(origin);
  for (const double side : {-1.0, 1.0}) box.extend(origin + reach * UnitVector(axis + side * half));
  const Vec2 direction = UnitVector(axis);
  for (const Vec2& d : {Vec2(1, 0), Vec2(-1, 0), Vec2(0, 1), Vec2(0, -1)})
    if (direction.dot(d) >= std::cos(half)) box.extend(origin + reach * d);
  return box;
}

}  // namespace

SonarGrid::SonarGrid(const Box2& extent, SonarGridOptions options)
    : options_(Validated(options)),
      origin_(extent.min()),
      scale_(kLimit / options_.log_odds_limit),
      cells_(CellsCovering(extent, options_.resolution, options_.max_cells)),
      occupied_(Steps(options_.log_odds_occupied, scale_), kLimit),
      free_(Steps(options_.log_odds_free, scale_), kLimit) {}

Box2 SonarGrid::ExtentOf(const Log& log, std::size_t first, std::size_t end,
                         const SonarGridOptions& options) {
  Box2 box;
  for (std::size_t k = first; k < std::min(end, log.scans.size()); ++k) {
    const Scan& ring = log.scans[k];
    if (!ring.sonar || !ring.pose.IsFinite()) continue;
    const double half = ring.sonar->spread / 2.0;
    for (std::size_t i = 0; i < ring.size(); ++i) {
      if (const auto cone = ToInsert(ring, i, options))
        box.extend(ConeBounds(cone->origin, cone->axis, half,
                              cone->range + (cone->hit ? options.arc_thickness / 2.0 : 0.0)));
    }
  }
  if (box.isEmpty()) return box;
  const Vec2 grow = Vec2::Constant(options.margin);
  return {box.min() - grow, box.max() + grow};
}

std::size_t SonarGrid::Insert(const Scan& ring) {
  if (!ring.sonar || !ring.pose.IsFinite()) return 0;
  const double half = ring.sonar->spread / 2.0;
  std::size_t inserted = 0;
  for (std::size_t i = 0; i < ring.size(); ++i) {
    const auto cone = ToInsert(ring, i, options_);
    if (!cone) continue;
    InsertCone(cone->origin, cone->axis, half, cone->range, cone->hit);
    ++inserted;
  }
  return inserted;
}

void SonarGrid::InsertCone(const Vec2& origin, double axis, double half_spread, double range,
                           bool hit) {
  const double half_arc = options_.arc_thickness / 2.0;
  const double reach = hit ? range + half_arc : range;
  const double free_until = hit ? range - half_arc : range;
  const Box2 bounds = ConeBounds(origin, axis, half_spread, reach);
  const double inv = 1.0 / options_.resolution;
  // Cells whose centres may lie in the cone, clamped to the grid.
  // Clamped as doubles first: casting a huge or NaN index to int is undefined.
  const auto index = [&](double v, double o, int n) {
    const double i = std::floor((v - o) * inv);
    return static_cast<int>(std::clamp(std::isnan(i) ? -1.0 : i, -1.0, static_cast<double>(n)));
  };
  const int x0 = std::max(0, index(bounds.min().x(), origin_.x(), width()));
  const int y0 = std::max(0, index(bounds.min().y(), origin_.y(), height()));
  const int x1 = std::min(width() - 1, index(bounds.max().x(), origin_.x(), width()));
  const int y1 = std::min(height() - 1, index(bounds.max().y(), origin_.y(), height()));
  const Vec2 direction = UnitVector(axis);
  const double cos_half = std::cos(half_spread);
  for (int iy = y0; iy <= y1; ++iy) {
    for (int ix = x0; ix <= x1; ++ix) {
      const Vec2 centre = origin_ + options_.resolution * Vec2(ix + 0.5, iy + 0.5);
      const Vec2 d = centre - origin;
      const double r = d.norm();
      if (r > reach || direction.dot(d) < cos_half * r) continue;  // outside the cone
      if (r < free_until)
        cells_.Apply(ix, iy, free_);
      else if (hit)
        cells_.Apply(ix, iy, occupied_);
    }
  }
}

double SonarGrid::LogOdds(int ix, int iy) const {
  return LogOddsOf(cells_.Get(ix, iy), scale_);
}

OccupancyRaster SonarGrid::Raster() const {
  return RasterOf(cells_, origin_, options_.resolution, scale_);
}

}  // namespace priormap::grid
