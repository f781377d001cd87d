#pragma once
/// The accuracy study of PRF maps against occupancy grids at equal data (issue 6; Paskin &
/// Thrun, Sec. 3): for each scene and sensor, a localized log of a few scans simulated along the
/// scene's waypoints, the grid and the PRF (posterior chains, then annealing to a MAP map) built
/// from exactly the same beams, and both scored against the scene's ground truth over the
/// observed area and its sparse part; the MAP map's edges against the true walls.
///
/// A case is a pure function of its scene, sensor, options and the study seed (its own seed is
/// derived from the seed and its name), so cases run in parallel (oneTBB) and a case gives the
/// same numbers alone or in any study.
///
/// The truth and the scores know no sensor model: the sonar comparison (sonar_study.hpp) plugs in
/// at the same seams, with the observed area and coverage of its cones
/// (MakeSonarEvaluationRaster), its grid's raster through SampleAtCentres and its MappingData
/// through RunMapping.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <priormap/core/map_server.hpp>
#include <priormap/core/range_sensor.hpp>
#include <priormap/core/scene.hpp>
#include <priormap/grid/occupancy_grid.hpp>
#include <priormap/prf/map_scores.hpp>
#include <priormap/prf/mapping.hpp>
#include <priormap/prf/study_session.hpp>

namespace priormap::prf {

/// The finest and the coarsest evaluation or truth raster the studies take, m.
inline constexpr double kFinestStudyResolution = 0.005;
inline constexpr double kCoarsestStudyResolution = 1.0;
/// Empty when both resolutions are within [kFinestStudyResolution, kCoarsestStudyResolution],
/// else what is wrong.
[[nodiscard]] std::string StudyResolutionProblem(double resolution, double truth_resolution);

/// The first name that two items share, if any (a study would run that case twice and count it
/// twice in its totals).
template <typename T, typename Name>
[[nodiscard]] std::optional<std::string> RepeatedName(const std::vector<T>& items, Name name) {
  for (std::size_t i = 0; i < items.size(); ++i)
    for (std::size_t j = i + 1; j < items.size(); ++j)
      if (name(items[i]) == name(items[j])) return name(items[i]);
  return std::nullopt;
}

struct MapStudyOptions {
  std::vector<Scene> scenes;         ///< each with a waypoint path (or a default pose)
  std::vector<RangeSensor> sensors;  ///< each scene is simulated with each sensor
  int poses = 3;                     ///< scans per case, evenly spaced along the waypoint path
  std::size_t beam_step = 1;         ///< every k-th beam of each scan, for both methods
  double max_range = 20.0;           ///< R (capped by the sensor's own), m
  double resolution = 0.05;          ///< evaluation raster, grid cells and PRF raster, m
  double band = 0.1;                 ///< depth behind a seen surface that counts as observed, m
  double truth_resolution = 0.01;    ///< raster of the ground truth's reachability, m
  WallScoreOptions walls;
  /// The PRF run; its seed and raster resolution are set per case, annealing is on when
  /// anneal_steps > 0.
  MappingOptions mapping;
  /// The grid's log-odds; its resolution and insertion range are set from the above.
  grid::GridOptions grid;
  std::uint64_t seed = 1;

  /// Empty when usable, else what is wrong (scenes, sensors, counts, lengths).
  [[nodiscard]] std::string Problem() const;
};

/// One mapping method's result on one case.
struct MethodScores {
  std::string method;  ///< "grid", "prf posterior", "prf map"
  MapClassification classification;
  double seconds = 0.0;  ///< building the map (the MAP map: annealing included in the PRF's)
};

struct MapStudyCase {
  std::string scene;
  std::string sensor;
  std::uint64_t seed = 0;  ///< of the simulation; the PRF's is derived from it
  std::vector<Se2> poses;
  std::shared_ptr<const LaserData> data;
  EvaluationRaster evaluation;
  OccupancyRaster grid_map;  ///< P(occupied), NaN where never observed
  MappingResult prf;         ///< posterior rasters on evaluation.grid, the MAP coloring
  std::vector<MethodScores> methods;
  WallScore walls;  ///< of the MAP map
  double wall_time_s = 0.0;

  [[nodiscard]] std::string Name() const { return scene + "/" + sensor; }
  [[nodiscard]] const MethodScores& Method(const std::string& name) const;
};

struct MapStudyResult {
  /// Scenes outer, sensors inner. A case the session stopped has its name only, or its data
  /// and truth with an incomplete `prf` (prf.complete false), and no scores.
  std::vector<MapStudyCase> cases;
  /// Per method, the counts of all cases pooled and their times summed.
  std::vector<MethodScores> overall;
  double wall_time_s = 0.0;
  /// False when the session stopped the study before every case was scored (`overall` then
  /// pools the scored cases only).
  bool complete = true;
};

/// The case of one scene and sensor; its chains run in `session` and report to `progress`.
/// Precondition: options.Problem() is empty.
[[nodiscard]] MapStudyCase RunMapStudyCase(
    const Scene& scene, const RangeSensor& sensor, const MapStudyOptions& options,
    const MappingSession& session = {},
    const std::function<void(const MappingProgress&)>& progress = {});

/// Every scene × sensor case, in parallel. Precondition: options.Problem() is empty. Throws
/// BinaryFormatError when resuming from a damaged checkpoint or one of another study.
[[nodiscard]] MapStudyResult RunMapStudy(const MapStudyOptions& options,
                                         const StudySession& session = {});

/// `count` poses spaced evenly by arc length along the scene's waypoint path from its start,
/// heading along it; the default pose when the scene has fewer than two waypoints (count 1).
[[nodiscard]] std::vector<Se2> StudyPoses(const Scene& scene, int count);

}  // namespace priormap::prf
