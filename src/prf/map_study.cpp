#include <algorithm>
#include <chrono>
#include <functional>
#include <iterator>
#include <span>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include <priormap/core/binary_io.hpp>
#include <priormap/core/check.hpp>
#include <priormap/core/rng.hpp>
#include <priormap/core/scene_truth.hpp>
#include <priormap/core/simulate.hpp>
#include <priormap/prf/map_study.hpp>
#include <priormap/prf/polygon_map.hpp>

#include "study_cases.hpp"

namespace priormap::prf {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

// The log-odds grid of exactly the PRF's beams, over its window at the evaluation resolution.
OccupancyRaster BuildGrid(const LaserData& data, const Window& window,
                          const MapStudyOptions& options) {
  grid::GridOptions grid_options = options.grid;
  grid_options.resolution = options.resolution;
  grid_options.max_range = data.max_range;
  grid::OccupancyGrid grid(Box2(window.min, window.max), grid_options);
  for (const LaserBeam& beam : data.beams)
    grid.InsertBeam(beam.origin, beam.origin + beam.range * beam.direction, !beam.max_reading);
  return grid.Raster();
}

}  // namespace

std::string StudyResolutionProblem(double resolution, double truth_resolution) {
  // Finer than any range sensor resolves; finer still, the scenes' rasters would not fit.
  if (resolution < kFinestStudyResolution || truth_resolution < kFinestStudyResolution)
    return fmt::format("the resolutions must be at least {} m (got {} and {})",
                       kFinestStudyResolution, resolution, truth_resolution);
  // Coarser, a room is a cell or two and the scores say nothing of the maps.
  if (resolution > kCoarsestStudyResolution || truth_resolution > kCoarsestStudyResolution)
    return fmt::format("the resolutions must be at most {} m (got {} and {})",
                       kCoarsestStudyResolution, resolution, truth_resolution);
  return {};
}

std::string MapStudyOptions::Problem() const {
  if (scenes.empty() || sensors.empty()) return "at least one scene and one sensor";
  for (const Scene& scene : scenes) {
    if (const auto problems = scene.Problems(); !problems.empty())
      return fmt::format("scene '{}': {}", scene.name, problems.front());
    if (scene.waypoints.size() < 2 && (poses > 1 || !scene.default_pose))
      return fmt::format("scene '{}' has no waypoint path for {} poses", scene.name, poses);
    // The poses come from the waypoints whenever there are two (and the truth is seeded by
    // them): they must make a path; else the waypoint and the default pose lie off the walls.
    if (scene.waypoints.size() >= 2) {
      if (std::string problem = WaypointPathProblem(scene); !problem.empty()) return problem;
    } else {
      if (std::string problem = PointOnASurface(scene, scene.waypoints); !problem.empty())
        return problem;
      if (scene.default_pose) {
        const Vec2 pose = scene.default_pose->translation();
        if (std::string problem = PointOnASurface(scene, std::span(&pose, 1)); !problem.empty())
          return problem + " (the default pose)";
      }
    }
  }
  if (const auto name = RepeatedName(scenes, [](const Scene& s) { return s.name; }))
    return fmt::format("scene '{}' is given twice (each case runs once)", *name);
  if (const auto name = RepeatedName(sensors, [](const RangeSensor& s) { return s.name; }))
    return fmt::format("sensor '{}' is given twice (each case runs once)", *name);
  for (const RangeSensor& sensor : sensors)
    if (std::string why; !sensor.IsValid(&why))
      return fmt::format("sensor '{}': {}", sensor.name, why);
  if (poses < 1) return "at least one pose per case";
  if (beam_step < 1) return "the beam step must be at least 1";
  if (!(max_range > 0.0 && resolution > 0.0 && band >= 0.0 && truth_resolution > 0.0))
    return "the max range and the resolutions must be positive and the band not negative";
  if (std::string problem = StudyResolutionProblem(resolution, truth_resolution); !problem.empty())
    return problem;
  if (!(walls.spacing > 0.0 && walls.tolerance >= 0.0))
    return "the wall spacing must be positive and the tolerance not negative";
  if (mapping.chains < 1) return "at least one chain";
  if (mapping.samples < 1) return "at least one sample per chain: P(black) is their mean";
  if (const std::string problem = mapping.model.Problem(); !problem.empty())
    return "laser model: " + problem;
  return {};
}

const MethodScores& MapStudyCase::Method(const std::string& name) const {
  for (const MethodScores& m : methods)
    if (m.method == name) return m;
  PRIORMAP_CHECK(false, "no method " + name + " in case " + Name());
  return methods.front();  // not reached
}

std::vector<Se2> StudyPoses(const Scene& scene, int count) {
  PRIORMAP_CHECK(count >= 1, "at least one pose");
  if (scene.waypoints.size() < 2) {
    PRIORMAP_CHECK(count == 1 && scene.default_pose, "a scene without a path gives one pose");
    return {*scene.default_pose};
  }
  double length = 0.0;
  for (std::size_t i = 0; i + 1 < scene.waypoints.size(); ++i)
    length += (scene.waypoints[i + 1] - scene.waypoints[i]).norm();
  // One pose per second at a speed that covers the path in `count` seconds.
  const std::vector<TimedPose> path = TrajectoryFromWaypoints(scene.waypoints, length / count, 1.0);
  std::vector<Se2> poses;
  for (int k = 0; k < count && k < static_cast<int>(path.size()); ++k)
    poses.push_back(path[static_cast<std::size_t>(k)].pose);
  return poses;
}

MapStudyCase RunMapStudyCase(const Scene& scene, const RangeSensor& sensor,
                             const MapStudyOptions& options, const MappingSession& session,
                             const std::function<void(const MappingProgress&)>& progress) {
  const auto start = Clock::now();
  MapStudyCase c;
  c.scene = scene.name;
  c.sensor = sensor.name;
  // From the case's name (FNV-1a), so that it is the same in any study that holds the case.
  c.seed = SplitMix64(options.seed ^ Fnv1a64(c.Name()));

  // The localized log: true poses, the sensor's own noise.
  c.poses = StudyPoses(scene, options.poses);
  std::vector<TimedPose> trajectory;
  for (std::size_t k = 0; k < c.poses.size(); ++k)
    trajectory.push_back({static_cast<double>(k), c.poses[k]});
  const Log log = SimulateLog(scene, sensor, trajectory, c.seed);
  LaserSelection selection;
  selection.beam_step = options.beam_step;
  selection.max_range = options.max_range;
  auto selected = SelectBeams(log, selection);
  PRIORMAP_CHECK(selected.ok(), "the simulated scans of " + c.Name() + " hold no usable reading");
  c.data = std::make_shared<const LaserData>(std::move(selected).value());

  // The truth, where it was observed, and which cells the beams reach.
  MappingOptions mapping = options.mapping;
  mapping.seed = SplitMix64(c.seed + 1);
  mapping.raster_resolution = options.resolution;
  const Window window = WindowAround(*c.data, mapping.margin);
  const CellGrid evaluation_grid = CellGrid::Covering(window.min, window.max, options.resolution);
  std::vector<Vec2> seeds = scene.waypoints;
  for (const Se2& pose : c.poses) seeds.push_back(pose.translation());
  const SceneTruth truth(scene, seeds,
                         {.resolution = options.truth_resolution,
                          .margin = std::max(0.1, 2.0 * options.truth_resolution)});
  std::vector<SensorView> views;
  for (const Se2& pose : c.poses)
    views.push_back({.pose = pose, .fov = sensor.fov, .max_range = c.data->max_range});
  const ObservedArea observed(scene, views, options.band);
  c.evaluation = MakeEvaluationRaster(evaluation_grid, truth, observed);
  MarkCoverage(*c.data, &c.evaluation);

  // Both maps from the same beams.
  const auto grid_start = Clock::now();
  c.grid_map = BuildGrid(*c.data, window, options);
  const double grid_seconds = Seconds(grid_start);
  c.prf = RunMapping(c.data, mapping, progress, session);
  if (!c.prf.complete) return c;  // stopped: nothing to score yet
  PRIORMAP_CHECK(c.prf.raster.nx == evaluation_grid.nx && c.prf.raster.ny == evaluation_grid.ny,
                 "the PRF's raster is the evaluation raster");

  c.methods.push_back(
      {"grid", ScoreClassification(SampleAtCentres(c.grid_map, evaluation_grid), c.evaluation),
       grid_seconds});
  c.methods.push_back(
      {"prf posterior",
       ScoreClassification(Flatten(c.prf.black_fraction, evaluation_grid), c.evaluation),
       c.prf.sampling_time_s});
  if (c.prf.map) {
    c.methods.push_back(
        {"prf map",
         ScoreClassification(Flatten(ColourRaster(*c.prf.map, evaluation_grid), evaluation_grid),
                             c.evaluation),
         c.prf.wall_time_s});
    std::vector<Segment> edges;
    for (const EdgeId e : c.prf.map->edge_ids()) edges.push_back(c.prf.map->EdgeSegment(e));
    const std::vector<Vec2> wall_points = VisibleWallPoints(scene, observed, options.walls.spacing);
    std::vector<Vec2> hits;
    for (const LaserBeam& beam : c.data->beams)
      if (!beam.max_reading) hits.push_back(beam.origin + beam.range * beam.direction);
    c.walls = ScoreWalls(edges, truth, observed, wall_points, options.walls, hits);
  }
  c.wall_time_s = Seconds(start);
  return c;
}

MapStudyResult RunMapStudy(const MapStudyOptions& options, const StudySession& session) {
  PRIORMAP_CHECK(options.Problem().empty(), options.Problem());
  const auto start = Clock::now();
  MapStudyResult result;
  const std::size_t sensors = options.sensors.size();
  const std::size_t cases = options.scenes.size() * sensors;
  result.cases.resize(cases);
  std::vector<StudyCaseName> names;
  for (std::size_t i = 0; i < cases; ++i) {
    // Named before the run: a case the session skips keeps its name (and an incomplete prf).
    MapStudyCase& c = result.cases[i];
    c.scene = options.scenes[i / sensors].name;
    c.sensor = options.sensors[i % sensors].name;
    c.prf.complete = false;
    names.push_back({c.scene, c.sensor});
  }
  StudyCases runner(session, std::move(names));
  result.complete = runner.Run([&](std::size_t i, const MappingSession& mapping,
                                   const std::function<void(const MappingProgress&)>& progress) {
    MapStudyCase& c = result.cases[i];
    c = RunMapStudyCase(options.scenes[i / sensors], options.sensors[i % sensors], options, mapping,
                        progress);
    return c.prf.complete;
  });
  for (const MapStudyCase& c : result.cases) {
    for (const MethodScores& m : c.methods) {
      auto it = std::find_if(result.overall.begin(), result.overall.end(),
                             [&](const MethodScores& o) { return o.method == m.method; });
      if (it == result.overall.end()) {
        result.overall.push_back({m.method, {}, 0.0});
        it = std::prev(result.overall.end());
      }
      it->classification.observed += m.classification.observed;
      it->classification.sparse += m.classification.sparse;
      it->classification.covered += m.classification.covered;
      it->seconds += m.seconds;
    }
  }
  result.wall_time_s = Seconds(start);
  return result;
}

}  // namespace priormap::prf
