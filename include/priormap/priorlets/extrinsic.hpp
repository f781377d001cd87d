#pragma once
/// The extrinsic degrees of freedom of an augmented scan (Sec. IV-B, eq. (8)): how the readings
/// x = (rho_0..rho_{n-1}, alpha_0..alpha_{n-1}) move when the sensor moves and the map does not.
/// Extr = span of the columns of this Jacobian; Intr = Free - Extr.
///
/// Conventions (those of core's ray caster and simulator, i.e. Censi's CSM `laser_data`):
/// - phi_i: beam angle in the sensor frame; rho_i: range, m; alpha_i: angle of the surface normal
///   at the hit, in the sensor frame, pointing back at the sensor (cos(alpha_i - phi_i) < 0).
///   Angles may be wrapped or unwrapped: only their sines and cosines are used, so the alpha rows
///   are derivatives of a continuous (unwrapped) alpha and never contain 2 pi jumps.
/// - The pose variation is body-frame: the sensor moves from T_world_sensor to
///   T_world_sensor.Compose(Se2(dx, dy, dtheta)) (q (+) dq), so dx is along the beam phi = 0.
///   For derivatives with respect to the world-frame parameters (x, y, theta) of the pose, as
///   Se2's Jacobians are, multiply on the right by diag(R(theta)^T, 1) (the inverse of Compose's
///   J_out_other at dq = 0). Both give the same span, hence the same Extr.
/// - Curvature kappa_i, 1/m, is d alpha / d s, where s is arc length along the surface in the
///   direction in which the hit moves when phi increases. So kappa > 0 where the surface is
///   concave as seen from the sensor (+1/R inside a circular room of radius R), kappa < 0 where
///   convex (-1/R outside a pillar), 0 on a straight wall. It does not depend on which way the
///   normal points.

#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>

namespace priormap::priorlets {

/// Beams whose |cos(alpha_i - phi_i)| is below this (incidence beyond ~87 degrees) are treated as
/// if it were this: at grazing incidence the derivatives grow as 1 / cos and would dominate Extr
/// with directions that measure nothing but the grazing geometry.
inline constexpr double kDefaultMinIncidenceCos = 0.05;

/// Neighbouring normals that turn by more than this (rad) are taken to be on different surfaces
/// (a corner or a depth jump), not samples of one curved surface.
inline constexpr double kDefaultMaxNormalTurn = 0.5;

/// The Jacobian d x / d q of the augmented scan with respect to a body-frame sensor motion
/// q (+) (dx, dy, dtheta), the map fixed: 2n x 3, rows rho_0..rho_{n-1} then
/// alpha_0..alpha_{n-1}, columns dx, dy, dtheta. With beta_i = alpha_i - phi_i:
///   d rho_i   = -(cos alpha_i dx + sin alpha_i dy + rho_i sin beta_i dtheta) / cos beta_i
///   d alpha_i = kappa_i ds_i - dtheta,  ds_i = (-sin phi_i dx + cos phi_i dy + rho_i dtheta)
///                                               / |cos beta_i|
/// (ds_i: the slide of the hit along the surface; the range is first-order insensitive to
/// curvature). `curvature` is empty (all surfaces straight) or has n entries, e.g. from the scene
/// or EstimateCurvature. Grazing beams (|cos beta_i| < min_incidence_cos) are computed with
/// |cos beta_i| = min_incidence_cos, keeping its sign, and marked 1 in `clamped` (resized to n)
/// when given. A beam with a non-finite input gets NaN rows. Preconditions: equal sizes,
/// 0 < min_incidence_cos <= 1.
[[nodiscard]] Eigen::Matrix<double, Eigen::Dynamic, 3> ExtrinsicJacobian(
    std::span<const double> rho, std::span<const double> alpha, std::span<const double> phi,
    std::span<const double> curvature, double min_incidence_cos = kDefaultMinIncidenceCos,
    std::vector<std::uint8_t>* clamped = nullptr);

/// Curvature kappa_i (1/m, sign as above) from the scan alone, for engines that know nothing
/// better: the change of alpha between beam i's neighbours over the polyline length through the
/// three hit points. A neighbour is unusable when its rho or alpha is not finite or its normal
/// turns by more than `max_normal_turn` from beam i's (a corner); then the one-sided difference
/// with the other neighbour is used (also at the ends of the scan), and with neither, or when
/// beam i itself is not finite, kappa_i = 0 (straight: the neutral choice for ExtrinsicJacobian).
/// As any second derivative of data, it amplifies noise: feed it smoothed alpha. Preconditions:
/// equal sizes, max_normal_turn > 0.
[[nodiscard]] std::vector<double> EstimateCurvature(std::span<const double> rho,
                                                    std::span<const double> alpha,
                                                    std::span<const double> phi,
                                                    double max_normal_turn = kDefaultMaxNormalTurn);

}  // namespace priormap::priorlets
