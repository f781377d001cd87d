// priormap prf study: the PRF posterior and MAP map against the occupancy grid at equal data, on
// simulated localized logs of scenes with known ground truth (docs/prf.md).
#include <array>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>

#include <priormap/core/file_io.hpp>
#include <priormap/prf/map_study.hpp>
#include <priormap/prf/map_study_io.hpp>
#include <priormap/prf/polygon_map.hpp>
#include <priormap/render/prf_figures.hpp>
#include <priormap/render/prf_study_figures.hpp>

#include "cli_support.hpp"
#include "commands.hpp"
#include "study_session_cli.hpp"

namespace priormap::app {
namespace {

struct StudyCliOptions {
  std::vector<std::string> scenes{"l-room", "rectangle", "corridor"};
  std::vector<std::string> sensors{"utm30", "lms200"};
  std::string out;
  bool figures = true;
  prf::MapStudyOptions study;
  StudySessionCliOptions session;
};

// Every figure a case may have, which a new run removes first.
constexpr std::array<const char*, 4> kCaseFigures = {"truth.png", "grid.png", "posterior.png",
                                                     "map.png"};

// The figures of one case in DIR/<scene>-<sensor>/.
void SaveCaseFigures(const std::filesystem::path& dir, const prf::MapStudyCase& c,
                     const Scene& scene) {
  EnsureDirectory(dir.string());
  std::vector<Vec2> sensors;
  for (const Se2& pose : c.poses) sensors.push_back(pose.translation());
  const std::string beams = fmt::format("{} beams", c.data->beams.size());
  render::SaveTruthFigure(dir / "truth.png", c.evaluation, c.poses,
                          fmt::format("{}: truth over the observed area", c.Name()));
  render::SaveProbabilityFigure(dir / "grid.png", c.grid_map,
                                fmt::format("{}: occupancy grid, {}", c.Name(), beams), sensors);
  const prf::CellGrid& raster = c.prf.raster;
  render::SaveProbabilityFigure(
      dir / "posterior.png", prf::SquareCellRaster(c.prf.black_fraction, raster),
      fmt::format("{}: PRF posterior P(black), {}", c.Name(), beams), sensors);
  if (c.prf.map)
    render::SaveMapAndWallsFigure(dir / "map.png", prf::ExtractFaces(*c.prf.map), c.prf.window,
                                  scene,
                                  fmt::format("{}: PRF MAP map, walls {:.1f} cm off on average",
                                              c.Name(), 100.0 * c.walls.mean_distance));
}

void RunStudyCommand(StudyCliOptions o) {
  if (o.out.empty()) throw UsageError("-o/--out is required");
  RefuseRepeatedEntries(o.scenes, "--scenes", "scene");
  RefuseRepeatedEntries(o.sensors, "--sensors", "sensor");
  for (const std::string& name : o.scenes) o.study.scenes.push_back(LoadScene(name, "--scenes"));
  for (const std::string& name : o.sensors) {
    const auto sensor = RangeSensor::Preset(name);
    if (!sensor)
      throw UserError(fmt::format("--sensors: unknown sensor '{}' (expected one of: {})", name,
                                  fmt::join(RangeSensor::PresetNames(), ", ")));
    o.study.sensors.push_back(*sensor);
  }
  if (const std::string problem = o.study.Problem(); !problem.empty()) throw UserError(problem);
  const std::filesystem::path dir(o.out);
  std::vector<std::string> folders;
  for (const Scene& scene : o.study.scenes)
    for (const RangeSensor& sensor : o.study.sensors)
      folders.push_back(prf::StudyCaseFolder(scene.name, sensor.name));
  const DirectoryLock lock =
      BeginStudy(dir, folders, prf::MapStudyOptionsJson(o.study), o.session.resume);

  const std::optional<prf::MapStudyResult> ended = RunStoppableStudy(
      dir, folders, o.session,
      [&](const prf::StudySession& session) { return prf::RunMapStudy(o.study, session); });
  if (!ended) return;
  const prf::MapStudyResult& result = *ended;

  const std::string table = prf::MapStudyMarkdownTable(result);
  bool maps = false;
  FinishStudy(dir, folders, [&] {
    WriteTextFileAtomically(dir / "summary.json", prf::MapStudySummaryJson(result, o.study));
    WriteTextFileAtomically(dir / "table.md", table);
    for (std::size_t i = 0; i < result.cases.size(); ++i) {
      const prf::MapStudyCase& c = result.cases[i];
      const std::filesystem::path case_dir = dir / folders[i];
      // An earlier run's figures of this case would stand beside this run's numbers.
      RemoveFiles(case_dir, kCaseFigures);
      if (o.figures) SaveCaseFigures(case_dir, c, o.study.scenes[i / o.study.sensors.size()]);
      maps = maps || c.prf.map.has_value();
    }
  });
  fmt::print("{}\nwrote {} (summary.json, table.md{}) in {:.0f} s\n", table, o.out,
             !o.figures ? ""
             : maps     ? ", <scene>-<sensor>/{truth,grid,posterior,map}.png"
                        : ", <scene>-<sensor>/{truth,grid,posterior}.png",
             result.wall_time_s);
}

}  // namespace

void AddPrfStudyCommand(CLI::App& prf_cmd) {
  auto o = std::make_shared<StudyCliOptions>();
  prf::MapStudyOptions& s = o->study;
  prf::MappingOptions& m = s.mapping;
  // Sized so that the six default cases take a few minutes on two cores; 1M steps of each
  // change no accuracy by more than 0.7 points (docs/prf.md).
  m.samples = 300000;
  m.burn_in = 300000;
  m.chains = 2;
  m.anneal_steps = 300000;
  CLI::App* cmd = prf_cmd.add_subcommand(
      "study",
      "PRF posterior and MAP map vs the occupancy grid on simulated logs with ground truth: "
      "classification accuracy over the observed area and its sparse part, MAP wall distances");
  cmd->add_option("--scenes", o->scenes, "Scenes (built-in names or scene JSON files)")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--sensors", o->sensors, "Range sensor presets")
      ->delimiter(',')
      ->check(CLI::Validator(
          [](std::string& name) -> std::string {
            if (RangeSensor::Preset(name)) return {};
            return fmt::format("unknown sensor '{}' (expected one of: {})", name,
                               fmt::join(RangeSensor::PresetNames(), ", "));
          },
          ""))
      ->capture_default_str();
  cmd->add_option("--poses", s.poses, "Scans per case, evenly along the scene's waypoint path")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  cmd->add_option("--beam-step", s.beam_step, "Every k-th beam of each scan (both methods)")
      ->check(CLI::Range(std::size_t{1}, std::size_t{100000}))
      ->capture_default_str();
  cmd->add_option("--max-range", s.max_range, "R: readings at or above it are max-range, m")
      ->check(PositiveValue())
      ->capture_default_str();
  cmd->add_option("--resolution", s.resolution,
                  "Cell of the evaluation raster, the grid and the PRF raster, m")
      ->check(PositiveValue())
      ->check(StudyResolution())
      ->capture_default_str();
  cmd->add_option("--band", s.band, "Depth behind a seen surface that counts as observed, m")
      ->check(NonNegativeValue())
      ->capture_default_str();
  cmd->add_option("--p", m.sampler.p, "Scale parameter p of the Arak prior (1/m)")
      ->check(PositiveValue())
      ->capture_default_str();
  cmd->add_option("--sigma", m.model.sigma, "Range noise of the PRF's beam model, m")
      ->check(PositiveValue())
      ->capture_default_str();
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
  cmd->add_option("--anneal-steps", m.anneal_steps, "Annealing steps to the MAP map (0: none)")
      ->transform(StepCount())
      ->capture_default_str();
  cmd->add_option("--wall-tolerance", s.walls.tolerance,
                  "A seen true wall is recovered with a MAP edge this close, m")
      ->check(NonNegativeValue())
      ->capture_default_str();
  cmd->add_option("--seed", s.seed, "Random seed; the same seed gives the same result")
      ->transform(SeedValue())
      ->capture_default_str();
  cmd->add_option("-o,--out", o->out, "Output directory")->required();
  cmd->add_flag("!--no-figures", o->figures, "Skip the per-case PNG figures");
  AddStudySessionOptions(*cmd, o->session);
  cmd->callback([o] { RunStudyCommand(*o); });
}

}  // namespace priormap::app
