#include <cmath>

#include <priormap/core/angles.hpp>
#include <priormap/core/check.hpp>
#include <priormap/priorlets/corner_geometry.hpp>

namespace priormap::priorlets {

CornerCheck CheckCorner(std::span<const double> phi, std::span<const double> rho,
                        std::span<const double> alpha, std::size_t border,
                        const CornerOptions& options) {
  PRIORMAP_CHECK(phi.size() == rho.size() && phi.size() == alpha.size(), "one value per point");
  PRIORMAP_CHECK(border + 1 < phi.size(), "a border between two points");
  CornerCheck check;
  const std::size_t a = border, b = border + 1;
  const double turn = WrapAngle(alpha[b] - alpha[a]);
  // Lines n . p = d through each point, n the normal.
  const double nax = std::cos(alpha[a]), nay = std::sin(alpha[a]);
  const double nbx = std::cos(alpha[b]), nby = std::sin(alpha[b]);
  const double da = rho[a] * std::cos(phi[a] - alpha[a]);
  const double db = rho[b] * std::cos(phi[b] - alpha[b]);
  check.turned = std::abs(std::sin(turn)) >= std::sin(options.min_turn);
  if (!check.turned) {
    // A corner c between the points puts each within |p - c| sin(turn) <= chord sin(turn) of
    // the other's line.
    const double chord = std::hypot(rho[b] * std::cos(phi[b]) - rho[a] * std::cos(phi[a]),
                                    rho[b] * std::sin(phi[b]) - rho[a] * std::sin(phi[a]));
    const double b_off_a = std::abs(rho[b] * std::cos(phi[b] - alpha[a]) - da);
    const double a_off_b = std::abs(rho[a] * std::cos(phi[a] - alpha[b]) - db);
    check.step = std::min(b_off_a, a_off_b) > chord * std::sin(options.min_turn);
    return check;
  }
  const double det = nax * nby - nay * nbx;
  const double cx = (da * nby - db * nay) / det;
  const double cy = (nax * db - nbx * da) / det;
  // In front of the sensor: on the side of the border's bisecting ray.
  const double mid = phi[a] + 0.5 * WrapAngle(phi[b] - phi[a]);
  if (!(cx * std::cos(mid) + cy * std::sin(mid) > 0.0)) return check;
  check.corner = true;
  check.bearing = std::atan2(cy, cx);
  // Points before the border beyond the corner, or after it short of the corner.
  for (std::size_t j = a + 1; j-- > 0 && WrapAngle(phi[j] - check.bearing) > 0.0;) --check.shift;
  if (check.shift == 0) {
    for (std::size_t j = b; j < phi.size() && WrapAngle(phi[j] - check.bearing) < 0.0; ++j)
      ++check.shift;
  }
  return check;
}

}  // namespace priormap::priorlets
