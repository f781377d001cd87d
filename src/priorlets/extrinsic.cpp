#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include <priormap/core/angles.hpp>
#include <priormap/core/check.hpp>
#include <priormap/core/types.hpp>
#include <priormap/priorlets/extrinsic.hpp>

namespace priormap::priorlets {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

bool AllFinite(double a, double b, double c, double d) {
  return std::isfinite(a) && std::isfinite(b) && std::isfinite(c) && std::isfinite(d);
}

// cos(beta) kept at least `min_cos` away from zero, its sign kept (zero counts as facing the
// sensor, i.e. negative).
double ClampedCos(double cos_beta, double min_cos, bool* clamped) {
  *clamped = std::abs(cos_beta) < min_cos;
  if (!*clamped) return cos_beta;
  return cos_beta > 0.0 ? min_cos : -min_cos;
}

}  // namespace

Eigen::Matrix<double, Eigen::Dynamic, 3> ExtrinsicJacobian(std::span<const double> rho,
                                                           std::span<const double> alpha,
                                                           std::span<const double> phi,
                                                           std::span<const double> curvature,
                                                           double min_incidence_cos,
                                                           std::vector<std::uint8_t>* clamped) {
  const std::size_t n = rho.size();
  PRIORMAP_CHECK(alpha.size() == n && phi.size() == n, "rho, alpha and phi differ in size");
  PRIORMAP_CHECK(curvature.empty() || curvature.size() == n,
                 "curvature must be empty or have one entry per beam");
  PRIORMAP_CHECK(min_incidence_cos > 0.0 && min_incidence_cos <= 1.0,
                 "min_incidence_cos must be in (0, 1]");
  if (clamped) clamped->assign(n, 0);

  const auto rows = static_cast<Eigen::Index>(n);
  Eigen::Matrix<double, Eigen::Dynamic, 3> J(2 * rows, 3);
  for (std::size_t i = 0; i < n; ++i) {
    const auto r = static_cast<Eigen::Index>(i);
    const double kappa = curvature.empty() ? 0.0 : curvature[i];
    if (!AllFinite(rho[i], alpha[i], phi[i], kappa)) {
      J.row(r).setConstant(kNaN);
      J.row(rows + r).setConstant(kNaN);
      continue;
    }
    // Ray/line intersection with the tangent at the hit (Sec. IV-B, eq. (8)), beta = alpha - phi.
    bool is_clamped = false;
    const double beta = alpha[i] - phi[i];
    const double cos_beta = ClampedCos(std::cos(beta), min_incidence_cos, &is_clamped);
    if (clamped) (*clamped)[i] = is_clamped ? 1 : 0;
    J.row(r) << -std::cos(alpha[i]) / cos_beta, -std::sin(alpha[i]) / cos_beta,
        -rho[i] * std::sin(beta) / cos_beta;
    // The hit slides along the surface by ds (positive towards increasing phi) as the ray moves
    // across it; the normal turns by kappa ds there, and the sensor frame turns by dtheta.
    const double w = kappa / std::abs(cos_beta);
    J.row(rows + r) << -w * std::sin(phi[i]), w * std::cos(phi[i]), w * rho[i] - 1.0;
  }
  return J;
}

namespace {

// The hit of beam i in the sensor frame.
Vec2 HitPoint(std::span<const double> rho, std::span<const double> phi, std::size_t i) {
  return rho[i] * UnitVector(phi[i]);
}

// (d alpha, d s) from beam i to beam j, if j is a usable neighbour on the same smooth surface.
std::optional<std::pair<double, double>> Step(std::span<const double> rho,
                                              std::span<const double> alpha,
                                              std::span<const double> phi, std::size_t i,
                                              std::size_t j, double max_normal_turn) {
  if (!std::isfinite(rho[j]) || !std::isfinite(alpha[j]) || !std::isfinite(phi[j])) {
    return std::nullopt;
  }
  const double d_alpha = AngleDifference(alpha[j], alpha[i]);
  if (std::abs(d_alpha) > max_normal_turn) return std::nullopt;
  const double length = (HitPoint(rho, phi, j) - HitPoint(rho, phi, i)).norm();
  if (!(length > 0.0)) return std::nullopt;
  // Signed so that s grows with the beam index (phi increases with it).
  return std::pair{d_alpha, j > i ? length : -length};
}

}  // namespace

std::vector<double> EstimateCurvature(std::span<const double> rho, std::span<const double> alpha,
                                      std::span<const double> phi, double max_normal_turn) {
  const std::size_t n = rho.size();
  PRIORMAP_CHECK(alpha.size() == n && phi.size() == n, "rho, alpha and phi differ in size");
  PRIORMAP_CHECK(max_normal_turn > 0.0, "max_normal_turn must be positive");

  std::vector<double> kappa(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(rho[i]) || !std::isfinite(alpha[i]) || !std::isfinite(phi[i])) continue;
    const auto before = i > 0 ? Step(rho, alpha, phi, i, i - 1, max_normal_turn) : std::nullopt;
    const auto after = i + 1 < n ? Step(rho, alpha, phi, i, i + 1, max_normal_turn) : std::nullopt;
    // Central where both neighbours are usable: (alpha_{i+1} - alpha_{i-1}) / (s_{i+1} - s_{i-1}).
    double d_alpha = 0.0, d_s = 0.0;
    if (before) {
      d_alpha -= before->first;
      d_s -= before->second;
    }
    if (after) {
      d_alpha += after->first;
      d_s += after->second;
    }
    if (d_s != 0.0) kappa[i] = d_alpha / d_s;
  }
  return kappa;
}

}  // namespace priormap::priorlets
