// priormap demo: every engine on embedded simulated data (and on real logs when they are at hand),
// run as the very `priormap` commands a user would type, into a gallery page with their figures,
// key numbers and command lines.
#include <chrono>
#include <optional>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <priormap/core/file_io.hpp>
#include <priormap/core/log_io.hpp>

#include "cli_support.hpp"
#include "commands.hpp"
#include "demo_gallery.hpp"
#include "in_process.hpp"

namespace priormap::app {
namespace {

namespace fs = std::filesystem;
using Args = std::vector<std::string>;

struct DemoOptions {
  std::string out = "demo";
  std::uint64_t seed = 1;
  std::optional<std::string> data;  // ../shared/data when present
  bool no_real = false;
  bool quick = false;  // shorter chains, for tests
};

GalleryEntry Titled(std::string title) {
  GalleryEntry entry;
  entry.title = std::move(title);
  return entry;
}

nlohmann::json ReadJson(const fs::path& path) {
  const std::string text = ValueOrThrow(ReadFileText(path));
  return nlohmann::json::parse(text);
}

// Runs the commands of one gallery entry, showing progress on the terminal.
class Steps {
 public:
  Steps(const fs::path& dir, const DemoOptions& o)
      : dir_(dir), runner_(dir / "demo.log"), seed_(fmt::format("{}", o.seed)) {}

  /// `dir`/relative, as it appears in the commands.
  [[nodiscard]] std::string Path(const std::string& relative) const {
    return (dir_ / relative).string();
  }
  [[nodiscard]] const std::string& seed() const { return seed_; }

  void Run(GalleryEntry* entry, const Args& args) {
    const std::string line = InProcessRunner::CommandLine(args);
    fmt::print("  {}\n", line);
    std::fflush(stdout);
    entry->seconds += runner_.Run(args);
    entry->commands.push_back(line);
  }

 private:
  fs::path dir_;
  InProcessRunner runner_;
  std::string seed_;
};

// The gallery's lines on a MAP scan (`map`, priormap scan's JSON) of a scan with `valid` valid
// readings.
std::vector<std::string> MapScanNumbers(const nlohmann::json& map, std::size_t valid) {
  // Outliers among the valid readings (beams with no return are not in the model either).
  const std::size_t in_model = map.at("inmodel_beams").size();
  const auto& dof = map.at("dof");
  return {fmt::format("{} readings, {} valid: {}, {}, {}", map.at("inmodel").size(), valid,
                      Plural(map.at("regions").size(), "region"),
                      Plural(map.at("surfaces").size(), "surface"),
                      Plural(valid - in_model, "outlier")),
          fmt::format("degrees of freedom: {} free = {} extrinsic + {} intrinsic",
                      dof.at("free").get<int>(), dof.at("extrinsic").get<int>(),
                      dof.at("intrinsic").get<int>()),
          fmt::format("MAP solve {:.2f} s", map.at("stats").at("seconds").get<double>())};
}

GalleryEntry PriorletScan(Steps& s, const std::string& scene, const std::string& prior,
                          const std::string& outliers) {
  GalleryEntry e = Titled(fmt::format("{} scene, {} prior", scene, prior));
  const std::string scan = s.Path(fmt::format("data/{}-utm30.json", scene));
  const std::string stem = fmt::format("priorlets/{}-{}", scene, prior);
  s.Run(&e, {"simulate", "--scene", scene, "--sensor", "utm30", "--outliers", outliers, "--seed",
             s.seed(), "-o", scan});
  s.Run(&e, {"scan", "--prior", prior, "-i", scan, "-o", s.Path(stem + ".json"), "--png",
             s.Path(stem + ".png")});
  e.numbers = MapScanNumbers(ReadJson(s.Path(stem + ".json")),
                             ValueOrThrowQuietly(ReadLog(scan)).scans.front().NumValid());
  e.figures = {{stem + ".png",
                "(a) measured and corrected scan with regions, surface borders and outliers; "
                "(b) normals; (c) intrinsic eigenvariations; (d) prior vs posterior range "
                "deviation; (e) posterior covariance"}};
  return e;
}

GalleryEntry SlamStudy(Steps& s, const DemoOptions& o) {
  GalleryEntry e = Titled("Monte Carlo study on the simulated city");
  s.Run(&e, {"slam", "simulate", "--runs", o.quick ? "5" : "30", "--seed", s.seed(), "-o",
             s.Path("slam")});
  const nlohmann::json j = ReadJson(s.Path("slam/summary.json"));
  const auto& with = j.at("with_prior");
  const auto& without = j.at("without_prior");
  e.numbers = {
      fmt::format(
          "RMS position error: {:.2f} m with the prior map, {:.2f} m without (ratio {:.2f})",
          with.at("rms_position_m").get<double>(), without.at("rms_position_m").get<double>(),
          j.at("rms_position_ratio").get<double>()),
      fmt::format("mean NEES {:.2f} with, {:.2f} without (3 degrees of freedom)",
                  with.at("mean_nees").get<double>(), without.at("mean_nees").get<double>()),
      fmt::format("relations: {} correct, {} incorrect",
                  j.at("constraints").at("correct").get<int>(),
                  j.at("constraints").at("incorrect").get<int>())};
  e.figures = {
      {"slam/figures/pose_error.png", "Position error over time, with and without the prior map"},
      {"slam/figures/nees.png", "NEES over time against its 95 % band"},
      {"slam/figures/map.png", "The prior map, the true and estimated landmarks"},
      {"slam/figures/relations.png", "Landmark-to-wall relations found"}};
  return e;
}

// R-hat is null in a summary when the chains were too short to split.
std::string Rhat(const nlohmann::json& value) {
  return value.is_number() ? fmt::format("{:.3f}", value.get<double>()) : "n/a (chains too short)";
}

std::vector<std::string> PrfNumbers(const fs::path& prf_dir, const fs::path& grid_dir) {
  const nlohmann::json p = ReadJson(prf_dir / "summary.json");
  const nlohmann::json g = ReadJson(grid_dir / "summary.json");
  std::vector<std::string> numbers = {
      fmt::format("{} {} readings; {} chains, {:.0f} k proposals/s in all",
                  p.at("beams").get<std::size_t>(), p.at("sensor").get<std::string>(),
                  p.at("chains").get<int>(), p.at("proposals_per_second").get<double>() / 1e3),
      fmt::format("split-R̂: {} on the log-posterior, {} on point colours",
                  Rhat(p.at("rhat").at("log_posterior")), Rhat(p.at("rhat").at("point_colours")))};
  if (p.contains("map"))
    numbers.push_back(fmt::format(
        "MAP polygon map: {} edges, {} bytes compact ({} B GeoJSON) vs the grid's {} B",
        p.at("map").at("edges").get<int>(), p.at("map").at("compact_bytes").get<std::size_t>(),
        p.at("map").at("geojson_bytes").get<std::size_t>(), g.at("grid_bytes").get<std::size_t>()));
  return numbers;
}

GalleryEntry PrfOnLog(Steps& s, GalleryEntry e, const std::string& log, const std::string& dir,
                      const Args& log_options, const std::string& steps, bool anneal,
                      const Args& prf_options = {}) {
  Args grid = {"grid", "--log", log};
  grid.insert(grid.end(), log_options.begin(), log_options.end());
  grid.insert(grid.end(), {"-o", s.Path(dir + "/grid")});
  s.Run(&e, grid);
  Args prf = {"prf", "--log", log};
  prf.insert(prf.end(), log_options.begin(), log_options.end());
  prf.insert(prf.end(), prf_options.begin(), prf_options.end());
  prf.insert(prf.end(), {"--p", "0.1", "--samples", steps, "--burn-in", steps, "--chains", "2",
                         "--seed", s.seed()});
  if (anneal) prf.insert(prf.end(), {"--anneal"});
  prf.insert(prf.end(), {"-o", s.Path(dir + "/prf")});
  s.Run(&e, prf);
  e.numbers = PrfNumbers(s.Path(dir + "/prf"), s.Path(dir + "/grid"));
  e.figures = {{dir + "/grid/grid.png", "Occupancy grid (log-odds, inverse sensor model)"},
               {dir + "/prf/posterior.png", "PRF posterior P(black)"}};
  if (anneal) e.figures.push_back({dir + "/prf/map.png", "PRF MAP polygon map (annealed)"});
  return e;
}

// A log simulated along a scene's waypoints, then the grid and the PRF on it.
GalleryEntry SimulatedPrf(Steps& s, const std::string& title, const std::string& scene,
                          const std::string& sensor, const std::string& dir,
                          const Args& log_options, const std::string& steps, bool anneal) {
  GalleryEntry e = Titled(title);
  const std::string log = s.Path(fmt::format("data/{}-{}.json", scene, sensor));
  s.Run(&e,
        {"simulate", "--scene", scene, "--sensor", sensor, "--log", "--seed", s.seed(), "-o", log});
  return PrfOnLog(s, std::move(e), log, dir, log_options, steps, anneal);
}

// The sonar PRF as docs/prf.md runs it: a sonar model fitted to rings simulated with another
// seed (about a second), the free-space and orientation priors, a tempered start.
GalleryEntry SonarPrf(Steps& s, const std::string& steps) {
  GalleryEntry e = Titled("Sonar: a pioneer16 ring along the office corridor");
  const std::string model = s.Path("data/sonar-model.json");
  s.Run(&e, {"prf", "fit-sonar", "--seed", "1000", "-o", model});
  const std::string log = s.Path("data/office-pioneer16.json");
  s.Run(&e, {"simulate", "--scene", "office", "--sensor", "pioneer16", "--log", "--seed", s.seed(),
             "-o", log});
  return PrfOnLog(s, std::move(e), log, "prf-sonar", {}, steps, false,
                  {"--sonar-model", model, "--free-space", "1", "--orientation-weight", "1",
                   "--burn-in-temperature", "5"});
}

std::optional<fs::path> RealDataDir(const DemoOptions& o) {
  if (o.no_real) return std::nullopt;
  if (o.data) {
    if (!fs::is_directory(*o.data))
      throw UserError(fmt::format("--data {}: no such directory", *o.data));
    return fs::path(*o.data);
  }
  const fs::path shared = "../shared/data";
  if (fs::is_directory(shared)) return shared;
  return std::nullopt;
}

void Run(const DemoOptions& o) {
  const auto start = std::chrono::steady_clock::now();
  const fs::path dir = o.out;
  if (o.out.empty()) throw UsageError("-o/--out: an empty directory name");
  const std::optional<fs::path> data = RealDataDir(o);  // before any work: a typo fails at once
  for (const char* sub : {"data", "priorlets"}) EnsureDirectory(dir / sub);
  // An earlier gallery's real log, which this one may not show: the demo's own directory.
  std::error_code ignored;
  fs::remove_all(dir / "real", ignored);
  fs::remove(dir / "demo.log");
  Steps s(dir, o);
  // Chain lengths that keep the whole demo near a minute on two cores.
  const std::string laser_steps = o.quick ? "20000" : "300000";
  const std::string sonar_steps = o.quick ? "10000" : "150000";
  const std::string real_steps = o.quick ? "20000" : "1000000";
  std::vector<GallerySection> sections;

  fmt::print("priormap demo: priorlets\n");
  sections.push_back(
      {.heading = "Priorlets: one scan + an environment prior",
       .intro = "A noisy simulated laser scan and a prior written in the prior language give the "
                "MAP ranges and normals, the segmentation into regions and surfaces, the outliers, "
                "the scan's degrees of freedom and the shrunk posterior covariance.",
       .entries = {PriorletScan(s, "l-room", "rectangular", "0.02"),
                   PriorletScan(s, "two-circles", "circular", "0.02")}});

  fmt::print("priormap demo: SLAM with a prior map\n");
  sections.push_back(
      {.heading = "SLAM with a heterogeneous prior map",
       .intro = "EKF-SLAM of point landmarks that decides which landmarks lie on which walls of a "
                "noisy, partly wrong building map and applies those relations as "
                "pseudo-observations; runs with and without the map.",
       .entries = {SlamStudy(s, o)}});

  fmt::print("priormap demo: polygonal random fields\n");
  // Every 8th beam: the PRF extrapolates walls between beams, and mixes faster on fewer.
  GalleryEntry laser =
      SimulatedPrf(s, "Laser: a localized lms200 log in the l-room scene", "l-room", "lms200",
                   "prf-laser", {"--beam-step", "8"}, laser_steps, true);
  GalleryEntry sonar = SonarPrf(s, sonar_steps);
  sections.push_back(
      {.heading = "Polygonal random fields vs the occupancy grid",
       .intro = "MCMC over polygonal maps (Arak prior, Clifford-Nicholls moves) from localized "
                "range data, next to the log-odds occupancy grid built from the same readings.",
       .entries = {std::move(laser), std::move(sonar)}});

  std::string data_note = o.no_real
                              ? "no real logs (--no-real)"
                              : "no real logs (none given with --data, ../shared/data absent)";
  if (data) {
    const fs::path intel = *data / "laser-corrected/intel-corrected.log.gz";
    if (fs::exists(intel)) {
      fmt::print("priormap demo: a real log ({})\n", intel.string());
      GalleryEntry scan = Titled("Intel lab, scan 100, polygonal prior");
      EnsureDirectory(dir / "real");
      s.Run(&scan,
            {"scan", "--prior", "polygonal", "--log", intel.string(), "--index", "100", "-o",
             s.Path("real/intel-scan-100.json"), "--png", s.Path("real/intel-scan-100.png")});
      // `scan` gave the log's warnings in demo.log.
      const Log intel_log = ValueOrThrowQuietly(ReadLog(intel));
      scan.numbers = MapScanNumbers(ReadJson(s.Path("real/intel-scan-100.json")),
                                    intel_log.scans.at(100).NumValid());
      scan.figures = {
          {"real/intel-scan-100.png", "A real scan of the Intel lab under the polygonal prior"}};
      GalleryEntry prf = PrfOnLog(
          s, Titled("Intel lab, the first 185 scans, every 6th beam (5,550 beams)"), intel.string(),
          "real/intel", {"--range", "0:185", "--beam-step", "6", "--resolution", "0.1"}, real_steps,
          true);
      sections.push_back({.heading = "A real log",
                          .intro = "The Intel Research Lab log (SLAM-corrected poses) from " +
                                   data->string() + ".",
                          .entries = {std::move(scan), std::move(prf)}});
      data_note = "real logs from " + data->string();
    } else {
      data_note = fmt::format("{} has no laser-corrected/intel-corrected.log.gz", data->string());
    }
  }

  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // The options that change the numbers, so that a reader can make the same gallery.
  std::string command = fmt::format("priormap demo --seed {}", o.seed);
  if (o.quick) command += " --quick";
  if (o.no_real) command += " --no-real";
  if (o.data) command += " --data " + *o.data;
  WriteGallery(dir / "index.html", sections,
               fmt::format("Made by {} in {:.0f} s; {}. The output of every command is in "
                           "demo.log.",
                           command, seconds, data_note));
  fmt::print("priormap demo: wrote {} in {:.1f} s ({}); every command's output is in {}\n",
             (dir / "index.html").string(), seconds, data_note, (dir / "demo.log").string());
}

}  // namespace

void AddDemoCommand(CLI::App& app) {
  auto o = std::make_shared<DemoOptions>();
  CLI::App* cmd = app.add_subcommand(
      "demo",
      "Run every engine on embedded simulated data (and a real log when at hand) and write a "
      "gallery, OUT/index.html");
  cmd->add_option("-o,--out", o->out, "Output directory")->capture_default_str();
  cmd->add_option("--seed", o->seed, "Random seed; the same seed gives the same gallery")
      ->transform(SeedValue())
      ->capture_default_str();
  cmd->add_option("--data", o->data,
                  "Directory of real logs (like ../shared/data, which is used when present)");
  cmd->add_flag("--no-real", o->no_real, "Only the simulated data");
  cmd->add_flag("--quick", o->quick, "Short chains and few runs (a smoke test, seconds)");
  cmd->callback([o] { Run(*o); });
}

}  // namespace priormap::app
