#include "testing/scan_truth.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <priormap/core/rng.hpp>
#include <priormap/core/scene_ray_caster.hpp>
#include <priormap/core/simulate.hpp>
#include <priormap/priorlets/normal_baselines.hpp>

namespace priormap::testing {

Scan SimulateScene(const Scene& scene, const RangeSensor& sensor, const Se2& pose,
                   std::uint64_t seed) {
  Rng rng(seed);
  return SimulateScan(SceneRayCaster(scene), sensor, pose, rng);
}

std::vector<std::size_t> TrueBorders(const Scan& scan) {
  std::vector<std::size_t> borders;
  for (std::size_t i = 0; i + 1 < scan.size(); ++i) {
    if (scan.truth->region[i] != scan.truth->region[i + 1]) borders.push_back(i);
  }
  return borders;
}

std::size_t TrueRegionCount(const Scan& scan, std::size_t min_points) {
  std::size_t count = 0, run = 0;
  int region = -1;
  for (std::size_t i = 0; i < scan.size(); ++i) {
    if (!scan.IsValid(i) || scan.truth->outlier[i]) continue;
    if (scan.truth->region[i] != region) {
      count += run >= min_points ? 1 : 0;
      region = scan.truth->region[i];
      run = 0;
    }
    ++run;
  }
  return count + (run >= min_points ? 1 : 0);
}

std::vector<std::size_t> TrueCorners(const Scan& scan) {
  std::vector<std::size_t> corners;
  const ScanTruth& t = *scan.truth;
  for (std::size_t i = 0; i + 1 < scan.size(); ++i) {
    if (scan.IsValid(i) && scan.IsValid(i + 1) && t.region[i] >= 0 && t.region[i + 1] >= 0 &&
        t.outlier[i] == 0 && t.outlier[i + 1] == 0 && t.surface[i] == t.surface[i + 1] &&
        t.region[i] != t.region[i + 1]) {
      corners.push_back(i);
    }
  }
  return corners;
}

std::vector<FoundBorder> FoundBorders(const priorlets::MapScan& map) {
  std::vector<FoundBorder> borders;
  for (std::size_t r = 0; r + 1 < map.regions.size(); ++r) {
    borders.push_back({map.regions[r].last, map.regions[r + 1].first});
  }
  // A ring (a full-turn scan) also has the border from its last region round to its first,
  // unless it has no border at all.
  const bool borderless = map.closing_link == priorlets::Link::kSameRegion &&
                          std::all_of(map.links.begin(), map.links.end(), [](priorlets::Link l) {
                            return l == priorlets::Link::kSameRegion;
                          });
  if (map.closed && !map.regions.empty() && !borderless)
    borders.push_back({map.regions.back().last, map.regions.front().first});
  return borders;
}

long BorderError(std::size_t c, const FoundBorder& b) {
  const auto d = [](std::size_t x, std::size_t y) {
    return std::abs(static_cast<long>(x) - static_cast<long>(y));
  };
  return std::max(d(b.last, c), d(b.first, c + 1));
}

long NearestBorder(std::size_t c, const std::vector<FoundBorder>& found) {
  long best = std::numeric_limits<long>::max();
  for (const FoundBorder& b : found) best = std::min(best, BorderError(c, b));
  return best;
}

std::vector<std::uint8_t> TruthMask(const Scan& scan, bool skip_borders) {
  std::vector<std::uint8_t> mask(scan.size(), 0);
  for (std::size_t i = 0; i < scan.size(); ++i) {
    mask[i] = scan.IsValid(i) && !scan.truth->outlier[i];
  }
  if (skip_borders) {
    for (std::size_t b : TrueBorders(scan)) mask[b] = mask[b + 1] = 0;
  }
  return mask;
}

std::vector<int> TrueInModel(const Scan& scan, int unscored_surface, double bound_sigmas) {
  const ScanTruth& t = *scan.truth;
  std::vector<int> label(scan.size(), 0);
  for (std::size_t i = 0; i < scan.size(); ++i) {
    if (!scan.IsValid(i) || t.surface[i] < 0) continue;
    if (t.surface[i] == unscored_surface) {
      label[i] = -1;
    } else if (t.outlier[i] != 0) {
      label[i] = std::abs(scan.ranges[i] - t.range[i]) <= bound_sigmas * scan.sigma[i] ? -1 : 0;
    } else {
      label[i] = 1;
    }
  }
  return label;
}

void ErrorPool::Add(const std::vector<double>& estimate, const Scan& scan,
                    const std::vector<std::uint8_t>& mask) {
  const priorlets::NormalErrorStats s =
      priorlets::CompareNormals(estimate, scan.truth->alpha, mask);
  std::size_t in_mask = 0;
  for (std::size_t i = 0; i < scan.size(); ++i) {
    in_mask += mask[i] != 0 && std::isfinite(scan.truth->alpha[i]);
  }
  missing += in_mask - s.count;
  if (s.count == 0) return;
  sum += s.mean_deg * static_cast<double>(s.count);
  count += s.count;
  worst_scan = std::max(worst_scan, s.mean_deg);
}

double ErrorPool::Mean() const {
  return count ? sum / static_cast<double>(count) : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace priormap::testing
