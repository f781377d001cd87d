#pragma once
/// Scores of occupancy maps against a scene's ground truth (the accuracy study of Paskin &
/// Thrun's Sec. 3 claim that PRFs extrapolate where grids cannot; docs/prf.md):
///   - classification: a map's P(occupied) at the centres of an evaluation raster, black above
///     0.5 and white below, against the true colour, over the observed area and over its sparse
///     part (cells no measurement crossed or ended in);
///   - walls: how far a polygonal map's edges lie from the true walls, and how much of the seen
///     true walls they recover.
/// Nothing here knows the sensor or the mapping method: a sonar map is scored the same way, with
/// its own observed area and coverage (MakeSonarEvaluationRaster, sonar_observed_area.hpp).

#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include <Eigen/Core>

#include <priormap/core/map_server.hpp>
#include <priormap/core/observed_area.hpp>
#include <priormap/core/scene_truth.hpp>
#include <priormap/core/segment.hpp>
#include <priormap/prf/cell_grid.hpp>
#include <priormap/prf/laser_data.hpp>

namespace priormap::prf {

/// The points a map is scored at: the centres of `grid`, with their truth. Indices are CellGrid
/// cell indices (iy * nx + ix).
struct EvaluationRaster {
  CellGrid grid;
  std::vector<std::uint8_t> truth_black;  ///< 1: occupied in truth
  std::vector<Observation> observation;   ///< from the sensor poses
  std::vector<std::uint8_t> covered;      ///< a measurement crossed or ended in the cell

  /// Scored for classification: visible, or just behind a seen surface and black in truth. A
  /// band point that is white in truth lies behind a wall with free space beyond (the corridor's
  /// outside): nothing there was seen, so it is not scored.
  [[nodiscard]] bool Observed(std::size_t i) const {
    return observation[i] == Observation::kVisible ||
           (observation[i] == Observation::kBehindSurface && truth_black[i] != 0);
  }
  /// Observed, yet no measurement crossed or ended in the cell.
  [[nodiscard]] bool Sparse(std::size_t i) const { return Observed(i) && covered[i] == 0; }
  [[nodiscard]] std::size_t size() const { return truth_black.size(); }
};

/// Truth and observation at each centre of `grid`; `covered` all zero (see MarkCoverage).
[[nodiscard]] EvaluationRaster MakeEvaluationRaster(const CellGrid& grid, const SceneTruth& truth,
                                                    const ObservedArea& observed);

/// Marks the cells each beam passes through from its origin to its end (its reading, or R for a
/// max reading), the end's cell included: the cells the data say something about directly.
void MarkCoverage(const LaserData& data, EvaluationRaster* raster);

/// A map's decision at a point from its P(occupied): black above 0.5, white below; exactly 0.5
/// or NaN (never observed) is no decision.
enum class Decision : std::uint8_t { kWhite, kBlack, kUndecided };
[[nodiscard]] Decision Decide(double p_occupied);

/// Counts over a set of scored points. An undecided point counts as an error in Accuracy(): a
/// map that does not know cannot be planned on; Coverage() says how much of the set the map
/// decides, DecidedAccuracy() how well it decides it.
struct ClassificationScore {
  std::size_t points = 0;
  std::size_t decided = 0;
  std::size_t correct = 0;

  [[nodiscard]] double Accuracy() const { return Ratio(correct, points); }
  [[nodiscard]] double Coverage() const { return Ratio(decided, points); }
  [[nodiscard]] double DecidedAccuracy() const { return Ratio(correct, decided); }
  ClassificationScore& operator+=(const ClassificationScore& other);

 private:
  static double Ratio(std::size_t a, std::size_t b) {
    return b > 0 ? static_cast<double>(a) / static_cast<double>(b)
                 : std::numeric_limits<double>::quiet_NaN();
  }
};

/// The classification scores of one map.
struct MapClassification {
  ClassificationScore observed;  ///< the whole observed area
  ClassificationScore sparse;    ///< its cells no measurement crossed or ended in
  ClassificationScore covered;   ///< the rest of it
};

/// Scores P(occupied) given at each point of `raster` (same indexing; NaN where unknown).
[[nodiscard]] MapClassification ScoreClassification(std::span<const double> p_occupied,
                                                    const EvaluationRaster& raster);

/// P(occupied) of a raster map (an occupancy grid) at each centre of `grid`: the value of the
/// map's cell holding the centre, NaN outside the map.
[[nodiscard]] std::vector<double> SampleAtCentres(const OccupancyRaster& map, const CellGrid& grid);
/// A matrix over `grid`'s cells (row iy, column ix), flattened in cell index order.
[[nodiscard]] std::vector<double> Flatten(const Eigen::MatrixXd& values, const CellGrid& grid);

/// The q-quantile (q in [0, 1]) of values with non-negative weights: the smallest value whose
/// cumulative weight reaches q of the total. NaN when the total weight is zero.
[[nodiscard]] double WeightedQuantile(std::vector<double> values, std::vector<double> weights,
                                      double q);

struct WallScoreOptions {
  double spacing = 0.01;    ///< m between the points an edge or a true wall is measured at
  double tolerance = 0.05;  ///< m: a seen true wall point is recovered with an edge this close
  /// m: an edge piece is a wall of the map when the points this far on both of its sides are
  /// observed (visible, or behind a seen surface).
  double side_offset = 0.02;
  /// m: a wall piece is also *supported* when a beam ended (a hit, not a max reading) this close
  /// to it: a wall the sensor perceived, as opposed to a boundary the map drew where nothing
  /// echoed (the shadow behind a door jamb drawn through an unsampled sliver of visible space).
  /// Generous, so that a wall drawn off its hits still counts, with its distance.
  double support_radius = 0.3;
};

struct WallScore {
  /// Length of the map's walls: edges with the observed area on both sides, m.
  double scored_length = 0.0;
  /// Length of edges along the border of the observed area (observed on one side only: the
  /// map's guess where the unseen begins, such as the shadow of a door jamb), not scored, m.
  double border_length = 0.0;
  /// Length-weighted distance of those edges to the nearest true wall, m.
  double mean_distance = std::numeric_limits<double>::quiet_NaN();
  double p90_distance = std::numeric_limits<double>::quiet_NaN();
  double max_distance = std::numeric_limits<double>::quiet_NaN();
  /// The same for the supported pieces (hits given to ScoreWalls); NaN without hits.
  double supported_length = 0.0;
  double supported_mean_distance = std::numeric_limits<double>::quiet_NaN();
  double supported_p90_distance = std::numeric_limits<double>::quiet_NaN();
  double supported_max_distance = std::numeric_limits<double>::quiet_NaN();
  /// Seen true wall points, and the fraction of them with a map edge within the tolerance.
  std::size_t wall_points = 0;
  double recovered_fraction = std::numeric_limits<double>::quiet_NaN();
};

/// Scores a polygonal map's edges. An edge is measured at the midpoints of pieces of at most
/// options.spacing, each weighted by its length. A piece counts as a wall of the map when both
/// its sides are observed: it then claims a wall where the data could show one. Pieces with an
/// unseen side are left out: where the map extrapolates, and along the border of the unseen,
/// where an edge is the map's guess where the shadow behind a seen wall begins, not a wall.
/// `wall_points`: the seen true walls (VisibleWallPoints). `hits`: where the data's beams ended,
/// for the supported pieces' scores.
[[nodiscard]] WallScore ScoreWalls(std::span<const Segment> edges, const SceneTruth& truth,
                                   const ObservedArea& observed, std::span<const Vec2> wall_points,
                                   const WallScoreOptions& options = {},
                                   std::span<const Vec2> hits = {});

}  // namespace priormap::prf
