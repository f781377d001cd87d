#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

#include <priormap/core/check.hpp>
#include <priormap/prf/contour_scores.hpp>
#include <priormap/prf/point_buckets.hpp>

namespace priormap::prf {
namespace {

constexpr double kLevel = 0.5;

}  // namespace

std::vector<Segment> HalfContour(std::span<const double> values, const CellGrid& grid) {
  PRIORMAP_CHECK(values.size() == static_cast<std::size_t>(grid.NumCells()),
                 "one value per cell of the grid");
  std::vector<Segment> contour;
  const auto value = [&](int ix, int iy) {
    return values[static_cast<std::size_t>(iy) * static_cast<std::size_t>(grid.nx) +
                  static_cast<std::size_t>(ix)];
  };
  for (int iy = 0; iy + 1 < grid.ny; ++iy) {
    for (int ix = 0; ix + 1 < grid.nx; ++ix) {
      // Corners counter-clockwise from the lower left, at the cells' centres.
      const std::array<int, 4> cx{ix, ix + 1, ix + 1, ix}, cy{iy, iy, iy + 1, iy + 1};
      std::array<double, 4> v{};
      std::array<Vec2, 4> p;
      bool known = true;
      for (int k = 0; k < 4; ++k) {
        v[k] = value(cx[k], cy[k]);
        known = known && std::isfinite(v[k]);
        p[k] = grid.Centre(cy[k] * grid.nx + cx[k]);
      }
      if (!known) continue;
      // Where the level crosses each side (side k joins corner k and k + 1).
      std::array<Vec2, 4> crossing;
      crossing.fill(Vec2::Zero());
      std::array<bool, 4> crosses{};
      int count = 0;
      for (int k = 0; k < 4; ++k) {
        const double a = v[k], b = v[(k + 1) % 4];
        if ((a >= kLevel) == (b >= kLevel)) continue;
        const double t = (kLevel - a) / (b - a);
        crossing[k] = p[k] + t * (p[(k + 1) % 4] - p[k]);
        crosses[k] = true;
        ++count;
      }
      if (count == 2) {
        std::array<Vec2, 2> ends{Vec2::Zero(), Vec2::Zero()};
        int n = 0;
        for (int k = 0; k < 4; ++k)
          if (crosses[k]) ends[n++] = crossing[k];
        contour.push_back({ends[0], ends[1]});
      } else if (count == 4) {
        // A saddle: corners 0 and 2 on one side of the level, 1 and 3 on the other. When the
        // mean is on corner 0's side, the region of corner 0 connects across the centre, and
        // the contour cuts off corners 1 and 3.
        const bool centre_high = (v[0] + v[1] + v[2] + v[3]) / 4.0 >= kLevel;
        if (centre_high == (v[0] >= kLevel)) {
          contour.push_back({crossing[0], crossing[1]});  // around corner 1
          contour.push_back({crossing[2], crossing[3]});  // around corner 3
        } else {
          contour.push_back({crossing[3], crossing[0]});  // around corner 0
          contour.push_back({crossing[1], crossing[2]});  // around corner 2
        }
      }
    }
  }
  return contour;
}

ContourWallScore ScoreContour(std::span<const Segment> contour, std::span<const SeenWall> walls,
                              const EvaluationRaster& raster, const SceneTruth& truth,
                              const ContourWallOptions& options) {
  PRIORMAP_CHECK(options.spacing > 0.0 && options.tolerance > 0.0 && options.missed_below >= 0.0 &&
                     options.min_seen_length >= 0.0,
                 "positive spacing and tolerance, non-negative thresholds");
  ContourWallScore score;
  std::vector<double> distances, weights;
  std::vector<Vec2> points;  // the scored contour, one point per piece
  for (const Segment& s : contour) {
    const double length = s.Length();
    const int pieces = std::max(1, static_cast<int>(std::ceil(length / options.spacing)));
    for (int k = 0; k < pieces; ++k) {
      const Vec2 p = s.PointAt((k + 0.5) / pieces);
      if (!raster.Observed(static_cast<std::size_t>(raster.grid.CellOf(p)))) continue;
      points.push_back(p);
      distances.push_back(truth.DistanceToWall(p));
      weights.push_back(length / pieces);
    }
  }
  score.contour_length = std::accumulate(weights.begin(), weights.end(), 0.0);
  if (score.contour_length > 0.0) {
    score.mean_distance =
        std::inner_product(distances.begin(), distances.end(), weights.begin(), 0.0) /
        score.contour_length;
    score.p90_distance = WeightedQuantile(distances, weights, 0.9);
  }

  const PointBuckets near(points, options.tolerance);
  std::size_t seen = 0, recovered = 0;
  for (const SeenWall& wall : walls) {
    const double seen_length = static_cast<double>(wall.points.size()) * options.spacing;
    if (wall.points.empty() || seen_length < options.min_seen_length) continue;
    std::size_t found = 0;
    for (const Vec2& p : wall.points) found += near.AnyWithin(p, options.tolerance) ? 1 : 0;
    ++score.walls_seen;
    if (static_cast<double>(found) < options.missed_below * static_cast<double>(wall.points.size()))
      ++score.walls_missed;
    seen += wall.points.size();
    recovered += found;
  }
  if (seen > 0)
    score.recovered_fraction = static_cast<double>(recovered) / static_cast<double>(seen);
  return score;
}

}  // namespace priormap::prf
