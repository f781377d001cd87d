#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include <priormap/core/binary_io.hpp>
#include <priormap/core/check.hpp>
#include <priormap/core/rng.hpp>
#include <priormap/core/scene_truth.hpp>
#include <priormap/core/simulate.hpp>
#include <priormap/core/sonar_simulate.hpp>
#include <priormap/prf/point_buckets.hpp>
#include <priormap/prf/scene_coloring.hpp>
#include <priormap/prf/sonar_mapping.hpp>
#include <priormap/prf/sonar_observed_area.hpp>
#include <priormap/prf/sonar_study.hpp>

#include "study_cases.hpp"

namespace priormap::prf {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

// The seen part of each true wall (segment): its points with a ray's hit on it within `gap`.
std::vector<SeenWall> SeenWalls(const Scene& scene, const ConeWallHits& wall_hits, double spacing,
                                double gap) {
  std::vector<SeenWall> walls;
  for (const ScenePrimitive& primitive : scene.Primitives()) {
    const auto* segment = std::get_if<Segment>(&primitive.shape);
    if (segment == nullptr) continue;
    SeenWall wall;
    wall.length = segment->Length();
    const auto hits = wall_hits.find(primitive.region);
    if (hits != wall_hits.end()) {
      const PointBuckets near(hits->second, gap);
      const int n = std::max(1, static_cast<int>(std::ceil(wall.length / spacing)));
      for (int k = 0; k < n; ++k) {
        const Vec2 p = segment->PointAt((k + 0.5) / n);
        if (near.AnyWithin(p, gap)) wall.points.push_back(p);
      }
    }
    walls.push_back(std::move(wall));
  }
  return walls;
}

}  // namespace

std::string SonarStudyOptions::Problem() const {
  if (scenes.empty()) return "at least one scene";
  for (const Scene& scene : scenes) {
    if (const auto problems = scene.Problems(); !problems.empty())
      return fmt::format("scene '{}': {}", scene.name, problems.front());
    if (scene.waypoints.size() < 2)
      return fmt::format("scene '{}' has no waypoint path to drive the sonar along", scene.name);
    if (std::string problem = WaypointPathProblem(scene); !problem.empty()) return problem;
  }
  if (const auto name = RepeatedName(scenes, [](const Scene& s) { return s.name; }))
    return fmt::format("scene '{}' is given twice (each case runs once)", *name);
  if (std::string why; !sensor.IsValid(&why)) return "sonar: " + why;
  if (!(speed > 0.0 && rate > 0.0)) return "the speed and the ring rate must be positive";
  double readings = 0.0;
  for (const Scene& scene : scenes)
    readings += TrajectoryPoseCount(scene.waypoints, speed, rate) *
                static_cast<double>(sensor.bearings.size());
  // Refused before anything is simulated: a typo of the speed or the rate would exhaust memory,
  // or run chains for days; the paper's whole data set is 29,120 readings.
  if (!(readings <= kMaxSonarStudyReadings))
    return fmt::format(
        "the speed {} m/s and the ring rate {} per s make {:.3g} readings in the scenes, more "
        "than the {:.0e} a study takes: use a lower rate or a higher speed",
        speed, rate, readings, kMaxSonarStudyReadings);
  if (!(resolution > 0.0 && band >= 0.0 && truth_resolution > 0.0))
    return "the resolutions must be positive and the band not negative";
  if (std::string problem = StudyResolutionProblem(resolution, truth_resolution); !problem.empty())
    return problem;
  if (rays_per_cone < 2) return "at least two rays per cone";
  if (mapping.chains < 1) return "at least one chain";
  if (mapping.samples < 1) return "at least one sample per chain: P(black) is their mean";
  if (const std::string problem = model.Problem(); !problem.empty())
    return "sonar model: " + problem;
  return {};
}

const SonarStudyMethod& SonarStudyCase::Method(const std::string& name) const {
  for (const SonarStudyMethod& m : methods)
    if (m.method == name) return m;
  PRIORMAP_CHECK(false, "no method " + name + " in case " + scene);
  return methods.front();  // not reached
}

std::uint64_t SonarStudyCaseSeed(std::uint64_t study_seed, const std::string& scene,
                                 const std::string& sensor) {
  return SplitMix64(study_seed ^ Fnv1a64(scene + "/" + sensor));
}

SonarStudyCase RunSonarStudyCase(const Scene& scene, const SonarStudyOptions& options,
                                 const MappingSession& session,
                                 const std::function<void(const MappingProgress&)>& progress) {
  const auto start = Clock::now();
  SonarStudyCase c;
  c.scene = scene.name;
  c.seed = SonarStudyCaseSeed(options.seed, scene.name, options.sensor.name);

  const Log log = SimulateSonarLog(
      scene, options.sensor, TrajectoryFromWaypoints(scene.waypoints, options.speed, options.rate),
      c.seed);
  for (const Scan& ring : log.scans) c.ring_poses.push_back(ring.pose);
  SonarSelection selection;
  selection.max_range = options.sensor.max_range;
  auto selected = SelectSonarReadings(log, selection);
  PRIORMAP_CHECK(selected.ok(), "the simulated rings of " + scene.name + " hold no usable reading");
  auto data = std::make_shared<const SonarData>(std::move(selected).value());
  c.readings = data->readings.size();
  c.max_readings =
      static_cast<std::size_t>(std::count_if(data->readings.begin(), data->readings.end(),
                                             [](const SonarReading& r) { return r.max_reading; }));

  MappingOptions mapping = options.mapping;
  mapping.seed = SplitMix64(c.seed + 1);
  mapping.raster_resolution = options.resolution;
  MappingData mapping_data = SonarMappingData(data, options.model, mapping);
  const Window& window = mapping_data.window;
  const CellGrid evaluation_grid = CellGrid::Covering(window.min, window.max, options.resolution);

  // The truth and what the cones could see.
  std::vector<Vec2> seeds = scene.waypoints;
  for (const Se2& pose : c.ring_poses) seeds.push_back(pose.translation());
  const SceneTruth truth(scene, seeds,
                         {.resolution = options.truth_resolution,
                          .margin = std::max(0.1, 2.0 * options.truth_resolution)});
  auto true_map = SceneColoring(scene, truth, window, mapping.cell_size);
  if (auto* map = std::get_if<Coloring>(&true_map)) {
    const PrfSampler at_truth(*map, mapping.sampler, 0, mapping_data.make_data_term());
    c.truth_log_posterior = at_truth.LogPosterior();
    c.truth_log_likelihood = at_truth.LogLikelihood();
    if (options.start_at_truth) mapping_data.start = std::move(*map);
  } else {
    PRIORMAP_CHECK(!options.start_at_truth, "scene " + scene.name + " has no true coloring: " +
                                                std::get<std::string>(true_map));
  }
  ConeWallHits wall_hits;
  c.evaluation = MakeSonarEvaluationRaster(
      evaluation_grid, truth, scene, *data,
      {.rays_per_cone = options.rays_per_cone,
       .band = options.band,
       // The study's published scores were marked every half of the nominal resolution.
       .mark_step = 0.5 * options.resolution},
      &wall_hits);
  // Neighbouring rays of a fan are at most this far apart on a wall within R.
  const double gap = options.sensor.max_range * 2.0 * data->readings.front().cone.half_spread /
                         (options.rays_per_cone - 1) +
                     options.walls.spacing;
  const std::vector<SeenWall> walls = SeenWalls(scene, wall_hits, options.walls.spacing, gap);

  // Both maps from the same readings.
  const auto grid_start = Clock::now();
  grid::SonarGridOptions grid_options = options.grid;
  grid_options.resolution = options.resolution;
  grid_options.max_range = data->max_range;
  grid::SonarGrid sonar_grid(Box2(window.min, window.max), grid_options);
  for (const Scan& ring : log.scans) sonar_grid.Insert(ring);
  c.grid_map = sonar_grid.Raster();
  const double grid_seconds = Seconds(grid_start);
  c.prf = RunMapping(mapping_data, mapping, progress, session);
  if (!c.prf.complete) return c;  // stopped: nothing to score yet
  PRIORMAP_CHECK(c.prf.raster.nx == evaluation_grid.nx && c.prf.raster.ny == evaluation_grid.ny,
                 "the PRF's raster is the evaluation raster");

  const std::vector<double> grid_p = SampleAtCentres(c.grid_map, evaluation_grid);
  const std::vector<double> prf_p = Flatten(c.prf.black_fraction, evaluation_grid);
  for (const auto& [name, p, seconds] :
       {std::tuple{"grid", &grid_p, grid_seconds},
        std::tuple{"prf posterior", &prf_p, c.prf.sampling_time_s}}) {
    const std::vector<Segment> contour = HalfContour(*p, evaluation_grid);
    c.methods.push_back({.method = name,
                         .classification = ScoreClassification(*p, c.evaluation),
                         .walls = ScoreContour(contour, walls, c.evaluation, truth, options.walls),
                         .seconds = seconds});
  }
  c.wall_time_s = Seconds(start);
  return c;
}

SonarStudyResult RunSonarStudy(const SonarStudyOptions& options, const StudySession& session) {
  PRIORMAP_CHECK(options.Problem().empty(), options.Problem());
  const auto start = Clock::now();
  SonarStudyResult result;
  result.cases.resize(options.scenes.size());
  std::vector<StudyCaseName> names;
  for (std::size_t k = 0; k < options.scenes.size(); ++k) {
    // Named before the run: a case the session skips keeps its name (and an incomplete prf).
    result.cases[k].scene = options.scenes[k].name;
    result.cases[k].prf.complete = false;
    names.push_back({options.scenes[k].name, options.sensor.name});
  }
  StudyCases runner(session, std::move(names));
  result.complete = runner.Run([&](std::size_t k, const MappingSession& mapping,
                                   const std::function<void(const MappingProgress&)>& progress) {
    SonarStudyCase& c = result.cases[k];
    c = RunSonarStudyCase(options.scenes[k], options, mapping, progress);
    return c.prf.complete;
  });
  result.wall_time_s = Seconds(start);
  return result;
}

}  // namespace priormap::prf
