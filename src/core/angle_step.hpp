#pragma once
// Evenly spaced beam angles as (first, step), for the writers of formats that store them so.

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>

namespace priormap::detail {

/// The step s with angles[i] == angles[0] + i * s exactly for all i, if there is one. The
/// readers build evenly spaced angles with that very expression, so such scans are stored as
/// (first angle, step) and read back bit for bit.
[[nodiscard]] inline std::optional<double> ExactAngleStep(std::span<const double> angles) {
  const std::size_t n = angles.size();
  if (n < 2) return std::nullopt;
  const auto angle = [&](std::size_t i, double step) {
    return angles[0] + static_cast<double>(i) * step;
  };
  const auto reproduces = [&](double step) {
    for (std::size_t i = 0; i < n; ++i) {
      if (angle(i, step) != angles[i]) return false;
    }
    return true;
  };
  const double estimate = (angles[n - 1] - angles[0]) / static_cast<double>(n - 1);
  double up = estimate, down = estimate;
  for (int ulps = 0; ulps < 4; ++ulps) {  // round-off leaves the estimate a few ulps away
    if (reproduces(up)) return up;
    if (reproduces(down)) return down;
    up = std::nextafter(up, std::numeric_limits<double>::infinity());
    down = std::nextafter(down, -std::numeric_limits<double>::infinity());
  }
  // A step much finer than the angles leaves the estimate many ulps from every step that
  // reproduces them. As angle(i, s) never decreases as s grows, the positive steps that give
  // angle i form an interval, and so does their intersection over i: found by bisection over
  // the bit patterns of positive doubles, which are in the doubles' order.
  if (!(angles[n - 1] > angles[0]) || !std::isfinite(estimate)) return std::nullopt;
  std::uint64_t lo = std::bit_cast<std::uint64_t>(std::numeric_limits<double>::denorm_min());
  std::uint64_t hi = std::bit_cast<std::uint64_t>(std::numeric_limits<double>::max());
  // The first bit pattern in [from, to] whose step gives angle i above `target` (or at or
  // above it, when `or_equal`); to + 1 when there is none.
  const auto first_above = [&](std::size_t i, std::uint64_t from, std::uint64_t to, bool or_equal) {
    std::uint64_t end = to + 1;
    while (from < end) {
      const std::uint64_t mid = from + (end - from) / 2;
      const double a = angle(i, std::bit_cast<double>(mid));
      if (or_equal ? a >= angles[i] : a > angles[i]) {
        end = mid;
      } else {
        from = mid + 1;
      }
    }
    return from;
  };
  // Narrowed angle by angle only until few candidates are left, which are then tried in
  // increasing order: the smallest step that reproduces every angle, as narrowing down to the
  // first angle would give, without a bisection per angle (angles evenly spaced far from 0, such
  // as a narrow field of view about a heading of 3 rad, come here on every scan of a log).
  constexpr std::uint64_t kFewCandidates = 64;
  for (std::size_t i = n - 1; i >= 1 && hi - lo >= kFewCandidates; --i) {
    const std::uint64_t first = first_above(i, lo, hi, true);
    const std::uint64_t past = first_above(i, lo, hi, false);
    if (first >= past) return std::nullopt;  // no step gives angle i exactly
    lo = first;
    hi = past - 1;
  }
  for (std::uint64_t bits = lo; bits <= hi; ++bits)
    if (reproduces(std::bit_cast<double>(bits))) return std::bit_cast<double>(bits);
  return std::nullopt;
}

}  // namespace priormap::detail
