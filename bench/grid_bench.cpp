// The occupancy-grid baseline's speed: reading a real log, and inserting every beam of it into
// a 5 cm grid, ours (module grid) against MRPT's COccupancyGridMap2D when MRPT is installed
// (scripts/install-deps.sh --baselines). Beams/s counts the readings offered to each grid.
#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <benchmark/benchmark.h>

#include <priormap/core/log_io.hpp>
#include <priormap/grid/occupancy_grid.hpp>

#ifdef PRIORMAP_HAVE_MRPT
#include <mrpt/maps/COccupancyGridMap2D.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/poses/CPose3D.h>
#endif

namespace {

using namespace priormap;

std::filesystem::path LogPath(const std::string& name) {
  return std::filesystem::path(PRIORMAP_SHARED_DATA_DIR) / "laser-corrected" /
         (name + "-corrected.log.gz");
}

// Read once per log for the insertion benchmarks.
const Log* Cached(const std::string& name) {
  static std::map<std::string, Log> logs;
  if (auto it = logs.find(name); it != logs.end()) return &it->second;
  Result<Log> log = ReadLog(LogPath(name));
  if (!log.ok()) return nullptr;
  return &logs.emplace(name, std::move(log).value()).first->second;
}

// The log of a benchmark's argument, or null (the benchmark then reports the missing data).
const Log* LogOrSkip(benchmark::State& state, const std::string& name) {
  const Log* log = Cached(name);
  if (!log) state.SkipWithError("../shared/data is absent");
  return log;
}

// Every reading offered to the grid counts, once per iteration.
void CountBeams(benchmark::State& state, const Log& log) {
  std::size_t readings = 0;
  for (const Scan& scan : log.scans) readings += scan.ranges.size();
  state.counters["beams_per_s"] =
      benchmark::Counter(static_cast<double>(readings) * static_cast<double>(state.iterations()),
                         benchmark::Counter::kIsRate);
}

void BM_ReadIntelLogGz(benchmark::State& state) {
  if (!std::filesystem::exists(LogPath("intel"))) {
    state.SkipWithError("../shared/data is absent");
    return;
  }
  for (auto _ : state) {
    Result<Log> log = ReadLog(LogPath("intel"));
    if (!log.ok()) state.SkipWithError(log.error().c_str());
    benchmark::DoNotOptimize(log);
  }
}
BENCHMARK(BM_ReadIntelLogGz)->Unit(benchmark::kMillisecond);

void BM_OurGrid(benchmark::State& state, const std::string& name) {
  const Log* log = LogOrSkip(state, name);
  if (!log) return;
  grid::GridOptions options;
  options.resolution = 0.05;
  const Box2 extent = grid::OccupancyGrid::ExtentOf(*log, 0, log->scans.size(), options);
  for (auto _ : state) {
    grid::OccupancyGrid map(extent, options);
    for (const Scan& scan : log->scans) map.Insert(scan);
    benchmark::DoNotOptimize(map);
  }
  CountBeams(state, *log);
}
BENCHMARK_CAPTURE(BM_OurGrid, intel, std::string("intel"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_OurGrid, freiburg_079, std::string("freiburg-079"))
    ->Unit(benchmark::kMillisecond);

#ifdef PRIORMAP_HAVE_MRPT
// The same beams as MRPT observations, inserted the same way: MRPT spreads a scan's N beams
// evenly over its aperture from the sensor's yaw - aperture / 2 in steps of aperture / N, so
// aperture and yaw are chosen to give our angles. Max-range readings clear up to the insertion
// range in both grids: MRPT does that for a valid reading at or beyond maxDistanceInsertion,
// whereas an invalid one would clear only half the previous beam's range (less work than ours);
// our invalid readings (no usable return) are skipped by both.
void BM_MrptGrid(benchmark::State& state, const std::string& name) {
  const Log* log = LogOrSkip(state, name);
  if (!log) return;
  grid::GridOptions options;
  const Box2 extent = grid::OccupancyGrid::ExtentOf(*log, 0, log->scans.size(), options);
  std::vector<std::pair<mrpt::obs::CObservation2DRangeScan, mrpt::poses::CPose3D>> observations;
  for (const Scan& scan : log->scans) {
    const std::size_t n = scan.ranges.size();
    if (n < 2) continue;
    mrpt::obs::CObservation2DRangeScan obs;
    const double step = (scan.angles.back() - scan.angles.front()) / static_cast<double>(n - 1);
    obs.aperture = static_cast<float>(step * static_cast<double>(n));
    obs.rightToLeft = true;
    obs.maxRange = static_cast<float>(options.max_range);
    obs.sensorPose = mrpt::poses::CPose3D(0, 0, 0, scan.angles.front() + 0.5 * obs.aperture, 0, 0);
    obs.resizeScan(n);
    for (std::size_t i = 0; i < n; ++i) {
      switch (scan.status[i]) {
        case BeamStatus::kValid:
          obs.setScanRange(i, static_cast<float>(scan.ranges[i]));
          obs.setScanRangeValidity(i, true);
          break;
        case BeamStatus::kMaxRange:
          obs.setScanRange(i, static_cast<float>(options.max_range));
          obs.setScanRangeValidity(i, options.max_readings_clear);
          break;
        case BeamStatus::kInvalid:
          obs.setScanRange(i, 0.0f);
          obs.setScanRangeValidity(i, false);
          break;
      }
    }
    observations.emplace_back(std::move(obs), mrpt::poses::CPose3D(scan.pose.x(), scan.pose.y(), 0,
                                                                   scan.pose.theta(), 0, 0));
  }
  for (auto _ : state) {
    mrpt::maps::COccupancyGridMap2D map(
        static_cast<float>(extent.min().x()), static_cast<float>(extent.max().x()),
        static_cast<float>(extent.min().y()), static_cast<float>(extent.max().y()), 0.05f);
    map.insertionOptions.maxDistanceInsertion = static_cast<float>(options.max_range);
    map.insertionOptions.considerInvalidRangesAsFreeSpace = false;
    for (const auto& [obs, pose] : observations) map.insertObservation(obs, pose);
    benchmark::DoNotOptimize(map);
  }
  CountBeams(state, *log);
}
BENCHMARK_CAPTURE(BM_MrptGrid, intel, std::string("intel"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_MrptGrid, freiburg_079, std::string("freiburg-079"))
    ->Unit(benchmark::kMillisecond);
#endif

}  // namespace

BENCHMARK_MAIN();
