#pragma once
/// How a raster map's boundaries line up with the true walls, for maps that have no edges of
/// their own (an occupancy grid, a PRF posterior): the map's 0.5 contour (where P(occupied)
/// crosses one half), its distance to the true walls (boundary sharpness), and which true
/// walls it finds (Paskin & Thrun, Fig. 5: the grid misses walls that sonar saw at a slant).

#include <cstddef>
#include <limits>
#include <span>
#include <vector>

#include <priormap/core/scene_truth.hpp>
#include <priormap/core/segment.hpp>
#include <priormap/prf/cell_grid.hpp>
#include <priormap/prf/map_scores.hpp>

namespace priormap::prf {

/// The level-0.5 contour of values given at the centres of `grid` (cell index order; NaN:
/// unknown), by marching squares with linear interpolation along the squares' sides. Squares
/// with an unknown corner have no contour; a saddle is resolved by the mean of its corners.
[[nodiscard]] std::vector<Segment> HalfContour(std::span<const double> values,
                                               const CellGrid& grid);

/// A true wall as seen by the data: its length and the points of it that were seen.
struct SeenWall {
  double length = 0.0;       ///< of the whole wall, m
  std::vector<Vec2> points;  ///< seen points, one every ContourWallOptions::spacing
};

struct ContourWallOptions {
  double spacing = 0.01;         ///< m between the points a contour or a wall is measured at
  double tolerance = 0.1;        ///< m: a seen wall point is recovered with the contour this close
  double missed_below = 0.5;     ///< a wall with less of its seen points recovered is missed
  double min_seen_length = 0.2;  ///< m: walls seen less than this are not counted
};

struct ContourWallScore {
  /// Length of the contour within the observed area (the piece's midpoint scored), m.
  double contour_length = 0.0;
  /// Boundary sharpness: the length-weighted distance of that contour to the nearest true wall.
  double mean_distance = std::numeric_limits<double>::quiet_NaN();
  double p90_distance = std::numeric_limits<double>::quiet_NaN();
  /// True walls seen over at least min_seen_length, and those of them missed.
  int walls_seen = 0;
  int walls_missed = 0;
  /// Of all seen wall points (of the walls counted), the fraction recovered.
  double recovered_fraction = std::numeric_limits<double>::quiet_NaN();
};

/// Scores `contour` (HalfContour of a map) against the truth over `raster`'s observed area.
[[nodiscard]] ContourWallScore ScoreContour(std::span<const Segment> contour,
                                            std::span<const SeenWall> walls,
                                            const EvaluationRaster& raster, const SceneTruth& truth,
                                            const ContourWallOptions& options = {});

}  // namespace priormap::prf
