#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <vector>

#include <priormap/core/carmen_io.hpp>

namespace priormap {
namespace {

constexpr int kMinSentinelCount = 10;
constexpr double kSentinelBand = 0.5;    // m below the sentinel that still count as "no return"
constexpr double kComparisonBand = 2.0;  // m below that band, where real returns would be
constexpr double kMinIsolation = 10.0;   // sentinel cluster / comparison band
constexpr double kMaxCm = 1e15;          // 10,000 km

}  // namespace

std::optional<double> DetectMaxRangeSentinel(std::span<const std::span<const double>> groups) {
  // Readings in centimetres: a dense histogram up to kDenseCm (every laser's range), a map for
  // the rare readings beyond. Counts saturate at 255: only "at least kMinSentinelCount" is
  // asked, and a byte per centimetre keeps the histogram at 100 KB (fresh pages cost more than
  // the counting on some machines).
  constexpr long long kDenseCm = 100000;
  std::vector<std::uint8_t> dense(kDenseCm + 1, 0);
  std::map<long long, int> sparse;
  for (const std::span<const double> readings : groups)
    for (double r : readings) {
      // Beyond kMaxCm no laser reports a range; such readings cannot be a sentinel, and their
      // centimetres would not fit a long long.
      if (!(std::isfinite(r) && r > 0.0 && r * 100.0 < kMaxCm)) continue;
      const long long cm = std::llround(r * 100.0);
      if (cm <= kDenseCm) {
        std::uint8_t& count = dense[static_cast<std::size_t>(cm)];
        count = static_cast<std::uint8_t>(count + (count < 255));
      } else {
        ++sparse[cm];
      }
    }
  std::optional<long long> sentinel_cm;
  for (auto it = sparse.rbegin(); it != sparse.rend() && !sentinel_cm; ++it)
    if (it->second >= kMinSentinelCount) sentinel_cm = it->first;
  for (long long cm = kDenseCm; cm >= 0 && !sentinel_cm; --cm)
    if (dense[static_cast<std::size_t>(cm)] >= kMinSentinelCount) sentinel_cm = cm;
  if (!sentinel_cm) return std::nullopt;
  const double threshold = static_cast<double>(*sentinel_cm) / 100.0 - kSentinelBand;
  long long cluster = 0, below = 0;
  for (const std::span<const double> readings : groups)
    for (double r : readings) {
      if (!std::isfinite(r)) continue;
      if (r >= threshold) {
        ++cluster;
      } else if (r >= threshold - kComparisonBand) {
        ++below;
      }
    }
  const double isolation = static_cast<double>(cluster) / static_cast<double>(std::max(below, 1LL));
  if (isolation < kMinIsolation) return std::nullopt;
  return threshold;
}

std::optional<double> DetectMaxRangeSentinel(const std::vector<double>& readings) {
  const std::span<const double> group(readings);
  return DetectMaxRangeSentinel(std::span<const std::span<const double>>(&group, 1));
}

}  // namespace priormap
