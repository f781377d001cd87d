#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>

#include <priormap/core/check.hpp>
#include <priormap/prf/map_scores.hpp>
#include <priormap/prf/point_buckets.hpp>

namespace priormap::prf {
namespace {

Box2 GridBox(const CellGrid& grid) {
  return {grid.origin, grid.origin + Vec2(grid.nx * grid.cell.x(), grid.ny * grid.cell.y())};
}

void Count(Decision decision, bool truth_black, ClassificationScore* score) {
  ++score->points;
  if (decision == Decision::kUndecided) return;
  ++score->decided;
  if ((decision == Decision::kBlack) == truth_black) ++score->correct;
}

}  // namespace

EvaluationRaster MakeEvaluationRaster(const CellGrid& grid, const SceneTruth& truth,
                                      const ObservedArea& observed) {
  EvaluationRaster raster;
  raster.grid = grid;
  const auto n = static_cast<std::size_t>(grid.NumCells());
  raster.truth_black.resize(n);
  raster.observation.resize(n);
  raster.covered.assign(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 centre = grid.Centre(static_cast<int>(i));
    raster.truth_black[i] = truth.Occupied(centre) ? 1 : 0;
    raster.observation[i] = observed.Classify(centre);
  }
  return raster;
}

void MarkCoverage(const LaserData& data, EvaluationRaster* raster) {
  const Box2 box = GridBox(raster->grid);
  for (const LaserBeam& beam : data.beams) {
    const auto inside =
        ClipSegmentToBox({beam.origin, beam.origin + beam.range * beam.direction}, box);
    if (!inside) continue;
    WalkCells(raster->grid, inside->a, inside->b, [&](int cell, double, double) {
      raster->covered[static_cast<std::size_t>(cell)] = 1;
      return true;
    });
  }
}

Decision Decide(double p_occupied) {
  if (p_occupied > 0.5) return Decision::kBlack;
  if (p_occupied < 0.5) return Decision::kWhite;
  return Decision::kUndecided;  // 0.5 or NaN
}

ClassificationScore& ClassificationScore::operator+=(const ClassificationScore& other) {
  points += other.points;
  decided += other.decided;
  correct += other.correct;
  return *this;
}

MapClassification ScoreClassification(std::span<const double> p_occupied,
                                      const EvaluationRaster& raster) {
  PRIORMAP_CHECK(p_occupied.size() == raster.size(), "one probability per evaluation point");
  MapClassification score;
  for (std::size_t i = 0; i < raster.size(); ++i) {
    if (!raster.Observed(i)) continue;
    const Decision decision = Decide(p_occupied[i]);
    const bool black = raster.truth_black[i] != 0;
    Count(decision, black, &score.observed);
    Count(decision, black, raster.covered[i] ? &score.covered : &score.sparse);
  }
  return score;
}

std::vector<double> SampleAtCentres(const OccupancyRaster& map, const CellGrid& grid) {
  std::vector<double> values(static_cast<std::size_t>(grid.NumCells()),
                             std::numeric_limits<double>::quiet_NaN());
  const Eigen::MatrixXd& p = map.probability;
  for (int i = 0; i < grid.NumCells(); ++i) {
    const Vec2 cell = (grid.Centre(i) - map.origin) / map.resolution;
    const double ix = std::floor(cell.x()), iy = std::floor(cell.y());
    if (ix >= 0.0 && iy >= 0.0 && ix < static_cast<double>(p.cols()) &&
        iy < static_cast<double>(p.rows()))
      values[static_cast<std::size_t>(i)] =
          p(static_cast<Eigen::Index>(iy), static_cast<Eigen::Index>(ix));
  }
  return values;
}

std::vector<double> Flatten(const Eigen::MatrixXd& values, const CellGrid& grid) {
  PRIORMAP_CHECK(values.rows() == grid.ny && values.cols() == grid.nx,
                 "the matrix must have the grid's shape");
  std::vector<double> flat(static_cast<std::size_t>(grid.NumCells()));
  for (int iy = 0; iy < grid.ny; ++iy)
    for (int ix = 0; ix < grid.nx; ++ix)
      flat[static_cast<std::size_t>(iy * grid.nx + ix)] = values(iy, ix);
  return flat;
}

double WeightedQuantile(std::vector<double> values, std::vector<double> weights, double q) {
  PRIORMAP_CHECK(values.size() == weights.size(), "one weight per value");
  PRIORMAP_CHECK(q >= 0.0 && q <= 1.0, "the quantile must be in [0, 1]");
  std::vector<std::size_t> order(values.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return values[a] < values[b]; });
  const double total = std::accumulate(weights.begin(), weights.end(), 0.0);
  if (!(total > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  double cumulative = 0.0;
  for (std::size_t i : order) {
    PRIORMAP_CHECK(weights[i] >= 0.0, "weights must not be negative");
    cumulative += weights[i];
    // A relative slack, so that q = 1 is reached despite round-off in the sum.
    if (cumulative >= q * total * (1.0 - 1e-12) && weights[i] > 0.0) return values[i];
  }
  return values[order.back()];
}

WallScore ScoreWalls(std::span<const Segment> edges, const SceneTruth& truth,
                     const ObservedArea& observed, std::span<const Vec2> wall_points,
                     const WallScoreOptions& options, std::span<const Vec2> hits) {
  PRIORMAP_CHECK(options.spacing > 0.0 && options.tolerance >= 0.0 && options.side_offset > 0.0 &&
                     options.support_radius > 0.0,
                 "positive spacing, side offset and support radius, and a non-negative tolerance");
  WallScore score;
  std::vector<double> distances, weights;
  std::vector<double> supported_distances, supported_weights;
  const PointBuckets hit_buckets(hits, options.support_radius);
  const auto seen = [&](const Vec2& p) { return observed.Classify(p) != Observation::kUnseen; };
  for (const Segment& edge : edges) {
    const double length = edge.Length();
    const Vec2 side = options.side_offset * edge.Normal();
    const int pieces = std::max(1, static_cast<int>(std::ceil(length / options.spacing)));
    for (int k = 0; k < pieces; ++k) {
      const Vec2 p = edge.PointAt((k + 0.5) / pieces);
      const bool left = seen(p + side), right = seen(p - side);
      if (left && right) {
        distances.push_back(truth.DistanceToWall(p));
        weights.push_back(length / pieces);
        if (hit_buckets.AnyWithin(p, options.support_radius)) {
          supported_distances.push_back(distances.back());
          supported_weights.push_back(weights.back());
        }
      } else if (left || right) {
        score.border_length += length / pieces;
      }
    }
  }
  const auto summarize = [](const std::vector<double>& d, const std::vector<double>& w,
                            double* length, double* mean, double* p90, double* max) {
    *length = std::accumulate(w.begin(), w.end(), 0.0);
    if (*length <= 0.0) return;
    *mean = std::inner_product(d.begin(), d.end(), w.begin(), 0.0) / *length;
    *max = *std::max_element(d.begin(), d.end());
    *p90 = WeightedQuantile(d, w, 0.9);
  };
  summarize(distances, weights, &score.scored_length, &score.mean_distance, &score.p90_distance,
            &score.max_distance);
  if (!hits.empty())
    summarize(supported_distances, supported_weights, &score.supported_length,
              &score.supported_mean_distance, &score.supported_p90_distance,
              &score.supported_max_distance);

  score.wall_points = wall_points.size();
  if (!wall_points.empty()) {
    std::vector<Box2> boxes;
    for (const Segment& edge : edges) {
      Box2 box = edge.Bounds();
      boxes.emplace_back(box.min() - Vec2::Constant(options.tolerance),
                         box.max() + Vec2::Constant(options.tolerance));
    }
    std::size_t recovered = 0;
    for (const Vec2& p : wall_points) {
      for (std::size_t e = 0; e < edges.size(); ++e) {
        if (boxes[e].contains(p) && PointSegmentDistance(p, edges[e]) <= options.tolerance) {
          ++recovered;
          break;
        }
      }
    }
    score.recovered_fraction =
        static_cast<double>(recovered) / static_cast<double>(wall_points.size());
  }
  return score;
}

}  // namespace priormap::prf
