// priormap slam: EKF-SLAM with a prior map of building walls (Parsley & Julier). `simulate` runs
// the paper's Monte Carlo study (Sec. VI) on a simulated city; `run` filters the user's files.
#include <algorithm>
#include <array>
#include <charconv>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <optional>
#include <system_error>

#include <fmt/format.h>
#include <tbb/global_control.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/file_io.hpp>
#include <priormap/core/world_bounds.hpp>
#include <priormap/render/slam_figures.hpp>
#include <priormap/slam/slam_io.hpp>
#include <priormap/slam/study.hpp>
#include <priormap/slam/study_io.hpp>

#include "cli_support.hpp"
#include "commands.hpp"

namespace priormap::app {
namespace {

namespace fs = std::filesystem;

// --- shared ------------------------------------------------------------------------------------

// The filter's thresholds (Sec. V-A, VI), shared by both subcommands as advanced options.
void AddAlgorithmOptions(CLI::App* cmd, slam::SlamOptions& o) {
  const char* group = "Advanced (structure inference, Sec. V-A)";
  cmd->add_option("--p-accept", o.priors.p_accept,
                  "Accept the most probable association hypothesis above this probability")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str()
      ->group(group);
  cmd->add_option("--p-line-real", o.priors.p_line_real,
                  "Prior probability that a prior-map segment is a real wall")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str()
      ->group(group);
  cmd->add_option("--p-point-on-line", o.priors.p_point_on_line,
                  "Prior probability that a landmark near a real wall lies on it")
      ->check(OpenUnitInterval())
      ->capture_default_str()
      ->group(group);
  cmd->add_option("--null-density", o.priors.unrelated_density,
                  "p(theta | d = 0): density of an unrelated pair's distance, per metre")
      ->check(PositiveValue())
      ->capture_default_str()
      ->group(group);
  cmd->add_option("--wall-std", o.wall_std, "How far a landmark on a wall may be off it, m")
      ->check(PositiveValue())
      ->capture_default_str()
      ->group(group);
  cmd->add_option("--gate-chi2", o.gate_chi2, "Gate of a landmark-segment pair (chi2, 1 dof)")
      ->check(PositiveValue())
      ->capture_default_str()
      ->group(group);
  cmd->add_option("--max-cluster-pairs", o.max_cluster_pairs,
                  "Larger clusters of gated pairs defer their least certain landmarks")
      ->check(CLI::Range(1, slam::kMaxEnumeratedPairs))
      ->capture_default_str()
      ->group(group);
  cmd->add_option("--recheck-chi2", o.recheck_chi2,
                  "Flag an applied relation whose innovation exceeds this (chi2, 1 dof) ...")
      ->check(PositiveValue())
      ->capture_default_str()
      ->group(group);
  cmd->add_option("--recheck-frames", o.recheck_frames, "... on this many consecutive frames")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str()
      ->group(group);
  cmd->add_flag_callback(
         "--keep-same-walls", [&o] { o.merge_same_walls = false; },
         "Do not merge prior segments that are the same wall (collinear and overlapping within "
         "their std, as a wall two footprints share, or collinear parts of one wall that a "
         "footprint splits at a vertex)")
      ->group(group);
  cmd->add_option("--same-wall-chi2", o.same_wall_chi2,
                  "Two prior segments are the same wall below this (chi2, 2 dof, of each one's "
                  "endpoints off the other's line)")
      ->check(NonNegativeValue())
      ->capture_default_str()
      ->group(group);
  cmd->add_flag("--building-relations", o.building_relations,
                "Relate a landmark at a corner to some wall of its building (eq. 3 mixture)")
      ->group(group);
  cmd->add_flag_callback(
         "--first-order-ekf",
         [&o] {
           o.first_estimates_jacobians = false;
           o.second_order_range = false;
         },
         "Textbook EKF: Jacobians at the current estimate, first-order range (overconfident)")
      ->group(group);
}

// -o DIR and --export-inputs DIR: created when missing, so their parent must exist (a typo
// fails before anything is computed or written) and they must not be files.
void RequireOutputDirectoryPath(const fs::path& directory, const std::string& option) {
  fs::path path = directory;
  if (!path.has_filename()) path = path.parent_path();  // "out/"
  std::error_code ec;
  if (fs::exists(path, ec) && !fs::is_directory(path, ec))
    throw UserError(fmt::format("{}: '{}' is a file, not a directory", option, directory.string()));
  const fs::path parent = path.parent_path().empty() ? "." : path.parent_path();
  if (!fs::is_directory(parent, ec))
    throw UserError(fmt::format("{}: cannot make '{}': directory {} does not exist", option,
                                directory.string(), parent.string()));
}

std::optional<tbb::global_control> LimitThreads(const std::optional<int>& threads) {
  std::optional<tbb::global_control> control;
  if (threads) control.emplace(tbb::global_control::max_allowed_parallelism, *threads);
  return control;
}

// Each figure as PNG and SVG.
template <typename Drawing>
void SaveFigure(const Drawing& drawing, const fs::path& stem) {
  for (const char* extension : {".png", ".svg"}) {
    fs::path path = stem;
    path += extension;
    drawing.Save(path);
  }
}

// What SaveFigure wrote for `stem` in an earlier run, gone: a run without figures must not sit
// beside another run's.
void RemoveFigure(const fs::path& stem) {
  for (const char* extension : {".png", ".svg"}) {
    fs::path path = stem;
    path += extension;
    fs::remove(path);
  }
}

constexpr std::array<const char*, 4> kStudyFigures = {"pose_error", "nees", "relations", "map"};

std::string Number(double value) {
  return fmt::format("{}", value);
}

// --- slam simulate -----------------------------------------------------------------------------

struct SimulateOptions {
  int runs = 30;
  std::uint64_t seed = 1;
  std::string out;
  std::optional<int> threads;
  bool no_figures = false;
  std::optional<std::string> export_inputs;
  double prior_std = slam::UrbanScenarioOptions{}.prior_std;
  double window = slam::SlamOptions{}.window_s;
  slam::SlamOptions slam;
};

void WriteStudyFigures(const slam::StudyResult& study, const slam::UrbanWorld& world,
                       const slam::UrbanRun& run, const fs::path& directory) {
  EnsureDirectory(directory);
  const std::string runs = Plural(study.with_prior.size(), "run");
  SaveFigure(render::StudyPlot(study, render::StudyPlotKind::kPoseError,
                               {.title = fmt::format("Pose error, {} (Fig. 4)", runs)}),
             directory / "pose_error");
  SaveFigure(render::StudyPlot(study, render::StudyPlotKind::kNees,
                               {.title = fmt::format("Consistency, {}", runs)}),
             directory / "nees");
  SaveFigure(render::StudyPlot(study, render::StudyPlotKind::kRelations,
                               {.title = fmt::format("Relations applied, {} (Fig. 5)", runs)}),
             directory / "relations");
  const slam::RunTrace* with = study.with_prior.empty() ? nullptr : &study.with_prior.front();
  const slam::RunTrace* without =
      study.without_prior.empty() ? nullptr : &study.without_prior.front();
  SaveFigure(render::StudyMapFigure(
                 world, run, with, without,
                 {.title = fmt::format("Simulated city and run 0 ({:.0f} m)", world.PathLength())}),
             directory / "map");
}

// The options of `slam run` that give the study's filter where it differs from the defaults
// (" --window 2 --p-accept 0.9", say), so that the exported command filters as the study did.
std::string NonDefaultFilterOptions(const slam::SlamOptions& s) {
  const slam::SlamOptions d;
  std::string out;
  const auto number = [&](const char* option, double value, double default_value) {
    if (value != default_value) out += fmt::format(" {} {}", option, Number(value));
  };
  number("--window", s.window_s, d.window_s);
  number("--p-accept", s.priors.p_accept, d.priors.p_accept);
  number("--p-line-real", s.priors.p_line_real, d.priors.p_line_real);
  number("--p-point-on-line", s.priors.p_point_on_line, d.priors.p_point_on_line);
  number("--null-density", s.priors.unrelated_density, d.priors.unrelated_density);
  number("--wall-std", s.wall_std, d.wall_std);
  number("--gate-chi2", s.gate_chi2, d.gate_chi2);
  number("--max-cluster-pairs", s.max_cluster_pairs, d.max_cluster_pairs);
  number("--recheck-chi2", s.recheck_chi2, d.recheck_chi2);
  number("--recheck-frames", s.recheck_frames, d.recheck_frames);
  number("--same-wall-chi2", s.same_wall_chi2, d.same_wall_chi2);
  if (!s.merge_same_walls) out += " --keep-same-walls";
  if (s.building_relations) out += " --building-relations";
  if (!s.first_estimates_jacobians) out += " --first-order-ekf";
  return out;
}

// Run 0's data in the files of `slam run`, its truth, and how to filter it as the study did.
void ExportInputs(const slam::UrbanWorld& world, const slam::UrbanRun& run,
                  const slam::SlamOptions& filter, const fs::path& directory) {
  EnsureDirectory(directory);
  slam::WriteObservationsCsv(run.input.frames, directory / "observations.csv");
  slam::WriteOdometryCsv({run.input.start_time, run.input.motion}, directory / "odometry.csv");
  slam::WritePriorMapGeoJson(run.prior_map, directory / "prior_map.geojson");
  std::string truth = "time,x,y,theta\n";
  for (std::size_t f = 0; f < run.frame_truth.size() && f < run.input.frames.size(); ++f) {
    const Se2& pose = run.frame_truth[f];
    truth +=
        fmt::format("{},{},{},{}\n", run.input.frames[f].time, pose.x(), pose.y(), pose.theta());
  }
  WriteTextFileAtomically(directory / "truth.csv", truth);
  std::string beacons = "id,x,y,wall,on_wall\n";
  for (std::size_t i = 0; i < world.beacons.size(); ++i) {
    const slam::Beacon& b = world.beacons[i];
    beacons += fmt::format("{},{},{},{},{}\n", i, b.position.x(), b.position.y(), b.wall,
                           b.on_wall ? 1 : 0);
  }
  WriteTextFileAtomically(directory / "beacons.csv", beacons);
  const Se2& start = run.input.initial_pose;
  const slam::MotionNoise& motion = run.input.motion_noise;
  const slam::SensorNoise& sensor = run.input.sensor_noise;
  WriteTextFileAtomically(
      directory / "README.txt",
      fmt::format(
          "Run 0 of a simulated prior-map SLAM study (priormap slam simulate), in the files of\n"
          "'priormap slam run' (docs/formats.md):\n"
          "  observations.csv   range-bearing observations of the beacons (ids known)\n"
          "  odometry.csv       bicycle controls (speed, steer) with noise\n"
          "  prior_map.geojson  the prior map: noisy walls and spurious segments\n"
          "  truth.csv          the true pose at each observation frame\n"
          "  beacons.csv        the true beacons (id = landmark id), on or off their wall\n"
          "Frames without observations are rows with only a time (\"t,,,\").\n\n"
          "Filter them with:\n"
          "  priormap slam run --observations observations.csv --odometry odometry.csv \\\n"
          "    --prior-map prior_map.geojson --initial-pose={},{},{} \\\n"
          "    --wheelbase {} --speed-std {} --steer-std {} --range-std {} --bearing-std {} \\\n"
          "   {} -o slam_out\n",
          Number(start.x()), Number(start.y()), Number(start.theta()), Number(motion.wheelbase),
          Number(motion.speed_std), Number(RadToDeg(motion.steer_std)), Number(sensor.range_std),
          Number(RadToDeg(sensor.bearing_std)), NonDefaultFilterOptions(filter)));
}

void PrintStudy(const slam::StudyResult& s) {
  const slam::VariantSummary& w = s.with_prior_summary;
  const slam::VariantSummary& wo = s.without_prior_summary;
  fmt::print("{}, {:.0f} m in {:.0f} s, {} beacons, {} prior segments\n",
             Plural(s.with_prior.size(), "run"), s.path_length_m, s.duration_s, s.beacons,
             s.prior_segments);
  fmt::print("{:<28}{:>14}{:>14}\n", "", "with prior", "without");
  fmt::print("{:<28}{:>14.3f}{:>14.3f}\n", "RMS position (m)", w.rms_position_m, wo.rms_position_m);
  fmt::print("{:<28}{:>14.3f}{:>14.3f}\n", "RMS heading (deg)", RadToDeg(w.rms_heading_rad),
             RadToDeg(wo.rms_heading_rad));
  fmt::print("{:<28}{:>14.3f}{:>14.3f}\n", "inside 3 sigma (min x,y,th)", w.inside_3sigma_fraction,
             wo.inside_3sigma_fraction);
  fmt::print("{:<28}{:>14.3g}{:>14.3g}\n",
             fmt::format("mean NEES [{:.2f}, {:.2f}]", s.nees_band_low, s.nees_band_high),
             w.mean_nees, wo.mean_nees);
  fmt::print("{:<28}{:>14.3f}{:>14.3f}\n", "NEES inside band", w.nees_inside_band_fraction,
             wo.nees_inside_band_fraction);
  fmt::print("{:<28}{:>14.1f}{:>14.1f}\n", "landmarks in state", w.mean_landmarks,
             wo.mean_landmarks);
  fmt::print("constraints: {} correct, {} incorrect ({} to spurious segments), {} flagged\n",
             s.relations.correct, s.relations.incorrect, s.relations.from_spurious,
             s.relations.flagged);
  fmt::print("wall time {:.1f} s\n", s.wall_time_s);
}

void Simulate(const SimulateOptions& o) {
  // Every check before the first write, so that a failure leaves nothing behind.
  slam::StudyOptions study;
  study.runs = o.runs;
  study.seed = o.seed;
  study.scenario.prior_std = o.prior_std;
  study.slam = o.slam;
  study.slam.window_s = o.window;
  std::string why;
  if (!study.scenario.IsValid(&why)) throw UserError("scenario: " + why);
  RequireOutputDirectoryPath(o.out, "--out");
  if (o.export_inputs) RequireOutputDirectoryPath(*o.export_inputs, "--export-inputs");

  const std::optional<tbb::global_control> threads = LimitThreads(o.threads);
  Progress progress(2 * static_cast<std::size_t>(o.runs), "filter runs");
  study.progress = [&progress](int, int) { progress.Step(); };
  const slam::StudyResult result = slam::RunStudy(study);

  const fs::path out = o.out;
  EnsureDirectory(out);
  const std::vector<fs::path> written = slam::WriteStudyOutputs(result, study, out);
  if (o.no_figures) {
    for (const char* figure : kStudyFigures) RemoveFigure(out / "figures" / figure);
    std::error_code not_empty;  // then it holds files of the user's, which stay
    fs::remove(out / "figures", not_empty);
  }
  if (!o.no_figures || o.export_inputs) {
    // The world and run 0 again (deterministic, cheap next to the filter runs).
    const slam::UrbanWorld world = slam::MakeUrbanWorld(study.scenario, study.seed);
    const slam::UrbanRun run = slam::SimulateUrbanRun(world, study.scenario, study.seed, 0);
    if (!o.no_figures) WriteStudyFigures(result, world, run, out / "figures");
    if (o.export_inputs) ExportInputs(world, run, study.slam, *o.export_inputs);
  }
  PrintStudy(result);
  fmt::print("wrote {} ({} and {} per-run tables{})\n", o.out, written.front().filename().string(),
             written.size() - 2, o.no_figures ? "" : ", figures/");
  if (o.export_inputs) fmt::print("wrote {} (run 0 as input files)\n", *o.export_inputs);
}

// --- slam run ----------------------------------------------------------------------------------

struct RunOptions {
  std::string observations;
  std::string odometry;
  std::optional<std::string> prior_map;
  std::string out;
  double prior_std = 1.0;
  std::string initial_pose = "0,0,0";
  std::string association = "ids";
  bool no_prior = false;
  bool no_figures = false;
  std::optional<int> threads;
  slam::MotionNoise motion;
  slam::SensorNoise sensor;
  double steer_std_deg = RadToDeg(slam::MotionNoise{}.steer_std);
  double bearing_std_deg = RadToDeg(slam::SensorNoise{}.bearing_std);
  std::string increment_std;
  slam::SlamOptions slam;
};

// Three comma-separated finite numbers, "x,y,theta".
std::optional<Vec3> ParseThree(const std::string& text) {
  Vec3 values;
  const char* first = text.data();
  const char* const last = text.data() + text.size();
  for (int k = 0; k < 3; ++k) {
    const char* end = k < 2 ? std::find(first, last, ',') : last;
    if (end == last && k < 2) return std::nullopt;
    const auto [ptr, ec] = std::from_chars(first, end, values[k]);
    if (ec != std::errc() || ptr != end || !std::isfinite(values[k])) return std::nullopt;
    first = end + 1;
  }
  return values;
}

Se2 ParseInitialPose(const std::string& text) {
  const std::optional<Vec3> v = ParseThree(text);
  if (!v) {
    throw UserError(fmt::format(
        "--initial-pose: expected x,y,theta (three numbers, m, m, rad), got '{}'", text));
  }
  // As every position priormap reads; beyond it the map written would be refused when read.
  if (!IsWithinWorld(v->x()) || !IsWithinWorld(v->y())) {
    throw UserError(
        fmt::format("--initial-pose: expected x and y at most {:.0e} m in magnitude, "
                    "got '{}'",
                    kMaxWorldCoordinate, text));
  }
  return {v->x(), v->y(), v->z()};
}

Vec3 ParseIncrementStd(const std::string& text) {
  const std::optional<Vec3> v = ParseThree(text);
  if (!v || (v->array() < 0.0).any()) {
    throw UserError(fmt::format(
        "--increment-std: expected sx,sy,stheta (three numbers >= 0: m, m, rad), got '{}'", text));
  }
  return *v;
}

// The observations must lie within the odometry's time span, and known-id association needs ids.
void CheckInputs(const RunOptions& o, const std::vector<slam::ObservationFrame>& frames,
                 const slam::Odometry& odometry) {
  if (frames.empty())
    throw UserError(fmt::format("{}: no observations (only a header)", o.observations));
  constexpr double kTolerance = 1e-9;
  const double begin = odometry.start_time, end = odometry.steps.back().time;
  // The frames are in time order, so the first one outside is the first or the last frame.
  const slam::ObservationFrame* outside = nullptr;
  if (frames.back().time > end + kTolerance) outside = &frames.back();
  if (frames.front().time < begin - kTolerance) outside = &frames.front();
  if (outside) {
    const Diagnostic where{
        .file = o.observations, .line = outside->line, .col = outside->col, .message = {}};
    throw UserError(fmt::format(
        "{}: observations at t = {} s, but the odometry in {} covers only {} to {} s (the "
        "observations span {} to {} s)",
        where.Location(), outside->time, o.odometry, begin, end, frames.front().time,
        frames.back().time));
  }
  if (o.association == "ids") {
    for (const slam::ObservationFrame& frame : frames) {
      for (const slam::RangeBearing& z : frame.observations) {
        if (z.id < 0) {
          throw UserError(fmt::format(
              "{}: the observations have no landmark ids (-1 or empty); use --association nearest",
              o.observations));
        }
      }
    }
  }
}

void PrintRun(const slam::SlamResult& r, double seconds) {
  std::size_t flagged = 0;
  for (const slam::RelationRecord& relation : r.relations) flagged += relation.flagged ? 1 : 0;
  fmt::print("{}: {} created ({} in the state at the end), {} in the state\n",
             Plural(r.frames.size(), "frame"), Plural(r.landmarks_created, "landmark"),
             r.landmarks.size(), Plural(r.segments.size(), "segment"));
  if (!r.same_walls.empty()) {
    std::size_t merged = 0;
    for (const std::vector<int>& group : r.same_walls) merged += group.size();
    fmt::print(
        "{} of the prior map filtered as {} (the same wall more than once, or one wall in "
        "parts; each named by its first segment)\n",
        Plural(merged, "segment"), Plural(r.same_walls.size(), "wall"));
  }
  fmt::print("{} applied ({} flagged), {}, {} rejected updates\n",
             Plural(r.relations.size(), "relation"), flagged,
             fmt::format("{} association hypotheses", r.inference.hypotheses), r.rejected_updates);
  if (!r.frames.empty()) {
    const Se2& end = r.frames.back().estimate;
    fmt::print("final pose {:.3f}, {:.3f}, {:.4f} (t = {} s); wall time {:.2f} s\n", end.x(),
               end.y(), end.theta(), r.frames.back().time, seconds);
  }
}

void RunOnFiles(const RunOptions& o) {
  // Every check before the first write, so that a failure leaves nothing behind.
  if (!o.prior_map && !o.no_prior)
    throw UsageError("--prior-map is required (or --no-prior to filter without a prior map)");
  RequireOutputDirectoryPath(o.out, "--out");
  slam::SlamInput input;
  input.initial_pose = ParseInitialPose(o.initial_pose);
  input.motion_noise = o.motion;
  input.motion_noise.steer_std = DegToRad(o.steer_std_deg);
  if (!o.increment_std.empty())
    input.motion_noise.increment_std = ParseIncrementStd(o.increment_std);
  input.sensor_noise = o.sensor;
  input.sensor_noise.bearing_std = DegToRad(o.bearing_std_deg);
  // The three files' problems together, so that one attempt shows them all.
  Result<std::vector<slam::ObservationFrame>> read_frames =
      slam::ReadObservationsCsv(o.observations);
  Result<slam::Odometry> read_odometry = slam::ReadOdometryCsv(o.odometry);
  std::optional<Result<slam::PriorMap>> read_map;
  if (o.prior_map) read_map = slam::ReadPriorMapGeoJson(*o.prior_map, o.prior_std);
  std::vector<Diagnostic> problems = read_frames.diagnostics();
  problems.insert(problems.end(), read_odometry.diagnostics().begin(),
                  read_odometry.diagnostics().end());
  if (read_map)
    problems.insert(problems.end(), read_map->diagnostics().begin(), read_map->diagnostics().end());
  // Each row is within the world's bound; where they take the vehicle together, from the start
  // pose, must be too (at the row that first leaves it).
  std::optional<Diagnostic> beyond;
  if (read_odometry) {
    beyond = slam::FirstPoseBeyondWorld(input.initial_pose, read_odometry.value(),
                                        input.motion_noise.wheelbase, o.odometry);
    if (beyond) problems.push_back(*beyond);
  }
  if (!read_frames || !read_odometry || (read_map && !*read_map) || beyond)
    throw UserError(DescribeDiagnostics(problems));
  std::vector<slam::ObservationFrame> frames = std::move(read_frames).value();
  slam::Odometry odometry = std::move(read_odometry).value();
  std::optional<slam::PriorMap> prior_map;
  if (read_map) prior_map = std::move(*read_map).value();
  CheckInputs(o, frames, odometry);
  input.start_time = odometry.start_time;
  input.motion = std::move(odometry.steps);
  input.frames = std::move(frames);

  slam::SlamOptions options = o.slam;
  options.use_prior_map = !o.no_prior;
  options.association = o.association == "ids" ? slam::AssociationMode::kKnownIds
                                               : slam::AssociationMode::kNearestNeighbour;
  const std::optional<tbb::global_control> threads = LimitThreads(o.threads);
  const auto start = std::chrono::steady_clock::now();
  const slam::SlamResult result =
      slam::RunSlam(input, o.no_prior || !prior_map ? nullptr : &*prior_map, options);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  const fs::path out = o.out;
  EnsureDirectory(out);
  slam::WriteSlamRunOutputs(result,
                            {.observations = o.observations,
                             .odometry = o.odometry,
                             .prior_map = o.prior_map.value_or(""),
                             .prior_segments = prior_map ? prior_map->segments.size() : 0,
                             .options = options,
                             .wall_time_s = seconds},
                            out);
  if (!o.no_figures) {
    SaveFigure(render::SlamRunMapFigure(
                   result, prior_map ? &*prior_map : nullptr,
                   {.title = fmt::format("{}: {}", o.observations,
                                         o.no_prior ? "without prior map" : "with prior map")}),
               out / "map");
  } else {
    RemoveFigure(out / "map");
  }
  PrintRun(result, seconds);
  fmt::print("wrote {} (summary.json, trajectory.csv, map.geojson, relations.csv{})\n", o.out,
             o.no_figures ? "" : ", map.png, map.svg");
}

void AddSimulate(CLI::App& slam_cmd) {
  auto o = std::make_shared<SimulateOptions>();
  CLI::App* cmd = slam_cmd.add_subcommand(
      "simulate",
      "Monte Carlo study on a simulated city (Sec. VI): runs with and without the prior map, "
      "errors, consistency, relations, figures");
  cmd->add_option("--runs", o->runs, "Monte Carlo runs")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  cmd->add_option("--seed", o->seed, "Random seed; the same seed gives the same results")
      ->transform(SeedValue())
      ->capture_default_str();
  cmd->add_option("-o,--out", o->out, "Output directory (created)")->required();
  cmd->add_option("--threads", o->threads, "At most this many threads (default: all cores)")
      ->check(CLI::Range(1, 4096));
  cmd->add_flag("--no-figures", o->no_figures, "Only the tables, no figures");
  cmd->add_option("--export-inputs", o->export_inputs,
                  "Also write run 0's data as input files of 'slam run' into this directory");
  cmd->add_option("--prior-std", o->prior_std, "Endpoint noise of the simulated prior map, m")
      ->check(PositiveValueUpTo(slam::kMaxPriorStd, "m"))
      ->capture_default_str();
  cmd->add_option("--window", o->window, "Drop landmarks not seen for this long, s (0: keep all)")
      ->check(NonNegativeValue())
      ->capture_default_str();
  AddAlgorithmOptions(cmd, o->slam);
  cmd->callback([o] { Simulate(*o); });
}

void AddRun(CLI::App& slam_cmd) {
  auto o = std::make_shared<RunOptions>();
  CLI::App* cmd = slam_cmd.add_subcommand(
      "run", "EKF-SLAM with a prior map on your files (observations, odometry, GeoJSON map)");
  cmd->add_option("--observations", o->observations, "Observations CSV: time,id,range,bearing")
      ->required();
  cmd->add_option("--odometry", o->odometry,
                  "Odometry CSV: time,speed,steer or time,dx,dy,dtheta[,sx,sy,stheta]")
      ->required();
  cmd->add_option("--prior-map", o->prior_map,
                  "Prior map: GeoJSON of wall segments (metres); required unless --no-prior");
  cmd->add_option("-o,--out", o->out, "Output directory (created)")->required();
  cmd->add_option("--prior-std", o->prior_std,
                  "Endpoint 1-sigma of the prior map where the GeoJSON gives none, m")
      ->check(PositiveValueUpTo(slam::kMaxPriorStd, "m"))
      ->capture_default_str();
  cmd->add_option("--initial-pose", o->initial_pose, "Start pose x,y,theta (m, m, rad), known")
      ->check(ParsedBy("--initial-pose", ParseInitialPose))
      ->capture_default_str();
  cmd->add_option("--association", o->association,
                  "ids: the observations' landmark ids; nearest: nearest compatible landmark")
      ->check(CLI::IsMember({"ids", "nearest"}))
      ->capture_default_str();
  cmd->add_option("--window", o->slam.window_s,
                  "Drop landmarks not seen for this long, s (0: keep all)")
      ->check(NonNegativeValue())
      ->capture_default_str();
  cmd->add_flag("--no-prior", o->no_prior, "Plain EKF-SLAM, without the prior map");
  cmd->add_flag("--no-figures", o->no_figures, "No map figure");
  cmd->add_option("--threads", o->threads, "At most this many threads")->check(CLI::Range(1, 4096));
  const char* noise = "Noise models";
  cmd->add_option("--range-std", o->sensor.range_std, "Range 1-sigma, m")
      ->check(PositiveValue())
      ->capture_default_str()
      ->group(noise);
  cmd->add_option("--bearing-std", o->bearing_std_deg, "Bearing 1-sigma, degrees")
      ->check(PositiveValue())
      ->capture_default_str()
      ->group(noise);
  cmd->add_option("--speed-std", o->motion.speed_std, "Bicycle odometry: speed 1-sigma, m/s")
      ->check(PositiveValue())
      ->capture_default_str()
      ->group(noise);
  cmd->add_option("--steer-std", o->steer_std_deg, "Bicycle odometry: steering 1-sigma, degrees")
      ->check(PositiveValue())
      ->capture_default_str()
      ->group(noise);
  cmd->add_option("--wheelbase", o->motion.wheelbase, "Bicycle odometry: wheelbase, m")
      ->check(PositiveValue())
      ->capture_default_str()
      ->group(noise);
  cmd->add_option("--increment-std", o->increment_std,
                  "Increment odometry without its own: 1-sigma sx,sy,stheta (m, m, rad); "
                  "default 0.05,0.05,0.005")
      ->check(ParsedBy("--increment-std", ParseIncrementStd))
      ->group(noise);
  cmd->add_option("--max-range", o->slam.max_range,
                  "Nearest-neighbour association: landmarks this near are candidates, m")
      ->check(PositiveValue())
      ->capture_default_str()
      ->group("Advanced (association)");
  cmd->add_option("--nn-gate-chi2", o->slam.nn_gate_chi2,
                  "Nearest-neighbour association: accept below this (chi2, 2 dof)")
      ->check(PositiveValue())
      ->capture_default_str()
      ->group("Advanced (association)");
  cmd->add_option("--nn-new-landmark-chi2", o->slam.nn_new_landmark_chi2,
                  "Nearest-neighbour association: a new landmark only above this from all")
      ->check(PositiveValue())
      ->capture_default_str()
      ->group("Advanced (association)");
  AddAlgorithmOptions(cmd, o->slam);
  cmd->callback([o] { RunOnFiles(*o); });
}

}  // namespace

void AddSlamCommand(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand(
      "slam", "EKF-SLAM with a prior map of walls (Parsley & Julier): simulate | run");
  cmd->require_subcommand(1);
  AddSimulate(*cmd);
  AddRun(*cmd);
}

}  // namespace priormap::app
