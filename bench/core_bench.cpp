// Foundation throughput: ray casting, simulation, log I/O, rendering. Results in
// docs/benchmarks.md.
#include <filesystem>

#include <benchmark/benchmark.h>

#include <priormap/core/carmen_io.hpp>
#include <priormap/core/file_io.hpp>
#include <priormap/core/json_io.hpp>
#include <priormap/core/simulate.hpp>
#include <priormap/render/figure.hpp>
#include <priormap/render/scene_drawing.hpp>

namespace priormap {
namespace {

const Scene& LRoom() {
  static const Scene scene = *BuiltinScene("l-room");
  return scene;
}

void BM_SimulateScanUtm30(benchmark::State& state) {
  const SceneRayCaster caster(LRoom());
  const RangeSensor sensor = *RangeSensor::Preset("utm30");
  Rng rng(1);
  for (auto _ : state)
    benchmark::DoNotOptimize(SimulateScan(caster, sensor, *LRoom().default_pose, rng));
  state.SetItemsProcessed(state.iterations() * sensor.num_beams);
  state.counters["beams/s"] = benchmark::Counter(
      static_cast<double>(state.iterations() * sensor.num_beams), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SimulateScanUtm30)->Unit(benchmark::kMicrosecond);

void BM_SimulateLog(benchmark::State& state) {
  const RangeSensor sensor = *RangeSensor::Preset("utm30");
  const auto trajectory = TrajectoryFromWaypoints(LRoom().waypoints, 0.5, 10.0);
  for (auto _ : state) benchmark::DoNotOptimize(SimulateLog(LRoom(), sensor, trajectory, 1));
  state.counters["scans"] = static_cast<double>(trajectory.size());
}
BENCHMARK(BM_SimulateLog)->Unit(benchmark::kMillisecond);

Log SyntheticLog() {
  const RangeSensor sensor = *RangeSensor::Preset("lms200");
  return SimulateLog(LRoom(), sensor, TrajectoryFromWaypoints(LRoom().waypoints, 0.5, 10.0), 1);
}

void BM_CarmenFormatAndParse(benchmark::State& state) {
  const std::string text = FormatCarmenLog(SyntheticLog());
  for (auto _ : state) benchmark::DoNotOptimize(ParseCarmenLog(text, "bench.log"));
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(text.size()));
}
BENCHMARK(BM_CarmenFormatAndParse)->Unit(benchmark::kMillisecond);

void BM_JsonLogParse(benchmark::State& state) {
  const std::string text = FormatJsonLog(SyntheticLog());
  for (auto _ : state) benchmark::DoNotOptimize(ParseJsonLog(text, "bench.json"));
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(text.size()));
}
BENCHMARK(BM_JsonLogParse)->Unit(benchmark::kMillisecond);

// The largest real log (Freiburg 079, 4791 scans x 360 beams), gzip: read + parse + classify.
void BM_ReadRealCarmenLog(benchmark::State& state) {
  const std::filesystem::path path = std::filesystem::path(PRIORMAP_SHARED_DATA_DIR) /
                                     "laser-corrected/freiburg-079-corrected.log.gz";
  if (!std::filesystem::exists(path)) {
    state.SkipWithError("../shared/data is absent");
    return;
  }
  for (auto _ : state) benchmark::DoNotOptimize(ReadCarmenLog(path));
}
BENCHMARK(BM_ReadRealCarmenLog)->Unit(benchmark::kMillisecond);

void BM_RenderScanPng(benchmark::State& state) {
  Rng rng(1);
  const Scan scan = SimulateScan(SceneRayCaster(LRoom()), *RangeSensor::Preset("utm30"),
                                 *LRoom().default_pose, rng);
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / "priormap-bench-scan.png";
  for (auto _ : state) {
    render::Figure figure(LRoom().Bounds());
    render::DrawScene(figure, LRoom());
    render::DrawScan(figure, scan);
    figure.Save(path);
  }
  std::filesystem::remove(path);
}
BENCHMARK(BM_RenderScanPng)->Unit(benchmark::kMillisecond);

// Making a figure with axes: its layout measures about 30 tick labels (the y labels for the
// left margin, the x labels for their spacing and for the margins the end labels need), then
// draws the axes. Nothing is saved.
void BM_FigureLayout(benchmark::State& state) {
  for (auto _ : state) {
    render::Figure figure(LRoom().Bounds(), {.title = "l-room"});
    benchmark::DoNotOptimize(figure.width_px());
  }
}
BENCHMARK(BM_FigureLayout)->Unit(benchmark::kMicrosecond);

// One tick label's width, as the layouts measure it.
void BM_TextWidth(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(render::TextWidth("1000000", 11.0));
}
BENCHMARK(BM_TextWidth)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace priormap

BENCHMARK_MAIN();
