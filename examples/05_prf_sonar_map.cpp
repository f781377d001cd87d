// Map a simulated sonar log with a polygonal random field (Paskin & Thrun) and compare it with
// the sonar occupancy grid built from the same readings, both scored against the true scene.
//   example_05_prf_sonar_map [scene] [steps] [out.png]   (steps: burn-in, and as many samples;
//   the figure may be .svg or .pdf too)
#include <charconv>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include <priormap/core/scene_truth.hpp>
#include <priormap/core/sonar_simulate.hpp>
#include <priormap/grid/sonar_grid.hpp>
#include <priormap/prf/map_scores.hpp>
#include <priormap/prf/sonar_mapping.hpp>
#include <priormap/prf/sonar_observed_area.hpp>
#include <priormap/render/prf_figures.hpp>

namespace prf = priormap::prf;

namespace {

// The whole argument as a step count from 1 to 2^40 (the bound of `priormap prf --samples`), or
// nothing: "abc", "1e4" or "-5" is refused rather than read as 0 or as 2^64 - 5 steps.
std::optional<std::uint64_t> ParseSteps(std::string_view text) {
  std::uint64_t value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size()) return std::nullopt;
  if (value < 1 || value > (std::uint64_t{1} << 40)) return std::nullopt;
  return value;
}

// The figure is written after the run: a name it cannot be written to is refused before it
// (Figure::Save takes .png, .svg or .pdf, into a directory that exists).
bool CanWriteFigure(const std::filesystem::path& path) {
  const std::filesystem::path extension = path.extension();
  const std::filesystem::path directory = path.has_parent_path() ? path.parent_path() : ".";
  return (extension == ".png" || extension == ".svg" || extension == ".pdf") &&
         std::filesystem::is_directory(directory);
}

}  // namespace

// What the library cannot do throws: say what, and exit 1.
int main(int argc, char** argv) try {
  const std::string scene_name = argc > 1 ? argv[1] : "l-room";
  const std::optional<std::uint64_t> steps = argc > 2 ? ParseSteps(argv[2]) : 40000;
  const std::string figure_path = argc > 3 ? argv[3] : "prf-sonar-posterior.png";
  const std::optional<priormap::Scene> scene = priormap::BuiltinScene(scene_name);
  if (!scene || !steps || argc > 4 || !CanWriteFigure(figure_path)) {
    std::fprintf(stderr, "usage: %s [scene] [steps: 1 to 2^40] [out.png|.svg|.pdf]\n", argv[0]);
    std::string known;
    for (const std::string& name : priormap::BuiltinSceneNames()) known += " " + name;
    if (!scene)
      std::fprintf(stderr, "unknown scene %s (built-in:%s)\n", scene_name.c_str(), known.c_str());
    if (!steps)
      std::fprintf(stderr, "steps: expected a whole number from 1 to 2^40, got %s\n", argv[2]);
    if (!CanWriteFigure(figure_path))
      std::fprintf(stderr,
                   "%s: cannot write the figure there (a .png, .svg or .pdf in a directory that "
                   "exists)\n",
                   figure_path.c_str());
    return 2;
  }

  // A pioneer16 ring driven along the scene's waypoints at 0.5 m/s, two rings a second.
  const priormap::SonarSensor sensor = *priormap::SonarSensor::Preset("pioneer16");
  const priormap::Log log = priormap::SimulateSonarLog(
      *scene, sensor, priormap::TrajectoryFromWaypoints(scene->waypoints, 0.5, 2.0), /*seed=*/1);
  prf::SonarSelection selection;
  selection.max_range = sensor.max_range;
  auto selected = prf::SelectSonarReadings(log, selection);
  if (!selected) {
    std::fprintf(stderr, "%s\n", selected.error().c_str());
    return 1;
  }
  const auto data = std::make_shared<const prf::SonarData>(std::move(selected).value());

  prf::MappingOptions options;
  options.burn_in = *steps;
  options.samples = *steps;
  options.seed = 1;
  options.raster_resolution = 0.05;
  // Sec. 4's preferences for free space and for walls along the building's axes: with so few
  // steps, they keep the chains from spending them on black wedges the sonar cannot rule out.
  options.sampler.free_space = 1.0;
  options.sampler.orientation.weight = 1.0;
  const prf::MappingData mapping = prf::SonarMappingData(data, prf::SonarModel{}, options);
  const prf::MappingResult posterior = prf::RunMapping(mapping, options, {});

  // The baseline: each cone free up to its reading, its arc occupied (Elfes 1989).
  priormap::grid::SonarGrid grid(priormap::Box2(mapping.window.min, mapping.window.max),
                                 {.resolution = 0.05, .max_range = data->max_range});
  for (const priormap::Scan& ring : log.scans) grid.Insert(ring);

  // Score both at the cells of the PRF's raster that some cone could see (geometrically: a fan
  // of rays across each cone, to the first true wall), against the scene's true free space, as
  // `priormap prf sonar-study` does. The gaps between a ring's cones are not scored: no reading
  // could tell anything there.
  std::vector<priormap::Vec2> positions;
  for (const priormap::Scan& ring : log.scans) positions.push_back(ring.pose.translation());
  const priormap::SceneTruth truth(*scene, positions);
  const prf::EvaluationRaster evaluation =
      prf::MakeSonarEvaluationRaster(posterior.raster, truth, *scene, *data);
  const prf::ClassificationScore prf_score =
      prf::ScoreClassification(prf::Flatten(posterior.black_fraction, posterior.raster), evaluation)
          .observed;
  const prf::ClassificationScore grid_score =
      prf::ScoreClassification(prf::SampleAtCentres(grid.Raster(), posterior.raster), evaluation)
          .observed;

  // An R-hat well above 1.1 says the chains have not mixed: a run of seconds shows the map, not
  // a converged posterior (docs/prf.md runs minutes).
  std::printf("%s: %zu rings, %zu readings; %d chains x %llu steps in %.1f s (R-hat %.2f)\n",
              scene_name.c_str(), log.scans.size(), data->readings.size(), options.chains,
              static_cast<unsigned long long>(options.burn_in + options.samples),
              posterior.wall_time_s, posterior.rhat_log_posterior);
  std::printf("classification of %zu observed cells: PRF %.1f %%, sonar grid %.1f %%\n",
              prf_score.points, 100.0 * prf_score.Accuracy(), 100.0 * grid_score.Accuracy());
  priormap::render::SaveProbabilityFigure(
      figure_path, prf::SquareCellRaster(posterior.black_fraction, posterior.raster),
      scene_name + ": PRF posterior P(occupied) from sonar", positions);
  std::printf("wrote %s\n", figure_path.c_str());

  // What the example claims: the polygonal prior turns the same ambiguous readings into a
  // better map than the grid's.
  const bool ok = prf_score.Accuracy() > grid_score.Accuracy();
  if (!ok) std::fprintf(stderr, "unexpected result: see the numbers above\n");
  return ok ? 0 : 1;
} catch (const std::exception& e) {
  std::fprintf(stderr, "error: %s\n", e.what());
  return 1;
}
