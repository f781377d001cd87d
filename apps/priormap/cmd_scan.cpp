// priormap scan: the MAP scan under a prior (priorlets engine) for one scan or every scan of a log.
#include <atomic>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <tuple>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <tbb/parallel_for.h>

#include <priormap/core/file_io.hpp>
#include <priormap/core/log_io.hpp>
#include <priormap/dsl/prior_library.hpp>
#include <priormap/priorlets/engine.hpp>
#include <priormap/priorlets/line_segments.hpp>
#include <priormap/priorlets/map_scan_json.hpp>
#include <priormap/priorlets/posterior.hpp>
#include <priormap/render/map_scan_figure.hpp>

#include "cli_support.hpp"
#include "commands.hpp"

namespace priormap::app {
namespace {

struct ScanOptions {
  std::string prior;
  std::vector<std::string> prior_path;
  std::string input;
  std::optional<std::size_t> index;
  bool all = false;
  std::string out;
  double beta = priorlets::EngineOptions{}.beta;
  bool no_refine = false;
  std::optional<double> max_range;
  std::string covariance = "conditional";
  int eigenvariations = priorlets::PosteriorOptions{}.eigenvariations;
  std::size_t max_free_dimension = priorlets::PosteriorOptions{}.max_free_dimension;
  std::optional<std::string> png;
  std::optional<std::string> svg;
  std::optional<std::string> lines;
};

// --png / --svg: each names a file of its own format, written only for one scan.
void CheckFigureOptions(const ScanOptions& o) {
  for (const auto& [file, option, extension] :
       {std::tuple(o.png, "--png", ".png"), std::tuple(o.svg, "--svg", ".svg")}) {
    if (!file) continue;
    if (o.all) {
      throw UserError(fmt::format("{} draws one scan, not --all (choose it with --index)", option));
    }
    if (std::filesystem::path(*file).extension().string() != extension) {
      throw UserError(fmt::format("{}: '{}' must end in {}", option, *file, extension));
    }
    RequireOutputDirectory(*file, option);
  }
}

// The figure of the MAP scan and its posterior, in each requested format.
void WriteFigures(const ScanOptions& o, const Scan& scan, const priorlets::MapScan& map,
                  const priorlets::Posterior& posterior, const std::string& title) {
  if (!o.png && !o.svg) return;
  const render::MapScanFigure figure(scan, map, posterior, {.title = title});
  for (const std::optional<std::string>& file : {o.png, o.svg}) {
    if (!file) continue;
    figure.Save(*file);
    fmt::print("wrote {}\n", *file);
  }
}

void Run(const ScanOptions& o) {
  CheckFigureOptions(o);
  if (o.lines) {
    if (o.all) throw UserError("--lines writes one scan's segments, not --all (use --index)");
    RequireOutputDirectory(*o.lines, "--lines");
  }
  RequireOutputDirectory(o.out, "--out");
  RequireDistinctFiles({{"-i/--log", o.input},
                        {"-o/--out", o.out},
                        {"--lines", o.lines.value_or("")},
                        {"--png", o.png.value_or("")},
                        {"--svg", o.svg.value_or("")}});
  const dsl::CompiledPrior prior = ValueOrThrow(MakePriorLibrary(o.prior_path).Load(o.prior));
  CarmenReadOptions carmen;
  carmen.max_range = o.max_range;
  LogFormat read_as{};
  const Log log = ValueOrThrow(ReadLog(o.input, std::nullopt, carmen, &read_as));
  RequireCarmenForMaxRange(o.input, read_as, o.max_range);
  if (log.scans.empty()) throw UserError(fmt::format("{}: the log has no scans", o.input));
  if (o.all && o.index) throw UserError("--all and --index exclude each other");
  const std::size_t index = o.index.value_or(0);
  if (index >= log.scans.size()) {
    throw UserError(
        fmt::format("--index {}: {} has {}", index, o.input, Plural(log.scans.size(), "scan")));
  }
  priorlets::EngineOptions engine;
  engine.beta = o.beta;
  engine.refine_borders = !o.no_refine;
  // Sec. IV; the m x m range covariance only for the figure (it is not written to JSON).
  priorlets::PosteriorOptions posterior_options;
  posterior_options.form = o.covariance == "projected" ? priorlets::CovarianceForm::kProjected
                                                       : priorlets::CovarianceForm::kConditional;
  posterior_options.eigenvariations = o.eigenvariations;
  posterior_options.max_free_dimension = o.max_free_dimension;
  // The range covariance for the figure and for the segments' covariances.
  posterior_options.keep_range_covariance = o.png || o.svg || o.lines;
  struct Estimate {
    priorlets::MapScan map;
    priorlets::Posterior posterior;
    std::string json;
  };
  const auto estimate = [&](std::size_t k) {
    const Scan& scan = log.scans[k];
    if (const std::vector<std::string> problems = scan.Problems(); !problems.empty()) {
      throw UserError(fmt::format("scan {}: {}", k, problems.front()));
    }
    // A priorlet relates neighbouring beams of one scan from one origin; a ring's cones leave
    // their transducers, a few bearings apart.
    if (scan.sonar) throw UserError("a sonar ring: priorlets take laser scans");
    Estimate e;
    e.map = priorlets::EstimateMapScan(scan, prior, engine);
    e.posterior = priorlets::AnalysePosterior(scan, prior, e.map, posterior_options);
    e.json = priorlets::MapScanToJson(e.map, {k, prior.name(), o.input}, &e.posterior);
    return e;
  };
  if (!o.all) {
    const Estimate e = estimate(index);
    WriteTextFileAtomically(o.out, e.json + "\n");
    fmt::print("wrote {}\n", o.out);
    if (o.lines) {
      const priorlets::LineSegments lines =
          priorlets::ExtractLineSegments(log.scans[index], e.map, &e.posterior);
      WriteTextFileAtomically(
          *o.lines,
          priorlets::LineSegmentsToJson(lines, "laser", log.scans[index].timestamp) + "\n");
      fmt::print("wrote {} ({} line segments)\n", *o.lines, lines.segments.size());
    }
    WriteFigures(o, log.scans[index], e.map, e.posterior,
                 fmt::format("{}: scan {}, {}", o.input, index, prior.name()));
    return;
  }
  // Every scan, in parallel; a scan that fails is reported and written as an error record.
  std::vector<std::string> lines(log.scans.size());
  std::atomic<std::size_t> failures{0};
  Progress progress(log.scans.size(), "scans");
  std::mutex report;
  tbb::parallel_for(std::size_t{0}, log.scans.size(), [&](std::size_t k) {
    try {
      lines[k] = estimate(k).json;
    } catch (const std::exception& e) {
      ++failures;
      lines[k] = nlohmann::json{
          {"format", "priormap.map_scan"},
          {"version", 1},
          {"scan_index", k},
          {"error",
           e.what()}}.dump();
      std::lock_guard lock(report);
      fmt::print(stderr, "\npriormap: scan {}: {}\n", k, e.what());
    }
    progress.Step();
  });
  std::string text;
  for (const std::string& line : lines) text += line + "\n";
  WriteTextFileAtomically(o.out, text);
  fmt::print("wrote {} ({}{})\n", o.out, Plural(lines.size(), "scan"),
             failures ? fmt::format(", {} failed", failures.load()) : std::string());
  // The file holds every scan's record, the failed ones' errors too; the exit status says that
  // not every scan was estimated.
  if (failures > 0)
    throw UserError(fmt::format("{} of {} failed; their records in {} say why", failures.load(),
                                Plural(lines.size(), "scan"), o.out));
}

}  // namespace

void AddScanCommand(CLI::App& app) {
  auto o = std::make_shared<ScanOptions>();
  CLI::App* cmd = app.add_subcommand(
      "scan", "MAP scan under a prior: corrected ranges and normals, regions, outliers");
  cmd->add_option("--prior", o->prior,
                  "Prior: a built-in name (see 'priormap prior list') or a .prior file")
      ->required();
  cmd->add_option("--prior-path", o->prior_path,
                  "Directories searched for priors named by 'specializes:'")
      ->check(CLI::ExistingDirectory);
  cmd->add_option("-i,--input,--log", o->input, "Scan or log: priormap JSON or CARMEN (.gz too)")
      ->required();
  cmd->add_option("--index", o->index, "Which scan of the log (0-based; default 0)")
      ->transform(IndexValue());
  cmd->add_flag("--all", o->all, "Every scan of the log, in parallel, as JSON Lines");
  cmd->add_option("-o,--out", o->out, "Output JSON (JSON Lines with --all)")->required();
  cmd->add_option("--beta", o->beta, "Prior probability that a reading fits the prior")
      ->check(CLI::Range(1e-6, 1.0 - 1e-6))
      ->capture_default_str();
  cmd->add_flag("--no-refine", o->no_refine, "Keep the greedy topology (no border refinement)");
  cmd->add_option("--max-range", o->max_range,
                  "CARMEN input: readings at or above this are max-range")
      ->check(PositiveValue());
  cmd->add_option("--covariance", o->covariance,
                  "Posterior covariance restricted to Free: 'conditional' N (N^T A N)^-1 N^T, or "
                  "the paper's 'projected' P A^-1 P^T (docs/formats.md)")
      ->check(CLI::IsMember({"conditional", "projected"}))
      ->capture_default_str();
  cmd->add_option("--eigenvariations", o->eigenvariations, "Scan eigenvariations reported")
      ->check(CLI::Range(0, 1000))
      ->capture_default_str();
  cmd->add_option("--max-free-dimension", o->max_free_dimension,
                  "Above this dim(Free) no covariance matrix or eigenvariations (cost O(dim^3))")
      ->transform(WholeNumber(100000, "a dimension"))
      ->capture_default_str();
  cmd->add_option("--png", o->png,
                  "One scan: a figure of the MAP scan, its normals, eigenvariations and "
                  "posterior covariance (PNG)");
  cmd->add_option("--svg", o->svg, "The same figure as SVG");
  cmd->add_option("--lines", o->lines,
                  "One scan: the straight regions as line segments, JSON in the convention of ROS "
                  "laser_line_extraction (polar line, covariance, endpoints; docs/formats.md)");
  cmd->callback([o] { Run(*o); });
}

}  // namespace priormap::app
