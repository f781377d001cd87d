// Uses the installed headers and libraries, one call into each module: simulate a scan, write it
// as JSON and draw it (core, render); correct it under a built-in prior (dsl, priorlets); grid it
// (grid); select its beams for a polygonal random field (prf); filter the simulated city with its
// prior map (slam).
#include <cstdio>
#include <string>

#include <priormap/core/json_io.hpp>
#include <priormap/core/simulate.hpp>
#include <priormap/dsl/prior_library.hpp>
#include <priormap/grid/occupancy_grid.hpp>
#include <priormap/prf/laser_data.hpp>
#include <priormap/priorlets/engine.hpp>
#include <priormap/render/scene_drawing.hpp>
#include <priormap/slam/prior_map_slam.hpp>
#include <priormap/slam/urban_scenario.hpp>

int main(int argc, char** argv) {
  const std::string out = argc > 1 ? argv[1] : ".";
  const priormap::Scene scene = *priormap::BuiltinScene("square");
  priormap::Rng rng(1);
  const priormap::Scan scan =
      priormap::SimulateScan(priormap::SceneRayCaster(scene),
                             *priormap::RangeSensor::Preset("lms200"), *scene.default_pose, rng);
  priormap::WriteJsonScan(scan, out + "/consumer-scan.json");
  priormap::render::Figure figure(scene.Bounds());
  priormap::render::DrawScene(figure, scene);
  priormap::render::DrawScan(figure, scan);
  figure.Save(out + "/consumer-scan.png");
  std::printf("consumer: %zu beams, %zu valid\n", scan.size(), scan.NumValid());

  // The built-in priors are compiled into the installed library.
  const auto prior = priormap::dsl::PriorLibrary::WithEnvironment({}).Load("rectangular");
  if (!prior) {
    std::fprintf(stderr, "%s\n", prior.error().c_str());
    return 1;
  }
  const priormap::priorlets::MapScan map =
      priormap::priorlets::EstimateMapScan(scan, prior.value());
  std::printf("consumer: %s, %zu regions, %s\n", prior.value().name().c_str(), map.regions.size(),
              map.feasible ? "feasible" : "infeasible");

  priormap::Log log;
  log.scans.push_back(scan);
  const priormap::grid::GridOptions grid_options;
  priormap::grid::OccupancyGrid grid(
      priormap::grid::OccupancyGrid::ExtentOf(log, 0, log.scans.size(), grid_options),
      grid_options);
  grid.Insert(scan);
  const auto beams = priormap::prf::SelectBeams(log, {});
  if (!beams) {
    std::fprintf(stderr, "%s\n", beams.error().c_str());
    return 1;
  }
  std::printf("consumer: grid %ld x %ld cells, %zu beams for the PRF\n",
              static_cast<long>(grid.Raster().probability.rows()),
              static_cast<long>(grid.Raster().probability.cols()), beams.value().beams.size());

  const priormap::slam::UrbanScenarioOptions scenario;
  const priormap::slam::UrbanWorld world = priormap::slam::MakeUrbanWorld(scenario, 1);
  const priormap::slam::UrbanRun run = priormap::slam::SimulateUrbanRun(world, scenario, 1, 0);
  const priormap::slam::SlamResult result = priormap::slam::RunSlam(run.input, &run.prior_map, {});
  std::printf("consumer: slam over %zu frames, %zu relations\n", result.frames.size(),
              result.relations.size());
  return scan.NumValid() > 0 && map.feasible && !result.frames.empty() ? 0 : 1;
}
