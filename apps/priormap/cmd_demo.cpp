// priormap demo: runs the toolkit on embedded simulated data and writes a small gallery.
#include <chrono>
#include <cmath>

#include <fmt/format.h>

#include <priormap/core/file_io.hpp>
#include <priormap/core/json_io.hpp>
#include <priormap/core/simulate.hpp>
#include <priormap/render/line_plot.hpp>
#include <priormap/render/scene_drawing.hpp>

#include "cli_support.hpp"
#include "commands.hpp"

namespace priormap::app {
namespace {

struct DemoOptions {
  std::string out = "demo";
  std::uint64_t seed = 1;
};

struct GalleryItem {
  std::string file;
  std::string caption;
  std::string command;
};

// Root-mean-square of measured minus true range over valid, non-outlier readings.
double RangeRmse(const Scan& scan) {
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < scan.size(); ++i) {
    if (!scan.IsValid(i) || scan.truth->outlier[i]) continue;
    const double e = scan.ranges[i] - scan.truth->range[i];
    sum += e * e;
    ++n;
  }
  return n > 0 ? std::sqrt(sum / static_cast<double>(n)) : 0.0;
}

GalleryItem SceneScan(const std::filesystem::path& dir, const std::string& name,
                      std::uint64_t seed) {
  const Scene scene = *BuiltinScene(name);
  const RangeSensor sensor = *RangeSensor::Preset("utm30");
  Rng rng(seed);
  const Scan scan = SimulateScan(SceneRayCaster(scene), sensor, *scene.default_pose, rng);
  const std::string file = fmt::format("scan-{}.png", name);
  Box2 bounds = scene.Bounds();
  bounds.extend(render::ScanBounds(scan));
  render::Figure figure(
      bounds, {.width_px = 640, .max_height_px = 640, .title = fmt::format("{} (utm30)", name)});
  render::DrawScene(figure, scene);
  render::DrawScan(figure, scan);
  figure.AddLegend("readings", render::palette::kBlue);
  figure.AddLegend("true normals", render::palette::kGreen);
  figure.Save(dir / file);
  return {file,
          fmt::format("{}: {} beams, {} valid, range RMSE {:.2f} cm (sigma 1 cm)", name,
                      scan.size(), scan.NumValid(), 100 * RangeRmse(scan)),
          fmt::format("priormap simulate --scene {} --sensor utm30 --seed {} -o {}.json --png {}",
                      name, seed, name, file)};
}

GalleryItem Residuals(const std::filesystem::path& dir, std::uint64_t seed) {
  const Scene scene = *BuiltinScene("l-room");
  RangeSensor sensor = *RangeSensor::Preset("utm30");
  sensor.outlier_probability = 0.02;
  Rng rng(seed);
  const Scan scan = SimulateScan(SceneRayCaster(scene), sensor, *scene.default_pose, rng);
  render::Series errors{.label = "measured - true", .markers = true};
  for (std::size_t i = 0; i < scan.size(); ++i) {
    if (!scan.IsValid(i)) continue;
    errors.x.push_back(scan.angles[i] * 180.0 / M_PI);
    errors.y.push_back(scan.ranges[i] - scan.truth->range[i]);
  }
  render::LinePlot plot({.title = "l-room, utm30 with 2% outliers: range error per beam",
                         .x_label = "beam angle (deg)",
                         .y_label = "range error (m)",
                         .y_range = std::pair{-0.1, 0.05}});
  plot.Add(std::move(errors));
  plot.AddHorizontalLine(3 * sensor.sigma, render::palette::kGray, "±3σ");
  plot.AddHorizontalLine(-3 * sensor.sigma, render::palette::kGray);
  const std::string file = "residuals-l-room.png";
  plot.Save(dir / file);
  return {file, "Per-beam range error: Gaussian noise inside ±3σ, outliers below (short readings)",
          fmt::format("priormap simulate --scene l-room --outliers 0.02 --seed {} -o s.json && "
                      "priormap plot s.json --kind residuals -o {}",
                      seed, file)};
}

GalleryItem LogMap(const std::filesystem::path& dir, std::uint64_t seed) {
  const Scene scene = *BuiltinScene("l-room");
  const RangeSensor sensor = *RangeSensor::Preset("lms200");
  const Log log =
      SimulateLog(scene, sensor, TrajectoryFromWaypoints(scene.waypoints, 0.5, 5.0), seed);
  WriteJsonLog(log, dir / "l-room.log.json");
  render::Figure figure(
      scene.Bounds(),
      {.width_px = 640,
       .max_height_px = 640,
       .title = fmt::format("l-room: localized log, {} scans (lms200)", log.scans.size())});
  render::DrawScene(figure, scene);
  render::DrawLog(figure, log);
  const std::string file = "log-l-room.png";
  figure.Save(dir / file);
  return {
      file,
      fmt::format(
          "A localized log of {} scans along the scene's waypoints (also saved as l-room.log.json)",
          log.scans.size()),
      fmt::format("priormap simulate --scene l-room --sensor lms200 --log --seed {} -o "
                  "l-room.log.json --png {}",
                  seed, file)};
}

std::string HtmlEscape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

void WriteIndex(const std::filesystem::path& dir, const std::vector<GalleryItem>& items) {
  std::string html =
      "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>priormap "
      "demo</title>\n"
      "<style>body{font-family:sans-serif;max-width:1400px;margin:2em auto;padding:0 1em}"
      "figure{display:inline-block;vertical-align:top;width:640px;margin:0 1em 2em 0}"
      "img{max-width:100%;border:1px solid #ccc}code{font-size:85%;background:#f4f4f4;"
      "padding:2px 4px;display:block;white-space:pre-wrap}</style></head><body>\n"
      "<h1>priormap demo</h1>\n<p>Simulated scenes with per-beam ground truth, drawn by "
      "priormap.</p>\n";
  for (const GalleryItem& item : items) {
    html += fmt::format(
        "<figure><img src=\"{}\" alt=\"{}\"><figcaption>{}<code>{}</code></figcaption></figure>\n",
        item.file, HtmlEscape(item.caption), HtmlEscape(item.caption), HtmlEscape(item.command));
  }
  html += "</body></html>\n";
  WriteTextFileAtomically(dir / "index.html", html);
}

void Run(const DemoOptions& o) {
  const auto start = std::chrono::steady_clock::now();
  const std::filesystem::path dir = o.out;
  EnsureDirectory(dir);
  std::vector<GalleryItem> items;
  std::uint64_t seed = o.seed;
  for (const std::string& name : BuiltinSceneNames()) items.push_back(SceneScan(dir, name, seed++));
  items.push_back(Residuals(dir, o.seed));
  items.push_back(LogMap(dir, o.seed));
  WriteIndex(dir, items);
  for (const GalleryItem& item : items)
    fmt::print("  {}  {}\n", (dir / item.file).string(), item.caption);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  fmt::print("priormap demo: wrote {} figures to {}/ in {:.1f} s; open {}\n", items.size(),
             dir.string(), seconds, (dir / "index.html").string());
}

}  // namespace

void AddDemoCommand(CLI::App& app) {
  auto o = std::make_shared<DemoOptions>();
  CLI::App* cmd = app.add_subcommand(
      "demo", "Run priormap on embedded simulated data and write a figure gallery");
  cmd->add_option("-o,--out", o->out, "Output directory")->capture_default_str();
  cmd->add_option("--seed", o->seed, "Random seed")->capture_default_str();
  cmd->callback([o] { Run(*o); });
}

}  // namespace priormap::app
