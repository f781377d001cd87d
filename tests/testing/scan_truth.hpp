#pragma once
// Simulated scans and their comparison with the simulator's ground truth, shared by the engine's
// tests and bench/normal_accuracy_bench.cpp (no GoogleTest here, so the bench can use it too).
#include <cstddef>
#include <cstdint>
#include <vector>

#include <priormap/core/range_sensor.hpp>
#include <priormap/core/scan.hpp>
#include <priormap/core/scene.hpp>
#include <priormap/core/se2.hpp>
#include <priormap/priorlets/engine.hpp>

namespace priormap::testing {

// One scan of `scene` from `pose`, noise drawn from Rng(seed).
[[nodiscard]] Scan SimulateScene(const Scene& scene, const RangeSensor& sensor, const Se2& pose,
                                 std::uint64_t seed);

// Links i | i + 1 where the simulator's region changes (corners and occlusions).
[[nodiscard]] std::vector<std::size_t> TrueBorders(const Scan& scan);

// Regions of a simulated scan: runs of one true region over the genuine valid readings, of at
// least `min_points` readings (shorter runs are clutter to the engine too, min_region_points).
[[nodiscard]] std::size_t TrueRegionCount(const Scan& scan, std::size_t min_points);

// Links i | i + 1 between valid, genuine readings of two primitives of one surface: corners
// (occlusion jumps between surfaces are not corners).
[[nodiscard]] std::vector<std::size_t> TrueCorners(const Scan& scan);

// A border the engine found: the last in-model beam of a region and the first of the next
// (across the seam of a closed map, last > first).
struct FoundBorder {
  std::size_t last = 0, first = 0;
};

[[nodiscard]] std::vector<FoundBorder> FoundBorders(const priorlets::MapScan& map);

// How many beams a found border is from the true one between beams c and c + 1: 0 when it is
// that very link; beams left out of the model between the two regions count against it (the
// border is then somewhere in the gap).
[[nodiscard]] long BorderError(std::size_t c, const FoundBorder& b);

// The error of the found border nearest to the true border after beam c.
[[nodiscard]] long NearestBorder(std::size_t c, const std::vector<FoundBorder>& found);

// Valid, genuine readings; with `skip_borders`, without the two beams of every true region
// change: a beam within a beam spacing of a corner fits either wall within the noise, so which
// wall it gets is a coin toss (the "+-1 beam" the issue grants corner location), and a wrong
// toss costs about 90 deg / n of the mean without saying anything about the normals.
[[nodiscard]] std::vector<std::uint8_t> TruthMask(const Scan& scan, bool skip_borders);

// Ground truth of INMODEL per beam (ScanTruth: `outlier` marks the simulator's spurious
// readings, `surface` what a genuine reading hit):
//   1  a valid, genuine reading of a straight surface (walls, and clutter such as a box: the
//      scene's `clutter` flag says no *structural* prior is meant to explain it, but a polygonal
//      prior does, so it belongs in the model);
//   0  a spurious reading, whose range is uniform between the sensor and the surface;
//  -1  not scored: readings of `unscored_surface` (e.g. a small round bin: a polygonal prior
//      cannot describe a circle, but at a few metres a run of beams on it lies on short straight
//      pieces within the noise, so keeping it and dropping it are both right), and spurious
//      readings that land within bound_sigmas of the surface, which no estimator can tell from
//      genuine ones.
[[nodiscard]] std::vector<int> TrueInModel(const Scan& scan, int unscored_surface,
                                           double bound_sigmas);

// Mean |normal error| in degrees pooled over several scans.
struct ErrorPool {
  double sum = 0.0;
  std::size_t count = 0;
  std::size_t missing = 0;  // beams of the mask without an estimate
  double worst_scan = 0.0;  // the largest mean of one scan
  void Add(const std::vector<double>& estimate, const Scan& scan,
           const std::vector<std::uint8_t>& mask);
  [[nodiscard]] double Mean() const;
};

}  // namespace priormap::testing
