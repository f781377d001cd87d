#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <stdexcept>

#include <fmt/format.h>

#include <priormap/grid/sonar_grid.hpp>

namespace priormap::grid {
namespace {

constexpr int kLimit = INT8_MAX;

const SonarGridOptions& Validated(const SonarGridOptions& o) {
  if (!(o.resolution > 0.0 && std::isfinite(o.resolution)))
    throw std::invalid_argument(fmt::format("resolution {} is not a positive size", o.resolution));
  if (!(o.log_odds_occupied > 0.0 && o.log_odds_free < 0.0))
    throw std::invalid_argument("log-odds of the arc must be positive and of the cone negative");
  if (!(o.log_odds_limit > 0.0 && o.log_odds_limit <= 100.0))
    throw std::invalid_argument("the log-odds limit must be in (0, 100]");
  if (!(o.log_odds_occupied <= o.log_odds_limit && -o.log_odds_free <= o.log_odds_limit))
    throw std::invalid_argument("log-odds of the arc or the cone must not exceed the limit");
  if (!(o.arc_thickness > 0.0 && std::isfinite(o.arc_thickness) && o.max_range > 0.0 &&
        std::isfinite(o.max_range)))
    throw std::invalid_argument("the arc's thickness and the max range must be positive lengths");
  if (!(o.margin >= 0.0 && std::isfinite(o.margin)))
    throw std::invalid_argument(fmt::format("the margin {} is not a length", o.margin));
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
      break;
    case BeamStatus::kValid:
      // An echo at or beyond the insertion range is a max reading: R is the PRF's, whose data
      // (SelectSonarReadings) takes a reading at R for a max reading.
      if (ring.ranges[i] < options.max_range) {
        cone.range = ring.ranges[i];
        cone.hit = true;
        return cone;
      }
      break;
  }
  // A max reading, or an echo at or beyond R: it clears its cone, unless max readings are off.
  if (!options.max_readings_clear) return std::nullopt;
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
  // An infinite range would clear the cone to the grid's edge and mark no echo anywhere.
  if (!(half_spread >= 0.0 && range >= 0.0 && std::isfinite(range) && std::isfinite(axis) &&
        origin.allFinite()))
    throw std::invalid_argument(fmt::format(
        "a cone needs a finite apex and axis, a half-angle >= 0 and a finite range >= 0 "
        "(got apex ({}, {}), axis {}, half-angle {} and range {})",
        origin.x(), origin.y(), axis, half_spread, range));
  // A cone of a full turn or more is the disc; beyond pi the cosine would turn it back, and at
  // pi the cells straight behind the apex would fall out of it by rounding (dot < -r).
  const bool whole_disc = half_spread >= std::numbers::pi;
  const double half = std::min(half_spread, std::numbers::pi);
  const double half_arc = options_.arc_thickness / 2.0;
  const double reach = hit ? range + half_arc : range;
  const double free_until = hit ? range - half_arc : range;
  const Box2 bounds = ConeBounds(origin, axis, half, reach);
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
  const double cos_half = std::cos(half);
  // An arc thinner or narrower than a cell can pass between the centres (short echoes, coarse
  // cells): the cell holding the echo's point on the axis is then its occupied cell, as a laser
  // beam's end cell is, so that no echo is read as free space alone. It is updated last, once.
  const Vec2 echo = origin + range * direction;
  const int echo_x = hit ? index(echo.x(), origin_.x(), width()) : -1;
  const int echo_y = hit ? index(echo.y(), origin_.y(), height()) : -1;
  const CellUpdate* echo_update = nullptr;
  bool arc_marked = false;
  for (int iy = y0; iy <= y1; ++iy) {
    for (int ix = x0; ix <= x1; ++ix) {
      const Vec2 centre = origin_ + options_.resolution * Vec2(ix + 0.5, iy + 0.5);
      const Vec2 d = centre - origin;
      const double r = d.norm();
      if (r > reach || (!whole_disc && direction.dot(d) < cos_half * r)) continue;  // outside
      const CellUpdate* update = r < free_until ? &free_ : hit ? &occupied_ : nullptr;
      if (update == nullptr) continue;
      arc_marked |= update == &occupied_;
      if (ix == echo_x && iy == echo_y)
        echo_update = update;
      else
        cells_.Apply(ix, iy, *update);
    }
  }
  if (hit && !arc_marked) echo_update = &occupied_;
  if (echo_update != nullptr && cells_.Contains(echo_x, echo_y))
    cells_.Apply(echo_x, echo_y, *echo_update);
}

double SonarGrid::LogOdds(int ix, int iy) const {
  return LogOddsOf(cells_.Get(ix, iy), scale_);
}

OccupancyRaster SonarGrid::Raster() const {
  return RasterOf(cells_, origin_, options_.resolution, scale_);
}

}  // namespace priormap::grid
