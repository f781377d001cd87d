// priormap prf sonar-study: the PRF posterior against the sonar occupancy grid on simulated sonar
// logs of scenes with rooms and doors (issue 7; docs/prf.md).
#include <array>
#include <filesystem>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <system_error>
#include <vector>

#include <fmt/format.h>

#include <priormap/core/file_io.hpp>
#include <priormap/prf/map_study_io.hpp>
#include <priormap/prf/sonar_model_io.hpp>
#include <priormap/prf/sonar_study.hpp>
#include <priormap/render/prf_figures.hpp>
#include <priormap/render/prf_study_figures.hpp>

#include "chain_states.hpp"
#include "cli_support.hpp"
#include "commands.hpp"
#include "prf_posterior_options.hpp"
#include "study_session_cli.hpp"

namespace priormap::app {
namespace {

struct SonarStudyCliOptions {
  std::vector<std::string> scenes{"office", "l-office"};
  std::string sensor = "pioneer16";
  std::optional<double> max_range;
  std::string sonar_model;
  PosteriorCliOptions posterior;
  std::string out;
  bool figures = true;
  prf::SonarStudyOptions study;
  StudySessionCliOptions session;
};

// Every figure a case may have, which a new run removes first.
constexpr std::array<const char*, 5> kCaseFigures = {"truth.png", "grid.png", "posterior.png",
                                                     "grid-errors.png", "posterior-errors.png"};

void SaveCaseFigures(const std::filesystem::path& dir, const prf::SonarStudyCase& c,
                     const std::string& sensor) {
  EnsureDirectory(dir.string());
  std::vector<Se2> poses;
  std::vector<Vec2> sensors;
  // Every tenth ring's pose: enough to show the path without hiding the map.
  for (std::size_t k = 0; k < c.ring_poses.size(); k += 10) {
    poses.push_back(c.ring_poses[k]);
    sensors.push_back(c.ring_poses[k].translation());
  }
  const std::string name = fmt::format("{}/{}", c.scene, sensor);
  const std::string readings = fmt::format("{} readings", c.readings);
  render::SaveTruthFigure(dir / "truth.png", c.evaluation, poses,
                          fmt::format("{}: truth over what the cones could see", name));
  render::SaveProbabilityFigure(dir / "grid.png", c.grid_map,
                                fmt::format("{}: sonar occupancy grid, {}", name, readings),
                                sensors);
  const prf::CellGrid& raster = c.prf.raster;
  render::SaveProbabilityFigure(
      dir / "posterior.png", prf::SquareCellRaster(c.prf.black_fraction, raster),
      fmt::format("{}: PRF posterior P(black), {}", name, readings), sensors);
  const std::vector<double> grid_p = prf::SampleAtCentres(c.grid_map, c.evaluation.grid);
  const std::vector<double> prf_p = prf::Flatten(c.prf.black_fraction, c.evaluation.grid);
  render::SaveErrorFigure(dir / "grid-errors.png", c.evaluation, grid_p,
                          fmt::format("{}: where the sonar grid is wrong", name));
  render::SaveErrorFigure(dir / "posterior-errors.png", c.evaluation, prf_p,
                          fmt::format("{}: where the PRF posterior is wrong", name));
}

// Each chain's last state, after an earlier study's are removed (it may have had more chains).
void SaveChainStates(const std::filesystem::path& dir, const prf::SonarStudyCase& c) {
  std::error_code ec;  // unremovable: the writes below fail there too, and say so
  for (const auto& earlier : NumberedFiles(dir, "chain", "_last.geojson"))
    std::filesystem::remove(earlier, ec);
  EnsureDirectory(dir);
  for (std::size_t k = 0; k < c.prf.chains.size(); ++k)
    if (c.prf.chains[k].last) SaveChainState(dir, k, *c.prf.chains[k].last, c.prf.window);
}

void RunSonarStudyCommand(SonarStudyCliOptions o) {
  if (o.out.empty()) throw UsageError("-o/--out is required");
  RefuseRepeatedEntries(o.scenes, "--scenes", "scene");
  for (const std::string& name : o.scenes) o.study.scenes.push_back(LoadScene(name, "--scenes"));
  const auto sensor = SonarSensor::Preset(o.sensor);
  if (!sensor)
    throw UserError(fmt::format("--sensor: unknown sonar '{}' (expected one of: {})", o.sensor,
                                fmt::join(SonarSensor::PresetNames(), ", ")));
  o.study.sensor = *sensor;
  if (o.max_range) o.study.sensor.max_range = *o.max_range;
  ApplyPosteriorOptions(o.posterior, &o.study.mapping);
  if (!o.sonar_model.empty()) o.study.model = ValueOrThrow(prf::ReadSonarModel(o.sonar_model));
  if (const std::string problem = o.study.Problem(); !problem.empty()) throw UserError(problem);
  const std::filesystem::path dir(o.out);
  std::vector<std::string> folders;
  for (const Scene& scene : o.study.scenes)
    folders.push_back(prf::StudyCaseFolder(scene.name, o.study.sensor.name));
  const DirectoryLock lock =
      BeginStudy(dir, folders, prf::SonarStudyOptionsJson(o.study), o.session.resume);

  const std::optional<prf::SonarStudyResult> ended = RunStoppableStudy(
      dir, folders, o.session,
      [&](const prf::StudySession& session) { return prf::RunSonarStudy(o.study, session); });
  if (!ended) return;
  const prf::SonarStudyResult& result = *ended;

  const std::string table = prf::SonarStudyMarkdownTable(result);
  FinishStudy(dir, folders, [&] {
    WriteTextFileAtomically(dir / "summary.json", prf::SonarStudySummaryJson(result, o.study));
    WriteTextFileAtomically(dir / "table.md", table);
    for (std::size_t i = 0; i < result.cases.size(); ++i) {
      const std::filesystem::path case_dir = dir / folders[i];
      RemoveFiles(case_dir, kCaseFigures);  // an earlier run's, beside this run's numbers
      if (o.figures) SaveCaseFigures(case_dir, result.cases[i], o.study.sensor.name);
      SaveChainStates(case_dir, result.cases[i]);
    }
  });
  fmt::print(
      "{}\nwrote {} (summary.json, table.md, <scene>-<sensor>/chainK_last.geojson{}) in {:.0f} s\n",
      table, o.out,
      o.figures ? ", <scene>-<sensor>/{truth,grid,posterior,grid-errors,posterior-errors}.png" : "",
      result.wall_time_s);
}

}  // namespace

void AddPrfSonarStudyCommand(CLI::App& prf_cmd) {
  auto o = std::make_shared<SonarStudyCliOptions>();
  prf::SonarStudyOptions& s = o->study;
  prf::MappingOptions& m = s.mapping;
  m.samples = 300000;
  m.burn_in = 300000;
  m.chains = 2;
  CLI::App* cmd = prf_cmd.add_subcommand(
      "sonar-study",
      "PRF posterior vs the sonar occupancy grid on simulated sonar logs with ground truth: "
      "classification over what the cones could see, walls missed, distance of the 0.5 contour "
      "to the true walls");
  cmd->add_option("--scenes", o->scenes, "Scenes with a waypoint path (built-in names or files)")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--sensor", o->sensor, "Sonar ring preset")
      ->check(SonarPresetName())
      ->capture_default_str();
  cmd->add_option("--speed", s.speed, "Robot speed along the waypoints, m/s")
      ->check(PositiveValueUpTo(100.0, "m/s"))
      ->capture_default_str();
  cmd->add_option("--rate", s.rate, "Rings per second")
      ->check(PositiveValue())
      ->capture_default_str();
  cmd->add_option("--max-range", o->max_range, "R of the sonar, m (default: the preset's)")
      ->check(PositiveValueUpTo(100.0, "m"));
  cmd->add_option("--resolution", s.resolution,
                  "Cell of the evaluation raster, the grid and the PRF raster, m")
      ->check(PositiveValue())
      ->check(StudyResolution())
      ->capture_default_str();
  cmd->add_option("--p", m.sampler.p, "Scale parameter p of the Arak prior (1/m)")
      ->check(PositiveValue())
      ->capture_default_str();
  AddPosteriorOptions(*cmd, m, o->posterior);
  cmd->add_option("--samples", m.samples, "PRF steps recorded per chain after the burn-in")
      ->transform(StepCount())
      ->check(StudySamples())
      ->capture_default_str();
  cmd->add_option("--burn-in", m.burn_in, "PRF steps per chain before recording")
      ->transform(StepCount())
      ->capture_default_str();
  cmd->add_option("--chains", m.chains, "PRF chains per case")
      ->check(CLI::Range(1, 256))
      ->capture_default_str();
  cmd->add_option("--wall-tolerance", s.walls.tolerance,
                  "A seen true wall point is recovered with the 0.5 contour this close, m")
      ->check(PositiveValue())
      ->capture_default_str();
  cmd->add_option("--seed", s.seed, "Random seed; the same seed gives the same result")
      ->transform(SeedValue())
      ->capture_default_str();
  cmd->add_option("--sonar-model", o->sonar_model,
                  "Sonar model file (priormap.sonar_model JSON); default: the built-in parameters");
  cmd->add_flag("--start-at-truth", s.start_at_truth,
                "Diagnostic: start the chains at the true map, to see what the posterior gives "
                "apart from how fast the chains find it");
  cmd->add_option("-o,--out", o->out, "Output directory")->required();
  cmd->add_flag("!--no-figures", o->figures, "Skip the per-case PNG figures");
  AddStudySessionOptions(*cmd, o->session);
  cmd->callback([o] { RunSonarStudyCommand(*o); });
}

}  // namespace priormap::app
