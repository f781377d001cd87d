// priormap prf fit-sonar: the sonar model's parameters by maximum likelihood on readings whose
// true map is known, from simulated rings in scenes or from a log of a surveyed scene
// (docs/sonar.md).
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include <priormap/core/log_io.hpp>
#include <priormap/core/scene_truth.hpp>
#include <priormap/core/simulate.hpp>
#include <priormap/core/sonar_simulate.hpp>
#include <priormap/prf/map_study.hpp>
#include <priormap/prf/sonar_fit.hpp>
#include <priormap/prf/sonar_model_io.hpp>
#include <priormap/prf/sonar_study.hpp>

#include "cli_support.hpp"
#include "commands.hpp"

namespace priormap::app {
namespace {

struct FitSonarCliOptions {
  std::vector<std::string> scenes{"office", "l-office"};
  std::string sensor = "pioneer16";
  double speed = 0.5;
  double rate = 2.0;
  std::uint64_t seed = 1000;
  std::optional<double> max_range;
  std::string log;    // a surveyed log, with --scene
  std::string scene;  // the scene the log was recorded in
  std::string start;  // a model file to start from
  std::string out;
  prf::SonarFitOptions fit;
  // The options of the simulation (--scenes, --sensor, ...) given on the command line: with
  // --log there is nothing to simulate, and they would be ignored without a word.
  std::vector<std::string> simulation_options_given;
};

// The most simulated readings a fit takes: 270 times the default's 3,728, about a gigabyte of
// views and ten minutes of CPU (37,024 readings, --rate 20, took 50 MB and 20 s).
constexpr double kMaxFitReadings = 1e6;

// A scene given twice would have its rings simulated twice with the same seed (drawn from the
// scene's name) and fitted twice: the same readings counted double, without a word. Compared by
// name, not by the text given, so that a file and the built-in of the same name are caught too.
void RefuseRepeatedScenes(const std::vector<std::string>& given, const std::vector<Scene>& scenes) {
  const auto repeated = prf::RepeatedName(scenes, [](const Scene& s) { return s.name; });
  if (!repeated) return;
  std::vector<std::string> entries;
  for (std::size_t i = 0; i < scenes.size(); ++i)
    if (scenes[i].name == *repeated) entries.push_back(given[i]);
  if (entries[0] == entries[1])  // the option's own value, whatever the scenes hold
    throw UsageError(
        fmt::format("--scenes: '{}' is given twice (each scene is fitted once)", entries[0]));
  throw UserError(fmt::format(
      "--scenes: '{}' and '{}' are both scene '{}' (each scene is fitted once, its name seeds its "
      "simulation: give the scenes different names)",
      entries[0], entries[1], *repeated));
}

// The readings with their true views, from --log and --scene or simulated in --scenes.
std::vector<prf::SonarFitReading> TrainingReadings(const FitSonarCliOptions& o,
                                                   nlohmann::ordered_json* about) {
  std::vector<prf::SonarFitReading> readings;
  const auto add = [&](const Log& log, const Scene& scene, double max_range) {
    auto views = prf::ViewsOfScene(log, scene, max_range);
    if (auto* problem = std::get_if<std::string>(&views)) throw UserError(*problem);
    auto& v = std::get<std::vector<prf::SonarFitReading>>(views);
    readings.insert(readings.end(), std::make_move_iterator(v.begin()),
                    std::make_move_iterator(v.end()));
  };
  if (!o.log.empty()) {
    if (o.scene.empty()) throw UserError("--log needs --scene: the map the log was recorded in");
    if (const std::vector<std::string>& given = o.simulation_options_given; !given.empty()) {
      // "--seed is", "--scenes and --rate are", "--scenes, --rate and --seed are".
      const std::string options =
          given.size() == 1
              ? given.front()
              : fmt::format("{} and {}", fmt::join(given.begin(), given.end() - 1, ", "),
                            given.back());
      throw UserError(fmt::format(
          "{} {} for simulated rings to fit; with --log the readings are the log's: give one or "
          "the other",
          options, given.size() == 1 ? "is" : "are"));
    }
    const Log log = ValueOrThrow(ReadLog(o.log));
    const double max_range = o.max_range.value_or(5.0);
    for (const Scan& scan : log.scans)
      if (scan.sonar && !(max_range > scan.min_range))
        throw UserError(
            fmt::format("--max-range {} m: the log's rings hear nothing closer than "
                        "{} m",
                        max_range, scan.min_range));
    add(log, LoadScene(o.scene, "--scene"), max_range);
    (*about)["log"] = std::filesystem::absolute(o.log).string();
    (*about)["scene"] = o.scene;
    (*about)["max_range"] = max_range;
    return readings;
  }
  if (!o.scene.empty())
    throw UserError(
        "--scene is the map of --log: without --log, the rings are simulated in "
        "--scenes");
  const auto sensor = SonarSensor::Preset(o.sensor);
  if (!sensor)
    throw UserError(fmt::format("--sensor: unknown sonar '{}' (expected one of: {})", o.sensor,
                                fmt::join(SonarSensor::PresetNames(), ", ")));
  SonarSensor ring = *sensor;
  if (o.max_range) ring.max_range = *o.max_range;
  if (std::string why; !ring.IsValid(&why)) throw UserError(fmt::format("--max-range: {}", why));
  std::vector<Scene> scenes;
  double rings = 0.0;  // along every scene's path
  for (const std::string& name : o.scenes) {
    Scene scene = LoadScene(name, "--scenes");
    if (std::string problem = WaypointPathProblem(scene); !problem.empty())
      throw UserError(problem);
    rings += TrajectoryPoseCount(scene.waypoints, o.speed, o.rate);
    scenes.push_back(std::move(scene));
  }
  RefuseRepeatedScenes(o.scenes, scenes);
  // Refused before anything is simulated: a slower speed or a higher rate is a typo, and would
  // exhaust memory (or run for hours) before the fit ends.
  const double simulated = rings * static_cast<double>(ring.bearings.size());
  if (!(simulated <= kMaxFitReadings))
    throw UserError(fmt::format(
        "--speed {} m/s and --rate {} per s make {:.3g} rings of {} transducers in the scenes, "
        "{:.3g} readings, more than the {:.0e} a fit takes: use a lower --rate or a higher "
        "--speed",
        o.speed, o.rate, rings, ring.bearings.size(), simulated, kMaxFitReadings));
  for (const Scene& scene : scenes) {
    const Log log =
        SimulateSonarLog(scene, ring, TrajectoryFromWaypoints(scene.waypoints, o.speed, o.rate),
                         prf::SonarStudyCaseSeed(o.seed, scene.name, ring.name));
    add(log, scene, ring.max_range);
  }
  (*about)["scenes"] = o.scenes;
  (*about)["sensor"] = ring.name;
  (*about)["max_range"] = ring.max_range;
  (*about)["speed"] = o.speed;
  (*about)["rate"] = o.rate;
  (*about)["seed"] = o.seed;
  return readings;
}

void RunFitSonarCommand(const FitSonarCliOptions& o) {
  if (o.out.empty()) throw UsageError("-o/--out is required");
  RequireOutputDirectory(o.out, "--out");  // before the fit, not after it
  nlohmann::ordered_json about;
  const std::vector<prf::SonarFitReading> readings = TrainingReadings(o, &about);
  const prf::SonarModel start =
      o.start.empty() ? prf::SonarModel{} : ValueOrThrow(prf::ReadSonarModel(o.start));
  const prf::SonarFitResult fit = prf::FitSonarModel(readings, start, o.fit);
  const auto n = static_cast<double>(fit.readings);
  about["readings"] = fit.readings;
  about["log_likelihood"] = fit.log_likelihood;
  about["start_log_likelihood"] = fit.initial_log_likelihood;
  about["evaluations"] = fit.evaluations;
  about["clear_mixture"] = o.fit.fit_clear_mixture;
  about["concave_corners"] = o.fit.fit_concave_corners;
  about["multipath"] = o.fit.fit_multipath;
  if (!o.start.empty()) about["start"] = std::filesystem::absolute(o.start).string();
  prf::WriteSonarModel(fit.model, o.out, &about);
  fmt::print(
      "{} readings: log-likelihood {:.1f} -> {:.1f} ({:.3f} -> {:.3f} per reading), "
      "{} evaluations\n",
      fit.readings, fit.initial_log_likelihood, fit.log_likelihood, fit.initial_log_likelihood / n,
      fit.log_likelihood / n, fit.evaluations);
  fmt::print("{}wrote {}\n", prf::FormatSonarModel(fit.model), o.out);
}

}  // namespace

void AddPrfFitSonarCommand(CLI::App& prf_cmd) {
  auto o = std::make_shared<FitSonarCliOptions>();
  CLI::App* cmd = prf_cmd.add_subcommand(
      "fit-sonar",
      "Fit the PRF sonar model by maximum likelihood to readings whose true map is known: "
      "simulated rings in --scenes, or --log recorded in --scene");
  cmd->add_option("--scenes", o->scenes,
                  "Scenes (closed wall polylines, with a waypoint path) to simulate rings in")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--sensor", o->sensor, "Sonar ring preset of the simulation")
      ->check(SonarPresetName())
      ->capture_default_str();
  cmd->add_option("--speed", o->speed, "Robot speed along the waypoints, m/s")
      ->check(PositiveValueUpTo(100.0, "m/s"))
      ->capture_default_str();
  cmd->add_option("--rate", o->rate, "Rings per second")
      ->check(PositiveValue())
      ->capture_default_str();
  cmd->add_option("--seed", o->seed, "Seed of the simulated rings")
      ->transform(SeedValue())
      ->capture_default_str();
  cmd->add_option("--max-range", o->max_range, "R, m (default: the sensor's, or 5 with --log)")
      ->check(PositiveValueUpTo(100.0, "m"));
  cmd->add_option("--log", o->log, "A localized sonar log instead of simulated rings");
  cmd->add_option("--scene", o->scene, "The true map of --log (a scene of closed polylines)");
  cmd->add_option("--start", o->start, "Start from this model file (default: the built-in one)");
  cmd->add_flag("!--no-clear-mixture", o->fit.fit_clear_mixture,
                "Keep one outlier mixture for every cone (the paper's model)");
  cmd->add_flag("!--no-concave-corners", o->fit.fit_concave_corners,
                "Keep corners' echoes a function of their distance alone (the paper's model)");
  cmd->add_flag("!--no-multipath", o->fit.fit_multipath,
                "Leave out the multipath component: a specular miss is an outlier drawn from the "
                "mixtures alone (the paper's model)");
  cmd->add_option("-o,--out", o->out, "Model file to write (priormap.sonar_model JSON)")
      ->required();
  cmd->callback([o, cmd] {
    o->simulation_options_given.clear();
    for (const char* option : {"--scenes", "--sensor", "--speed", "--rate", "--seed"})
      if (cmd->count(option) > 0) o->simulation_options_given.emplace_back(option);
    RunFitSonarCommand(*o);
  });
}

}  // namespace priormap::app
