// priormap plot: draw any scan or log (JSON or CARMEN) as a map, or a scan's ranges per beam.
#include <cmath>

#include <fmt/format.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/log_io.hpp>
#include <priormap/core/world_bounds.hpp>
#include <priormap/render/line_plot.hpp>
#include <priormap/render/scene_drawing.hpp>

#include "cli_support.hpp"
#include "commands.hpp"

namespace priormap::app {
namespace {

struct PlotOptions {
  std::string input;
  std::string out;
  std::string kind = "map";
  std::optional<std::size_t> scan;
  std::optional<std::string> scene;
  int stride = 1;
  std::optional<std::string> title;
  int width = 900;
  std::optional<double> max_range;
};

// Cairo draws in 24.8 fixed point: a world (or a range) far beyond the readers' bound on world
// coordinates cannot be drawn. The readers refuse, at their field, positions beyond it and
// returns (and true ranges) longer than it, so that what they read is drawable: a return's
// point lies within a pose, a transducer offset (at most sqrt(2) times the bound) and its range.
// No-return readings are drawn by their status, as rays to the max range, never by their value.
// These checks only guard against what a reader would let through.
constexpr double kLongestDrawableRange = kMaxWorldCoordinate;  // m
constexpr double kLargestDrawable = 4 * kMaxWorldCoordinate;   // m

bool IsDrawable(const Box2& box) {
  return box.isEmpty() || (box.min().cwiseAbs().maxCoeff() <= kLargestDrawable &&
                           box.max().cwiseAbs().maxCoeff() <= kLargestDrawable);
}

void PlotMap(const Log& log, const PlotOptions& o) {
  std::optional<Scene> scene;
  if (o.scene) scene = LoadScene(*o.scene, "--scene");
  const bool one_scan = o.scan.has_value() || log.scans.size() == 1;
  const std::size_t k = o.scan.value_or(0);
  Box2 bounds = one_scan ? render::ScanBounds(log.scans[k]) : render::LogBounds(log);
  // The log and the scene each on its own, so that the message names the one too far out.
  if (!IsDrawable(bounds)) {
    throw UserError(
        fmt::format("{}: poses or readings lie beyond {:.0e} m of the origin, too "
                    "far to draw",
                    o.input, kLargestDrawable));
  }
  if (scene) {
    const Box2 scene_bounds = scene->Bounds();
    if (!IsDrawable(scene_bounds)) {
      throw UserError(
          fmt::format("--scene {}: the scene reaches beyond {:.0e} m of the origin, "
                      "too far to draw",
                      *o.scene, kLargestDrawable));
    }
    bounds.extend(scene_bounds);
  }
  const std::string title =
      o.title.value_or(one_scan ? fmt::format("{}: scan {} of {}", o.input, k, log.scans.size())
                                : fmt::format("{}: {}", o.input, Plural(log.scans.size(), "scan")));
  render::Figure figure(bounds, {.width_px = o.width, .max_height_px = o.width, .title = title});
  if (scene) render::DrawScene(figure, *scene);
  if (one_scan) {
    render::DrawScan(figure, log.scans[k]);
  } else {
    render::DrawLog(figure, log, o.stride);
  }
  figure.Save(o.out);
}

void PlotRanges(const Log& log, const PlotOptions& o, bool residuals) {
  const std::size_t k = o.scan.value_or(0);
  const Scan& scan = log.scans[k];
  if (residuals && !scan.truth) {
    throw UserError(fmt::format("--kind residuals: scan {} of {} has no ground truth", k, o.input));
  }
  render::Series measured{.label = residuals ? "measured - true" : "measured", .markers = true};
  render::Series truth{.label = "true", .width_px = 1.0};
  for (std::size_t i = 0; i < scan.size(); ++i) {
    const double angle = RadToDeg(scan.angles[i]);
    const double value = scan.IsValid(i) ? scan.ranges[i] : std::nan("");
    measured.x.push_back(angle);
    measured.y.push_back(residuals ? value - scan.truth->range[i] : value);
    if (scan.truth && !residuals) {
      truth.x.push_back(angle);
      truth.y.push_back(scan.truth->range[i]);
    }
  }
  for (const std::vector<double>* values : {&measured.y, &truth.y}) {
    for (const double v : *values) {
      if (std::isfinite(v) && std::abs(v) > kLongestDrawableRange) {
        throw UserError(
            fmt::format("{}: scan {} has a range of {} m, too large to draw", o.input, k, v));
      }
    }
  }
  render::LinePlot plot({.width_px = o.width,
                         .title = o.title.value_or(fmt::format("{}: scan {}", o.input, k)),
                         .x_label = "beam angle (deg)",
                         .y_label = residuals ? "range error (m)" : "range (m)"});
  plot.Add(std::move(measured));
  if (!truth.x.empty()) plot.Add(std::move(truth));
  if (residuals && !scan.sigma.empty()) {
    // Each reading's own band: a sonar ring's noise grows with the range.
    // A ring's transducers are not in the order of their bearings: marks, not a line.
    const bool marks = scan.sonar.has_value();
    render::Series upper{
        .label = "±3σ", .color = render::palette::kGray, .width_px = 1.0, .markers = marks};
    render::Series lower{.color = render::palette::kGray, .width_px = 1.0, .markers = marks};
    for (std::size_t i = 0; i < scan.size(); ++i) {
      const double band = scan.IsValid(i) ? 3 * scan.sigma[i] : std::nan("");
      upper.x.push_back(RadToDeg(scan.angles[i]));
      upper.y.push_back(band);
      lower.x.push_back(RadToDeg(scan.angles[i]));
      lower.y.push_back(-band);
    }
    plot.Add(std::move(upper));
    plot.Add(std::move(lower));
  }
  plot.Save(o.out);
}

void Run(const PlotOptions& o) {
  RequireDistinctFiles({{"the input", o.input}, {"--out", o.out}});
  CarmenReadOptions carmen;
  carmen.max_range = o.max_range;
  LogFormat read_as{};
  const Log log = ValueOrThrow(ReadLog(o.input, std::nullopt, carmen, &read_as));
  RequireCarmenForMaxRange(o.input, read_as, o.max_range);
  if (log.scans.empty()) throw UserError(fmt::format("{}: the log has no scans to plot", o.input));
  if (o.scan && *o.scan >= log.scans.size()) {
    throw UserError(
        fmt::format("--scan {}: {} has {}", *o.scan, o.input, Plural(log.scans.size(), "scan")));
  }
  if (o.kind == "map") {
    PlotMap(log, o);
  } else {
    PlotRanges(log, o, o.kind == "residuals");
  }
  fmt::print("wrote {}\n", o.out);
}

}  // namespace

void AddPlotCommand(CLI::App& app) {
  auto o = std::make_shared<PlotOptions>();
  CLI::App* cmd =
      app.add_subcommand("plot", "Draw a scan or a log (JSON or CARMEN) as PNG, SVG or PDF");
  cmd->add_option("input", o->input, "Scan or log file")->required();
  cmd->add_option("-o,--out", o->out, "Figure file: .png, .svg or .pdf")
      ->required()
      ->check(FigurePath());
  cmd->add_option(
         "--kind", o->kind,
         "map: points in the world; ranges: range per beam; residuals: measured - true range")
      ->check(CLI::IsMember({"map", "ranges", "residuals"}))
      ->capture_default_str();
  cmd->add_option("--scan", o->scan, "Draw only this scan (0-based)")->transform(IndexValue());
  cmd->add_option("--scene", o->scene, "Overlay a scene (built-in name or scene JSON)");
  cmd->add_option("--stride", o->stride, "Log maps: draw every n-th scan")
      ->check(PositiveValue())
      ->capture_default_str();
  cmd->add_option("--title", o->title, "Figure title");
  cmd->add_option("--width", o->width, "Figure width, pixels")
      ->check(CLI::Range(200, 8000))
      ->capture_default_str();
  cmd->add_option("--max-range", o->max_range,
                  "CARMEN input: readings at or above this are max-range")
      ->check(PositiveValue());
  cmd->callback([o] { Run(*o); });
}

}  // namespace priormap::app
