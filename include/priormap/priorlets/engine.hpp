#pragma once
/// MAP estimate of one scan under a user prior (de la Puente & Censi, Sec. III): corrected ranges
/// and normals, the topology (regions and surfaces), and the outliers.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <priormap/core/scan.hpp>
#include <priormap/dsl/prior.hpp>

namespace priormap::priorlets {

/// The relation between two consecutive in-model points (paper Sec. II-A).
enum class Link : std::uint8_t { kSameRegion = 0, kDifferentRegion = 1, kDifferentSurface = 2 };

/// "same_region", "different_region", "different_surface".
[[nodiscard]] const char* ToString(Link link);

struct EngineOptions {
  /// Prior probability that a reading is described by the prior; gamma = log(beta / (1 - beta))
  /// is the reward per in-model point in MapScan::objective. As in the paper's Algorithm 1, it
  /// does not steer the search: which readings are outliers is decided by the range bounds
  /// (rho_bound_sigmas), the spikes and the regions' sizes (min_region_points).
  double beta = 0.95;
  /// Each range may move at most this many sigmas from its measurement (paper Sec. III-B).
  double rho_bound_sigmas = 4.0;
  /// A surface seen at more than this incidence (angle between its normal and the ray) is not
  /// believed: consecutive readings that would need it are on different surfaces (Fig. 5a).
  double max_incidence_deg = 85.0;
  /// Normals stay this close to facing the sensor (the bounds on alpha).
  double alpha_bound_deg = 89.0;
  /// Regions with fewer points are clutter: their points leave INMODEL.
  int min_region_points = 4;
  /// Neighbours on each side used to estimate the initial normal of a point, at least: the
  /// window grows (up to 16 times) while its points fit a line, and is one-sided next to a border.
  int normal_half_window = 4;
  /// The initial normals enter as a weak prior with at least this standard deviation, rad; it
  /// regularises normals no constraint or energy determines.
  double alpha_prior_sigma_min = 0.2;
  /// Feasible when every equality |f|, inequality max(0, g) and disjunction is below this.
  /// Residuals are in the constraints' own units, but for windows more than 100 m away (the
  /// engine's kUnitRange): there a constraint homogeneous in the ranges, such as a point's
  /// distance from its neighbour's line, is taken relative to the window's largest range r, as
  /// if the window were 100 m away (a residual in metres times 100 m / r; a curvature times
  /// r / 100 m), so that a far scene is solved as that scene 100 m away.
  double feasibility_tolerance = 1e-6;
  /// Penalty homotopy: lambda from lambda_initial, times lambda_factor per stage, up to
  /// lambda_max. The log barrier's weight 1/mu shrinks alongside (mu times mu_factor, capped).
  double lambda_initial = 1.0;
  double lambda_factor = 10.0;
  double lambda_max = 1e12;
  double mu_initial = 1.0;
  double mu_factor = 10.0;
  double mu_max = 1e6;
  /// Newton steps per homotopy stage (fewer when a step changes little; up to 8 more when the
  /// stage looks stalled, so that infeasibility is judged on a converged stage).
  int max_newton_steps_per_stage = 2;
  /// Outer rounds (topology changes) at most.
  int max_outer_rounds = 400;
  /// Links are grouped into zones of non-negligible penalty; the peak link of every zone whose
  /// total penalty is at least this fraction of the largest zone's breaks in the same round
  /// (1 = one at a time, as in the paper).
  double break_ratio = 0.5;
  /// After a feasible topology is found, try moving every region border by a beam and merging
  /// neighbouring regions again, keeping what stays feasible and fits better (backtracking over
  /// the greedy decisions, the paper's future work); then move every corner's border to where
  /// its two regions' lines meet, or make it a surface border where they meet nowhere near
  /// (CheckCorner). No move leaves a region below min_region_points: in the border moves, one
  /// that would makes both the region's borders same_region instead (it and its two neighbours
  /// become one region), kept whenever the prior allows it; a corner is not moved.
  bool refine_borders = true;
  /// When the scan covers a full turn (CoversFullTurn), its last and first readings are
  /// neighbours like any other two: the in-model points form a ring (MapScan::closed), so that a
  /// wall across the seam is one region and the priorlets hold there too. false treats every
  /// scan as a chain from its first beam to its last.
  bool close_full_turn = true;
};

/// The 360-degree rule: true when the scan's beams go round a full turn evenly, so that its last
/// beam and its first are neighbours: at least 3 beams (a laser's, not a sonar ring's), and the
/// gap from the last angle round to the first, angles[0] + 2 pi - angles[n - 1], is the mean
/// beam step (angles[n - 1] - angles[0]) / (n - 1) to within kFullTurnStepTolerance of a step,
/// i.e. fov + step = 2 pi. A scan with a wider gap (a 359-degree scan missing a beam, 270
/// degrees) is a chain; so is one that sweeps more than a turn. RangeSensor::BeamAngles of a
/// sensor with fov = 2 pi is such a scan (n steps of 2 pi / n from -pi).
///
/// The engine then links the last valid reading to the first like any two consecutive ones
/// (only where the scan's indices start differs): the link is a geometric surface border when
/// max-range readings lie between them (at either end of the scan) or their ranges jump; the
/// priorlets' windows run across it, seeing the points past the seam a turn on (phi and alpha
/// + 2 pi); and the initial normals' line fits, the spike test, the region-size test, the zones
/// of broken links, the border refinement and the corner checks all run round it. So do the
/// posterior's Free, curvature (Extr) and covariance. Should outliers leave fewer than 3 points,
/// or no more than the prior's order, the points are a chain again.
[[nodiscard]] bool CoversFullTurn(const Scan& scan);
/// A gap from the last beam to the first within this fraction of a beam step of one step
/// closes the turn: a missing beam makes it two steps, rounding of the angles (a float's, or a
/// log's 0.01 deg) a few percent at most.
inline constexpr double kFullTurnStepTolerance = 0.1;

/// Where the time went, and how much work it took.
struct EngineStats {
  int outer_rounds = 0;
  int inner_solves = 0;
  int newton_steps = 0;
  int refinement_trials = 0;
  double seconds_total = 0.0;
  double seconds_outer = 0.0;   ///< inner solves of the greedy relaxation
  double seconds_refine = 0.0;  ///< inner solves of the border refinement
};

/// A contiguous range of beams [first, last] (scan indices, inclusive); in a closed MapScan,
/// first > last is the range across the seam, [first, n) then [0, last].
struct BeamRange {
  std::size_t first = 0;
  std::size_t last = 0;
};

/// The MAP scan. Per-beam vectors have one entry per beam of the input scan; beams outside
/// INMODEL keep their measured range and NaN normal.
///
/// Of a scan that covers a full turn (CoversFullTurn, EngineOptions::close_full_turn) the
/// in-model points form a ring, `closed`: `closing_link` relates the last in-model beam to the
/// first, and a region or surface across the seam is one BeamRange with first > last (from
/// `first` to the scan's end, on from its start to `last`), listed last. With no border at all
/// the one region is {inmodel_beams.front(), inmodel_beams.back()} and closing_link is
/// same_region (the whole ring).
struct MapScan {
  std::vector<double> rho;
  std::vector<double> alpha;  ///< sensor frame, towards the sensor, unwrapped along the scan
                              ///< (a turn apart across the seam of a closed one)
  std::vector<double> initial_alpha;  ///< the estimate the optimisation started from (NaN if none)
  /// Standard deviation of the weak prior on initial_alpha, rad (NaN if none).
  std::vector<double> initial_alpha_sigma;
  std::vector<double> alpha_lower, alpha_upper;  ///< bounds of the final solve (NaN if none)
  std::vector<std::uint8_t> inmodel;
  std::vector<std::size_t> inmodel_beams;  ///< the beams in INMODEL, in order
  std::vector<Link> links;                 ///< links[j] relates inmodel_beams[j] and [j + 1]
  /// The in-model points form a ring (a full-turn scan); then closing_link relates
  /// inmodel_beams.back() and inmodel_beams.front().
  bool closed = false;
  Link closing_link = Link::kSameRegion;  ///< meaningful when closed
  std::vector<BeamRange> regions;   ///< maximal runs joined by same_region links (first > last:
                                    ///< across the seam of a closed scan)
  std::vector<BeamRange> surfaces;  ///< maximal runs not split by different_surface links
  bool feasible = false;            ///< the prior's constraints hold at the solution
  double max_violation = 0.0;       ///< largest constraint residual at the solution (far
                                    ///< windows' relative, see feasibility_tolerance)
  double objective = 0.0;           ///< data + prior energies - gamma |INMODEL| (smaller is better)
  EngineStats stats;
};

/// Runs Algorithms 1 and 2 of the paper on the valid readings of `scan`.
/// Preconditions: scan.Problems() is empty; the scan is a laser's (rays from one origin, not
/// a sonar ring's cones); the prior has order >= 1; options.beta is in (0, 1).
[[nodiscard]] MapScan EstimateMapScan(const Scan& scan, const dsl::CompiledPrior& prior,
                                      const EngineOptions& options = {});

}  // namespace priormap::priorlets
