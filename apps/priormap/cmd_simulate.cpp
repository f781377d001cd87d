// priormap simulate: scene + sensor -> a scan (or a localized log) with ground truth.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/json_io.hpp>
#include <priormap/core/log_io.hpp>
#include <priormap/core/simulate.hpp>
#include <priormap/core/sonar_simulate.hpp>
#include <priormap/render/scene_drawing.hpp>

#include "cli_support.hpp"
#include "commands.hpp"

namespace priormap::app {
namespace {

struct SimulateOptions {
  std::string scene = "l-room";
  std::string sensor = "utm30";
  std::optional<int> beams;
  std::optional<double> fov_deg, sigma, correlation, min_range, max_range, outliers, dropout;
  std::optional<std::string> pose;
  bool log = false;
  double speed = 0.5;
  double rate = 5.0;
  std::uint64_t seed = 1;
  std::string out;
  std::optional<std::string> format;
  std::optional<std::string> figure;
  std::optional<std::string> write_scene;
  bool trajectory_given = false;  // --speed or --rate on the command line
};

RangeSensor MakeSensor(const SimulateOptions& o) {
  std::optional<RangeSensor> preset = RangeSensor::Preset(o.sensor);
  if (!preset) {
    throw UserError(
        fmt::format("--sensor: unknown sensor '{}' (expected a laser: {}; or a sonar "
                    "ring: {})",
                    o.sensor, fmt::join(RangeSensor::PresetNames(), ", "),
                    fmt::join(SonarSensor::PresetNames(), ", ")));
  }
  RangeSensor sensor = *preset;
  if (o.beams) sensor.num_beams = *o.beams;
  if (o.fov_deg) sensor.fov = DegToRad(*o.fov_deg);
  if (o.sigma) sensor.sigma = *o.sigma;
  if (o.correlation) sensor.correlation = *o.correlation;
  if (o.min_range) sensor.min_range = *o.min_range;
  if (o.max_range) sensor.max_range = *o.max_range;
  if (o.outliers) sensor.outlier_probability = *o.outliers;
  if (o.dropout) sensor.dropout_probability = *o.dropout;
  std::string why;
  if (!sensor.IsValid(&why)) throw UserError("sensor: " + why);
  return sensor;
}

// --sensor's check: a laser or a sonar ring preset.
CLI::Validator SensorPresetName() {
  return CLI::Validator(
      [](std::string& name) -> std::string {
        if (RangeSensor::Preset(name) || SonarSensor::Preset(name)) return {};
        return fmt::format("unknown sensor '{}' (expected a laser: {}; or a sonar ring: {})", name,
                           fmt::join(RangeSensor::PresetNames(), ", "),
                           fmt::join(SonarSensor::PresetNames(), ", "));
      },
      "");
}

// A sonar ring preset (pioneer8, pioneer16, robond) with the options that apply to a ring;
// nullopt when `o.sensor` names a laser.
std::optional<SonarSensor> MakeSonarSensor(const SimulateOptions& o) {
  std::optional<SonarSensor> sensor = SonarSensor::Preset(o.sensor);
  if (!sensor) return std::nullopt;
  if (o.beams || o.fov_deg || o.sigma || o.correlation || o.outliers || o.dropout)
    throw UserError(fmt::format(
        "--sensor {} is a sonar ring: --beams, --fov, --sigma, --correlation, --outliers and "
        "--dropout apply to lasers only",
        o.sensor));
  if (o.min_range) sensor->min_range = *o.min_range;
  if (o.max_range) sensor->max_range = *o.max_range;
  std::string why;
  if (!sensor->IsValid(&why)) throw UserError("sensor: " + why);
  return sensor;
}

// More scans than any log needs: a slower speed or a higher rate is a typo, and would exhaust
// memory (or overflow the scan count) before writing anything.
constexpr double kMaxLogScans = 1e7;
// What a simulated reading takes in memory with its ground truth, measured on utm30 and pioneer16
// logs (a ring's cones and their truth make sonar readings dearer), and the most a log may take.
constexpr double kLaserReadingBytes = 150;
constexpr double kSonarReadingBytes = 500;
constexpr double kMaxLogBytes = 8e9;

// Refuses a log that would not fit in memory, before it is simulated.
void RequireLogFitsInMemory(double scans, double readings_per_scan, bool sonar) {
  const double bytes =
      scans * readings_per_scan * (sonar ? kSonarReadingBytes : kLaserReadingBytes);
  if (!(bytes <= kMaxLogBytes))
    throw UserError(fmt::format(
        "{} of {:.0f} readings would take about {:.0f} GB of memory, more than {:.0f} GB: use "
        "{}a lower --rate or a higher --speed",
        scans == 1 ? "a scan" : fmt::format("{:.3g} scans", scans), readings_per_scan, bytes / 1e9,
        kMaxLogBytes / 1e9, sonar ? "" : "fewer --beams, "));
}

void Run(const SimulateOptions& o) {
  // Every check before the first write, so that a failure leaves nothing behind.
  const Scene scene = LoadScene(o.scene, "--scene");
  const std::optional<SonarSensor> sonar = MakeSonarSensor(o);
  const RangeSensor sensor = sonar ? RangeSensor{} : MakeSensor(o);
  if (o.out.empty() && !o.write_scene)
    throw UsageError("--out is required (or --write-scene alone to export the scene)");
  const LogFormat format =
      o.out.empty() ? LogFormat::kJson : OutputLogFormat(o.format, o.out, "--out", "--format");
  if (sonar && !o.out.empty() && format != LogFormat::kJson)
    throw UserError(
        fmt::format("--out {}: sonar rings are written as JSON logs only (a CARMEN "
                    "log has no record for cones); use a .json file",
                    o.out));
  if (o.figure && o.out.empty())
    throw UserError("--png draws the simulated scan or log: give --out too");
  if (!o.out.empty()) RequireOutputDirectory(o.out, "--out");
  if (o.figure) RequireOutputDirectory(*o.figure, "--png");
  if (o.write_scene) RequireOutputDirectory(*o.write_scene, "--write-scene");
  const Se2 pose = o.pose ? ParsePose(*o.pose) : scene.default_pose.value_or(Se2());
  if (o.log && scene.waypoints.size() < 2) {
    throw UserError(fmt::format("--log: scene '{}' has no waypoints to follow", scene.name));
  }
  // Options for the other kind of output are refused, not ignored.
  if (o.log && o.pose)
    throw UserError("--pose places a single scan; --log follows the scene's waypoints");
  if (!o.log && o.trajectory_given)
    throw UserError("--speed and --rate set the trajectory of --log; a single scan has none");
  const double readings_per_scan =
      sonar ? static_cast<double>(sonar->bearings.size()) : sensor.num_beams;
  if (o.log) {
    const double path = WaypointPathLength(scene.waypoints);
    if (!(path > 0.0))
      throw UserError(fmt::format(
          "--log: the waypoints of scene '{}' all coincide: no path to follow", scene.name));
    const double step = o.speed / o.rate;
    const double scans = path / step;
    if (!(scans <= kMaxLogScans))
      throw UserError(fmt::format(
          "--speed {} m/s and --rate {} per s along the {:.1f} m path make {:.3g} scans, more than "
          "{:.0e}",
          o.speed, o.rate, path, scans, kMaxLogScans));
    if (!(step <= path))
      throw UserError(fmt::format(
          "--speed {} m/s and --rate {} per s move the robot {:.3g} m between scans, beyond the "
          "{:.1f} m path: the log would hold one scan; use a lower --speed or a higher --rate",
          o.speed, o.rate, step, path));
    RequireLogFitsInMemory(std::floor(scans) + 1, readings_per_scan, sonar.has_value());
  } else {
    RequireLogFitsInMemory(1, readings_per_scan, sonar.has_value());
  }
  if (o.write_scene) {
    WriteJsonScene(scene, *o.write_scene);
    fmt::print("wrote {} (scene {})\n", *o.write_scene, scene.name);
    if (o.out.empty()) return;
  }

  Log log;
  if (o.log && sonar) {
    log = SimulateSonarLog(scene, *sonar, TrajectoryFromWaypoints(scene.waypoints, o.speed, o.rate),
                           o.seed);
  } else if (o.log) {
    log = SimulateLog(scene, sensor, TrajectoryFromWaypoints(scene.waypoints, o.speed, o.rate),
                      o.seed);
  } else if (sonar) {
    Rng rng(o.seed);
    log.pose_source = PoseSource::kGroundTruth;
    log.scans.push_back(SimulateSonarRing(SonarScene(scene), *sonar, pose, rng));
  } else {
    Rng rng(o.seed);
    log.pose_source = PoseSource::kGroundTruth;
    log.scans.push_back(SimulateScan(SceneRayCaster(scene), sensor, pose, rng));
  }

  if (!o.log && format == LogFormat::kJson) {
    WriteJsonScan(log.scans.front(), o.out);
  } else {
    WriteLogWarningOfLosses(log, o.out, format);
  }
  std::size_t valid = 0, beams = 0;
  for (const Scan& scan : log.scans) {
    valid += scan.NumValid();
    beams += scan.size();
  }
  fmt::print("wrote {}: {} of {} from sensor {} in scene {} ({})\n", o.out,
             Plural(log.scans.size(), "scan"),
             Plural(beams / std::max<std::size_t>(log.scans.size(), 1), "beam"),
             sonar ? sonar->name : sensor.name, scene.name, Plural(valid, "valid reading"));

  if (o.figure) {
    Box2 bounds = scene.Bounds();
    for (const Scan& scan : log.scans) bounds.extend(render::ScanBounds(scan));
    render::Figure figure(
        bounds, {.title = fmt::format("{}: {} ({})", scene.name, sonar ? sonar->name : sensor.name,
                                      o.log ? Plural(log.scans.size(), "scan") : "one scan")});
    render::DrawScene(figure, scene);
    if (o.log) {
      render::DrawLog(figure, log);
    } else {
      render::DrawScan(figure, log.scans.front());
    }
    figure.Save(*o.figure);
    fmt::print("wrote {}\n", *o.figure);
  }
}

}  // namespace

void AddSimulateCommand(CLI::App& app) {
  auto o = std::make_shared<SimulateOptions>();
  CLI::App* cmd = app.add_subcommand(
      "simulate", "Simulate a range scan (or a localized log) with ground truth");
  cmd->add_option("--scene", o->scene,
                  fmt::format("Built-in scene ({}) or a scene JSON file",
                              fmt::join(BuiltinSceneNames(), ", ")))
      ->capture_default_str();
  cmd->add_option("--sensor", o->sensor,
                  "Sensor preset: a laser (utm30, lms200) or a sonar ring (pioneer8, pioneer16, "
                  "robond; docs/sonar.md)")
      ->check(SensorPresetName())
      ->capture_default_str();
  cmd->add_option("--beams", o->beams, "Number of beams (overrides the preset)")
      ->check(PositiveValue());
  cmd->add_option("--fov", o->fov_deg, "Field of view, degrees, in (0, 360]")
      ->check(PositiveValue())
      ->check(CLI::Range(0.0, 360.0));
  cmd->add_option("--sigma", o->sigma, "Range noise standard deviation, m")
      ->check(PositiveValue())
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            // The sensor's own bounds on sigma, which hold whatever the preset: judged on a
            // preset that meets every other one.
            RangeSensor sensor = *RangeSensor::Preset("utm30");
            std::string why;
            if (!CLI::detail::lexical_cast(text, sensor.sigma) || sensor.IsValid(&why)) return {};
            return why;
          },
          ""));
  cmd->add_option("--correlation", o->correlation,
                  "Noise correlation of neighbouring beams, in [0, 1)")
      ->check(NumberValidator(
          [](double value, const std::string& text) -> std::string {
            if (value >= 0.0 && value < 1.0) return {};
            return text + " is not in [0, 1), 1 excluded";
          },
          ""));
  // Checked here on their own; the sensor's own check (IsValid) then compares them with each
  // other and with the preset.
  cmd->add_option("--min-range", o->min_range, "Minimum range, m")->check(NonNegativeValue());
  cmd->add_option("--max-range", o->max_range, "Maximum range, m")->check(PositiveValue());
  cmd->add_option("--outliers", o->outliers, "Probability of a spurious short reading per beam")
      ->check(Probability());
  cmd->add_option("--dropout", o->dropout,
                  "Probability of a missing return (max-range reading) per beam")
      ->check(Probability());
  cmd->add_option("--pose", o->pose, "Sensor pose x,y,theta (m, m, rad); default: the scene's")
      ->check(ParsedBy("--pose", ParsePose));
  cmd->add_flag("--log", o->log,
                "Simulate a localized log along the scene's waypoints instead of one scan");
  cmd->add_option("--speed", o->speed, "Log: robot speed, m/s")
      ->check(PositiveValue())
      ->capture_default_str();
  cmd->add_option("--rate", o->rate, "Log: scans per second")
      ->check(PositiveValue())
      ->capture_default_str();
  cmd->add_option("--seed", o->seed, "Random seed; the same seed gives the same output")
      ->transform(SeedValue())
      ->capture_default_str();
  cmd->add_option("-o,--out", o->out,
                  "Output file: .json (priormap JSON) or .log / .log.gz (CARMEN)");
  cmd->add_option("--format", o->format, "Output format, overriding the extension")
      ->check(CLI::IsMember({"json", "carmen"}));
  cmd->add_option("--png,--figure", o->figure, "Also draw the result (.png, .svg or .pdf)")
      ->check(FigurePath());
  cmd->add_option("--write-scene", o->write_scene,
                  "Also write the scene as priormap JSON (a starting point for your own)");
  cmd->callback([o, cmd] {
    o->trajectory_given = cmd->count("--speed") + cmd->count("--rate") > 0;
    Run(*o);
  });
}

}  // namespace priormap::app
