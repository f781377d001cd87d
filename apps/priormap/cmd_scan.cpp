// priormap scan: the MAP scan under a prior (priorlets engine) for one scan or every scan of a log.
#include <cstdio>
#include <filesystem>
#include <functional>
#include <mutex>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <tbb/parallel_for.h>

#include <priormap/core/binary_io.hpp>
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
#include "graceful_stop.hpp"
#include "scan_journal.hpp"

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
  bool open_full_turn = false;
  std::optional<double> max_range;
  std::string covariance = "conditional";
  int eigenvariations = priorlets::PosteriorOptions{}.eigenvariations;
  std::size_t max_free_dimension = priorlets::PosteriorOptions{}.max_free_dimension;
  std::optional<std::string> png;
  std::optional<std::string> svg;
  std::optional<std::string> lines;
  bool resume = false;
};

// What a scan's record depends on: the prior's files, the options and the log's bytes. A
// journal of another run is refused on resume.
std::uint64_t AllScansFingerprint(const ScanOptions& o, const dsl::CompiledPrior& prior) {
  std::string identity =
      fmt::format("priormap {}\n{}\n{}\n{}\n{}\n{}\n{}\n{}\n", PRIORMAP_VERSION, o.prior, o.input,
                  o.beta, o.no_refine, o.max_range.value_or(-1.0), o.covariance, o.eigenvariations);
  identity += fmt::format("{}\n{}\n", o.max_free_dimension, o.open_full_turn);
  for (const dsl::PriorOrigin& origin : prior.chain()) {
    identity += origin.name + "\n" + origin.path + "\n";
    if (const Result<std::string> text = ReadFileText(origin.path); text.ok())
      identity += text.value();
  }
  const std::string log_bytes = ValueOrThrow(ReadFileText(o.input));
  return Fnv1a64(log_bytes, Fnv1a64(identity));
}

// --png / --svg: written only for one scan (each one's extension is its option's own check).
void CheckFigureOptions(const ScanOptions& o) {
  for (const auto& [file, option] : {std::pair(o.png, "--png"), std::pair(o.svg, "--svg")}) {
    if (!file) continue;
    if (o.all) {
      throw UserError(fmt::format("{} draws one scan, not --all (choose it with --index)", option));
    }
    RequireOutputDirectory(*file, option);
  }
}

CLI::Validator FileEndingIn(const std::string& extension) {
  return CLI::Validator(
      [extension](std::string& file) -> std::string {
        if (std::filesystem::path(file).extension().string() == extension) return {};
        return fmt::format("'{}' must end in {}", file, extension);
      },
      "");
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

// Every scan of `log`, in parallel, through `record_of` (its JSON record); a scan that fails is
// reported and written as an error record. Each record goes to the journal as it is done, so that
// Ctrl-C, SIGTERM or a crash loses none.
void RunAll(const ScanOptions& o, const Log& log, const dsl::CompiledPrior& prior,
            const std::function<std::string(std::size_t)>& record_of) {
  ScanJournal journal(o.out + ".partial", AllScansFingerprint(o, prior), log.scans.size(),
                      o.resume);
  if (journal.Restored() > 0)
    fmt::print(stderr, "resumed {} of {} from {}\n", journal.Restored(),
               Plural(log.scans.size(), "scan"), journal.path().string());
  Progress progress(log.scans.size(), "scans");
  std::mutex report;
  {
    const StopOnSignals stop_on_signals;
    tbb::parallel_for(std::size_t{0}, log.scans.size(), [&](std::size_t k) {
      if (journal.Record(k).empty()) {
        // After a stop the scans not begun are skipped: not done, so not counted as done.
        if (StopRequested()) return;
        std::string record;
        try {
          record = record_of(k);
        } catch (const std::exception& e) {
          record = nlohmann::json{{"format", "priormap.map_scan"},
                                  {"version", 1},
                                  {"scan_index", k},
                                  {"error", e.what()}}
                       .dump();
          std::lock_guard lock(report);
          fmt::print(stderr, "\npriormap: scan {}: {}\n", k, e.what());
        }
        journal.Append(k, record);
      }
      progress.Step();
    });
  }
  std::size_t done = 0;
  std::size_t failures = 0;
  std::string text;
  for (std::size_t k = 0; k < log.scans.size(); ++k) {
    const std::string& record = journal.Record(k);
    if (record.empty()) continue;
    ++done;
    // An error record (the only records with an "error" key at their top level).
    if (nlohmann::json::parse(record).contains("error")) ++failures;
    text += record + "\n";
  }
  if (done < log.scans.size()) {
    fmt::print("stopped: {} of {} done, kept in {}; continue with the same command and --resume\n",
               done, Plural(log.scans.size(), "scan"), journal.path().string());
    ExitAsStopped();
  }
  WriteTextFileAtomically(o.out, text);
  journal.Remove();
  fmt::print("wrote {} ({}{})\n", o.out, Plural(log.scans.size(), "scan"),
             failures ? fmt::format(", {} failed", failures) : std::string());
  // The file holds every scan's record, the failed ones' errors too; the exit status says that
  // not every scan was estimated.
  if (failures > 0)
    throw UserError(fmt::format("{} of {} failed; their records in {} say why", failures,
                                Plural(log.scans.size(), "scan"), o.out));
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
  const dsl::CompiledPrior prior = LoadPrior(o.prior_path, o.prior);
  CarmenReadOptions carmen;
  carmen.max_range = o.max_range;
  LogFormat read_as{};
  const Log log = ValueOrThrow(ReadLog(o.input, std::nullopt, carmen, &read_as));
  RequireCarmenForMaxRange(o.input, read_as, o.max_range);
  if (log.scans.empty()) throw UserError(fmt::format("{}: the log has no scans", o.input));
  if (o.all && o.index) throw UserError("--all and --index exclude each other");
  if (o.resume && !o.all)
    throw UserError("--resume continues a stopped --all run (one scan is quick)");
  const std::size_t index = o.index.value_or(0);
  if (index >= log.scans.size()) {
    throw UserError(
        fmt::format("--index {}: {} has {}", index, o.input, Plural(log.scans.size(), "scan")));
  }
  priorlets::EngineOptions engine;
  engine.beta = o.beta;
  engine.refine_borders = !o.no_refine;
  engine.close_full_turn = !o.open_full_turn;
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
  RunAll(o, log, prior, [&](std::size_t k) { return estimate(k).json; });
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
  cmd->add_flag("--resume", o->resume,
                "--all: continue the run stopped (Ctrl-C, SIGTERM or a crash) from the scans kept "
                "in OUT.partial; give the same prior, log and options");
  cmd->add_option("-o,--out", o->out, "Output JSON (JSON Lines with --all)")->required();
  cmd->add_option(
         "--beta", o->beta,
         "Prior probability that a reading fits the prior. It scores the result (the "
         "objective's -log(beta/(1-beta)) per in-model reading) but, as in the paper's "
         "Algorithm 1, does not decide the outliers: the range bounds, spikes and regions' "
         "sizes do")
      ->check(CLI::Range(1e-6, 1.0 - 1e-6))
      ->capture_default_str();
  cmd->add_flag("--no-refine", o->no_refine, "Keep the greedy topology (no border refinement)");
  cmd->add_flag("--open-full-turn", o->open_full_turn,
                "Treat a full-turn scan as a chain from its first beam to its last (by default its "
                "last reading and its first are neighbours, so a wall across the seam is one "
                "region)");
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
                  "posterior covariance (PNG)")
      ->check(FileEndingIn(".png"));
  cmd->add_option("--svg", o->svg, "The same figure as SVG")->check(FileEndingIn(".svg"));
  cmd->add_option("--lines", o->lines,
                  "One scan: the straight regions as line segments, JSON in the convention of ROS "
                  "laser_line_extraction (polar line, covariance, endpoints; docs/formats.md)");
  cmd->callback([o] { Run(*o); });
}

}  // namespace priormap::app
