#pragma once
/// The sonar comparison of issue 7 (Paskin & Thrun, Sec. 3, Fig. 5): for each scene, a sonar
/// ring driven along the scene's waypoints, the sonar occupancy grid and the PRF posterior
/// built from exactly the same readings, both scored against the ground truth over the area
/// the cones could see: classification (map_scores.hpp), walls missed and boundary sharpness
/// of their 0.5 contours (contour_scores.hpp).
///
/// The observed area is geometric (MakeSonarEvaluationRaster, sonar_observed_area.hpp): a fan
/// of rays across each cone, each followed to the first
/// true surface within R, marks the cells it crosses as visible and the `band` behind that
/// surface as behind it; the cells a reading says something about (inside its cone up to the
/// reading, or R) are its covered cells. A case is a pure function of its scene, the options
/// and the study seed; cases run in parallel.

#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <priormap/core/map_server.hpp>
#include <priormap/core/scene.hpp>
#include <priormap/core/sonar_sensor.hpp>
#include <priormap/grid/sonar_grid.hpp>
#include <priormap/prf/contour_scores.hpp>
#include <priormap/prf/map_study.hpp>
#include <priormap/prf/mapping.hpp>
#include <priormap/prf/sonar_data.hpp>
#include <priormap/prf/sonar_model.hpp>
#include <priormap/prf/study_session.hpp>

namespace priormap::prf {

/// The most readings a sonar study simulates over its scenes (SonarStudyOptions::Problem).
inline constexpr double kMaxSonarStudyReadings = 1e6;

struct SonarStudyOptions {
  std::vector<Scene> scenes;  ///< each with a waypoint path
  SonarSensor sensor = *SonarSensor::Preset("pioneer16");
  double speed = 0.5;        ///< m/s along the waypoints
  double rate = 2.0;         ///< rings per second
  double resolution = 0.05;  ///< evaluation raster, grid cells and PRF raster, m
  double band = 0.1;         ///< depth behind a seen surface that counts as observed, m
  double truth_resolution = 0.01;
  int rays_per_cone = 21;  ///< of the fan that finds what each cone could see
  ContourWallOptions walls;
  SonarModel model;
  MappingOptions mapping;  ///< seed and raster resolution are set per case
  grid::SonarGridOptions grid;
  std::uint64_t seed = 1;
  /// Diagnostic: start every chain at the true map (SceneColoring) instead of the empty one,
  /// which shows what the posterior itself gives, apart from how fast the chains find it.
  bool start_at_truth = false;

  /// Empty when usable, else what is wrong.
  [[nodiscard]] std::string Problem() const;
};

struct SonarStudyMethod {
  std::string method;  ///< "grid", "prf posterior"
  MapClassification classification;
  ContourWallScore walls;
  double seconds = 0.0;
};

struct SonarStudyCase {
  std::string scene;
  std::uint64_t seed = 0;
  std::size_t readings = 0;
  std::size_t max_readings = 0;
  std::vector<Se2> ring_poses;
  EvaluationRaster evaluation;
  OccupancyRaster grid_map;  ///< P(occupied), NaN where never observed
  MappingResult prf;
  /// log-posterior (Arak prior + sonar likelihood) of the true map, when the scene is made of
  /// closed polylines (NaN otherwise); against the chains', it tells a model that prefers
  /// another map from chains that have not found this one.
  double truth_log_posterior = std::numeric_limits<double>::quiet_NaN();
  /// Its likelihood part, to set against the chains' (ChainSummary::log_likelihood).
  double truth_log_likelihood = std::numeric_limits<double>::quiet_NaN();
  std::vector<SonarStudyMethod> methods;
  double wall_time_s = 0.0;

  [[nodiscard]] const SonarStudyMethod& Method(const std::string& name) const;
};

struct SonarStudyResult {
  /// A case the session stopped has its name only, or an incomplete `prf` (prf.complete false),
  /// and no scores.
  std::vector<SonarStudyCase> cases;
  double wall_time_s = 0.0;
  /// False when the session stopped the study before every case was scored.
  bool complete = true;
};

/// The seed of a case's rings, from the study seed and the case's name (scene and sensor), so
/// that a case gives the same rings in any study; `prf fit-sonar --seed S` simulates the rings
/// `sonar-study --seed S` would score.
[[nodiscard]] std::uint64_t SonarStudyCaseSeed(std::uint64_t study_seed, const std::string& scene,
                                               const std::string& sensor);

/// The case of one scene; its chains run in `session` and report to `progress`. Precondition:
/// options.Problem() is empty.
[[nodiscard]] SonarStudyCase RunSonarStudyCase(
    const Scene& scene, const SonarStudyOptions& options, const MappingSession& session = {},
    const std::function<void(const MappingProgress&)>& progress = {});
/// Every case, in parallel. Precondition: options.Problem() is empty. Throws BinaryFormatError
/// when resuming from a damaged checkpoint or one of another study.
[[nodiscard]] SonarStudyResult RunSonarStudy(const SonarStudyOptions& options,
                                             const StudySession& session = {});

/// summary.json and a Markdown table of a study.
[[nodiscard]] std::string SonarStudySummaryJson(const SonarStudyResult& study,
                                                const SonarStudyOptions& options);
[[nodiscard]] std::string SonarStudyMarkdownTable(const SonarStudyResult& study);

}  // namespace priormap::prf
