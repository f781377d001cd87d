// The extrinsic Jacobian (Sec. IV-B, eq. (8)) against the simulator's ray caster: the sensor is
// moved by +-h in the body frame and the scene re-cast, so every column is a true derivative of
// what the simulator would report.

#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <variant>
#include <vector>

#include <Eigen/Core>
#include <gtest/gtest.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/check.hpp>
#include <priormap/core/range_sensor.hpp>
#include <priormap/core/scan.hpp>
#include <priormap/core/scene.hpp>
#include <priormap/core/scene_ray_caster.hpp>
#include <priormap/core/se2.hpp>
#include <priormap/priorlets/extrinsic.hpp>

#include "testing/numeric_diff.hpp"

namespace priormap::priorlets {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kStep = 1e-6;          // finite-difference step, m and rad
constexpr double kTolerance = 1e-5;     // relative (absolute below 1)
constexpr double kMinCheckedCos = 0.1;  // beams closer to grazing are not compared

// What the simulator reports for each beam from `pose` (T_world_sensor): range, normal in the
// sensor frame (SimulateScan's truth.alpha), region; NaN and -1 where nothing is hit.
struct CastResult {
  std::vector<double> rho, alpha;
  std::vector<int> region;
};

CastResult Cast(const SceneRayCaster& caster, const Se2& pose, const std::vector<double>& phi) {
  CastResult out;
  for (const double p : phi) {
    const auto hit = caster.Cast({pose.translation(), pose.theta() + p},
                                 std::numeric_limits<double>::infinity());
    out.rho.push_back(hit ? hit->range : kNaN);
    out.alpha.push_back(hit ? WrapAngle(hit->normal_angle - pose.theta()) : kNaN);
    out.region.push_back(hit ? hit->region : -1);
  }
  return out;
}

Se2 BodyPerturbed(const Se2& pose, const Eigen::VectorXd& dq) {
  return pose.Compose(Se2(dq[0], dq[1], dq[2]));
}

// d x / d dq by central differences, x = (rho, alpha) cast from the pose `moved(dq)` (alpha
// differences wrapped, so a reading crossing +-pi does not jump).
Eigen::MatrixXd NumericExtrinsicJacobian(const SceneRayCaster& caster,
                                         const std::vector<double>& phi,
                                         const std::function<Se2(const Eigen::VectorXd&)>& moved) {
  const auto n = static_cast<Eigen::Index>(phi.size());
  const auto scan = [&](const Eigen::VectorXd& dq) {
    const CastResult r = Cast(caster, moved(dq), phi);
    Eigen::VectorXd x(2 * n);
    for (Eigen::Index i = 0; i < n; ++i) {
      x[i] = r.rho[static_cast<std::size_t>(i)];
      x[n + i] = r.alpha[static_cast<std::size_t>(i)];
    }
    return x;
  };
  const auto wrap_alpha = [n](Eigen::VectorXd d) {
    for (Eigen::Index i = n; i < 2 * n; ++i) d[i] = WrapAngle(d[i]);
    return d;
  };
  return testing::NumericJacobian(scan, Eigen::VectorXd::Zero(3), kStep, wrap_alpha);
}

// Beams on which the ray caster is smooth across the finite-difference stencil (the same region
// hit from all seven poses: no corner, edge or occlusion boundary in between) and not grazing.
std::vector<bool> SmoothBeams(const SceneRayCaster& caster, const Se2& pose,
                              const std::vector<double>& phi) {
  const CastResult base = Cast(caster, pose, phi);
  std::vector<bool> smooth(phi.size());
  for (std::size_t i = 0; i < phi.size(); ++i) {
    smooth[i] = base.region[i] >= 0 && std::abs(std::cos(base.alpha[i] - phi[i])) > kMinCheckedCos;
  }
  for (int axis = 0; axis < 3; ++axis) {
    for (const double sign : {-1.0, 1.0}) {
      Eigen::VectorXd dq = Eigen::VectorXd::Zero(3);
      dq[axis] = sign * kStep;
      const CastResult moved = Cast(caster, BodyPerturbed(pose, dq), phi);
      for (std::size_t i = 0; i < phi.size(); ++i) {
        if (moved.region[i] != base.region[i]) smooth[i] = false;
      }
    }
  }
  return smooth;
}

// The curvature the scene geometry gives each hit: 0 on segments; on circles +1/R seen from
// inside (concave) and -1/R from outside (convex).
std::vector<double> TrueCurvature(const SceneRayCaster& caster, const Se2& pose,
                                  const std::vector<int>& region) {
  std::vector<double> kappa(region.size(), kNaN);
  for (std::size_t i = 0; i < region.size(); ++i) {
    if (region[i] < 0) continue;
    const auto& shape = caster.primitives()[static_cast<std::size_t>(region[i])].shape;
    if (const auto* circle = std::get_if<Circle>(&shape)) {
      kappa[i] = (circle->Contains(pose.translation()) ? 1.0 : -1.0) / circle->radius;
    } else {
      kappa[i] = 0.0;
    }
  }
  return kappa;
}

// The 2x3 block of beam i (its rho and alpha rows).
Eigen::MatrixXd Beam(const Eigen::MatrixXd& J, std::size_t i) {
  const auto n = J.rows() / 2;
  const auto r = static_cast<Eigen::Index>(i);
  Eigen::MatrixXd block(2, 3);
  block.row(0) = J.row(r);
  block.row(1) = J.row(n + r);
  return block;
}

// Compares the analytic Jacobian with re-casting on every smooth beam; returns how many.
int ExpectMatchesRayCaster(const Scene& scene, const Se2& pose, const std::vector<double>& phi) {
  const SceneRayCaster caster(scene);
  const CastResult base = Cast(caster, pose, phi);
  const std::vector<double> kappa = TrueCurvature(caster, pose, base.region);
  const Eigen::MatrixXd analytic = ExtrinsicJacobian(base.rho, base.alpha, phi, kappa);
  const Eigen::MatrixXd numeric = NumericExtrinsicJacobian(
      caster, phi, [&](const Eigen::VectorXd& dq) { return BodyPerturbed(pose, dq); });
  const std::vector<bool> smooth = SmoothBeams(caster, pose, phi);
  int checked = 0;
  for (std::size_t i = 0; i < phi.size(); ++i) {
    if (!smooth[i]) continue;
    ++checked;
    EXPECT_TRUE(testing::JacobiansMatch(Beam(analytic, i), Beam(numeric, i), kTolerance))
        << scene.name << " beam " << i << " phi " << phi[i] << " kappa " << kappa[i];
  }
  return checked;
}

Scene WallScene(const Vec2& a, const Vec2& b) {
  Scene scene;
  scene.name = "wall";
  scene.surfaces.push_back({Polyline{{a, b}, false}, false, "wall"});
  return scene;
}

Scene PillarScene(const Vec2& center, double radius) {
  Scene scene;
  scene.name = "pillar";
  scene.surfaces.emplace_back().shape.emplace<Circle>(Circle{center, radius});
  return scene;
}

std::vector<double> Utm30Angles() {
  return RangeSensor::Preset("utm30")->BeamAngles();
}

TEST(ExtrinsicJacobian, StraightWallMatchesRayCasterAtSeveralIncidences) {
  // A slanted 180 m wall; beams aimed at it at set incidence angles from a rotated sensor.
  const Vec2 a(-40.0, -79.0), b(50.0, 77.0);
  const Se2 pose(0.2, -0.3, 0.4);
  Vec2 away = Perp((b - a).normalized());  // the wall's normal pointing away from the sensor
  if (away.dot(a - pose.translation()) < 0.0) away = -away;
  const double towards_wall = std::atan2(away.y(), away.x());
  std::vector<double> phi;
  for (const double incidence_deg : {-80.0, -60.0, -30.0, -5.0, 0.0, 20.0, 45.0, 70.0, 84.0}) {
    phi.push_back(WrapAngle(towards_wall + DegToRad(incidence_deg) - pose.theta()));
  }
  EXPECT_EQ(ExpectMatchesRayCaster(WallScene(a, b), pose, phi), static_cast<int>(phi.size()));
}

TEST(ExtrinsicJacobian, InsideCircularRoomMatchesRayCaster) {
  const Scene scene = *BuiltinScene("circle");  // radius 2 m: kappa = +0.5 / m
  const std::vector<double> phi = EvenlySpacedAngles(360, -kPi + kTwoPi / 360, kPi);
  for (const Se2& pose : {*scene.default_pose, Se2(-1.2, 0.7, -2.5), Se2(0.3, 1.6, 3.0)}) {
    EXPECT_EQ(ExpectMatchesRayCaster(scene, pose, phi), 360) << pose.ToString();
  }
}

TEST(ExtrinsicJacobian, OutsideCircularPillarMatchesRayCaster) {
  const Vec2 center(2.5, 1.0);
  const double radius = 0.8;  // kappa = -1.25 / m seen from outside
  const Se2 pose(0.1, -0.2, 0.7);
  const Vec2 to_center = center - pose.translation();
  const double bearing = std::atan2(to_center.y(), to_center.x()) - pose.theta();
  const double half_width = std::asin(radius / to_center.norm());
  const std::vector<double> phi =
      EvenlySpacedAngles(201, bearing - half_width, bearing + half_width);
  EXPECT_GT(ExpectMatchesRayCaster(PillarScene(center, radius), pose, phi), 150);
}

TEST(ExtrinsicJacobian, FullUtm30ScanOfSquareMatchesRayCaster) {
  const Scene scene = *BuiltinScene("square");
  const std::vector<double> phi = Utm30Angles();
  for (const Se2& pose : {*scene.default_pose, Se2(0.7, 0.4, -2.0)}) {
    EXPECT_GT(ExpectMatchesRayCaster(scene, pose, phi), 950) << pose.ToString();
  }
}

TEST(ExtrinsicJacobian, FullUtm30ScanOfLRoomMatchesRayCaster) {
  // Walls, a clutter box (segments) and a bin (a small convex circle) in view.
  const Scene scene = *BuiltinScene("l-room");
  const std::vector<double> phi = Utm30Angles();
  for (const Se2& pose : {*scene.default_pose, Se2(-2.0, -1.2, -1.2), Se2(1.5, -1.5, 2.8)}) {
    EXPECT_GT(ExpectMatchesRayCaster(scene, pose, phi), 850) << pose.ToString();
  }
}

TEST(ExtrinsicJacobian, AlphaRowsHaveNoWrapJumps) {
  // Sensor heading 0 facing the square's east wall: its normal is at alpha = pi in the sensor
  // frame, and rotating by -h takes it to -pi + h. The rows must be those of unwrapped alpha.
  const Scene scene = *BuiltinScene("square");
  const Se2 pose(0.3, 0.2, 0.0);
  const std::vector<double> phi = EvenlySpacedAngles(41, -0.6, 0.6);
  const SceneRayCaster caster(scene);
  const CastResult base = Cast(caster, pose, phi);
  for (const double alpha : base.alpha) ASSERT_NEAR(std::abs(alpha), kPi, 1e-12);
  EXPECT_EQ(ExpectMatchesRayCaster(scene, pose, phi), 41);

  // Any 2 pi representative of alpha gives the same rows.
  const std::vector<double> kappa(phi.size(), 0.3);
  const Eigen::MatrixXd J = ExtrinsicJacobian(base.rho, base.alpha, phi, kappa);
  for (const double shift : {-kTwoPi, kTwoPi, 2 * kTwoPi}) {
    std::vector<double> shifted = base.alpha;
    for (double& a : shifted) a += shift;
    EXPECT_TRUE(J.isApprox(ExtrinsicJacobian(base.rho, shifted, phi, kappa), 1e-12));
  }
}

TEST(ExtrinsicJacobian, WorldFrameParametersFollowFromSe2Compose) {
  // d x / d (x, y, theta)_world = J_body * diag(R^T, 1): the inverse of Compose's J_out_other.
  const Scene scene = *BuiltinScene("circle");
  const Se2 pose(-0.6, 0.9, 2.2);
  const std::vector<double> phi = EvenlySpacedAngles(90, -kPi + kTwoPi / 90, kPi);
  const SceneRayCaster caster(scene);
  const CastResult base = Cast(caster, pose, phi);
  const Eigen::MatrixXd body =
      ExtrinsicJacobian(base.rho, base.alpha, phi, std::vector<double>(phi.size(), 0.5));
  Mat3 J_out_other;
  (void)pose.Compose(Se2(), nullptr, &J_out_other);
  const Eigen::MatrixXd world = body * J_out_other.inverse();
  const Eigen::MatrixXd numeric =
      NumericExtrinsicJacobian(caster, phi, [&](const Eigen::VectorXd& dq) {
        return Se2(pose.x() + dq[0], pose.y() + dq[1], pose.theta() + dq[2]);
      });
  EXPECT_TRUE(testing::JacobiansMatch(world, numeric, kTolerance));
}

TEST(ExtrinsicJacobian, CentreOfCircularRoomHasClosedForm) {
  // From the centre every range is R and every alpha is phi + pi, whatever the heading; a step
  // dx shortens the beam phi = 0 by dx and turns the normal of beam phi by -sin(phi) dx / R.
  const double R = 2.0;
  const std::vector<double> phi = {-2.0, -0.5, 0.0, 1.0, 3.0};
  std::vector<double> rho(phi.size(), R), alpha;
  for (const double p : phi) alpha.push_back(WrapAngle(p + kPi));
  const Eigen::MatrixXd J = ExtrinsicJacobian(rho, alpha, phi, std::vector<double>(5, 1.0 / R));
  for (std::size_t i = 0; i < phi.size(); ++i) {
    const auto r = static_cast<Eigen::Index>(i);
    EXPECT_NEAR(J(r, 0), -std::cos(phi[i]), 1e-12);
    EXPECT_NEAR(J(r, 1), -std::sin(phi[i]), 1e-12);
    EXPECT_NEAR(J(r, 2), 0.0, 1e-12);
    EXPECT_NEAR(J(5 + r, 0), -std::sin(phi[i]) / R, 1e-12);
    EXPECT_NEAR(J(5 + r, 1), std::cos(phi[i]) / R, 1e-12);
    EXPECT_NEAR(J(5 + r, 2), 0.0, 1e-12);
  }
}

TEST(ExtrinsicJacobian, GrazingBeamsAreClampedAndFlagged) {
  // Beam 0 grazes a wall (incidence 89.94 degrees); beam 1 hits one at 72.5 degrees.
  const std::vector<double> rho = {2.0, 3.0}, phi = {0.0, 0.5};
  const std::vector<double> alpha = {kPi / 2 + 1e-3, 0.5 + kPi - 1.265};
  std::vector<std::uint8_t> clamped;
  const Eigen::MatrixXd J = ExtrinsicJacobian(rho, alpha, phi, {}, 0.05, &clamped);
  ASSERT_TRUE(J.allFinite());
  EXPECT_EQ(clamped, (std::vector<std::uint8_t>{1, 0}));
  // Beam 0 as if cos beta were -0.05 (its sign kept: the normal faces the sensor).
  const double sin_beta = std::sin(alpha[0] - phi[0]);
  EXPECT_NEAR(J(0, 0), std::cos(alpha[0]) / 0.05, 1e-12);
  EXPECT_NEAR(J(0, 1), std::sin(alpha[0]) / 0.05, 1e-12);
  EXPECT_NEAR(J(0, 2), rho[0] * sin_beta / 0.05, 1e-12);
  EXPECT_DOUBLE_EQ(J(2, 2), -1.0);
  // Clamping leaves the other beams alone.
  const Eigen::MatrixXd loose = ExtrinsicJacobian(rho, alpha, phi, {}, 1e-9);
  EXPECT_EQ(Beam(J, 1), Beam(loose, 1));
  EXPECT_GT(std::abs(loose(0, 2)), 1e3);  // what the unclamped grazing beam would give
}

TEST(ExtrinsicJacobian, NonFiniteBeamsGiveNaNRowsAndBadSizesThrow) {
  const std::vector<double> rho = {1.0, kNaN, 2.0}, phi = {-0.1, 0.0, 0.1};
  const std::vector<double> alpha = {kPi, kPi, kPi}, kappa = {0.0, 0.0, kNaN};
  const Eigen::MatrixXd J = ExtrinsicJacobian(rho, alpha, phi, kappa);
  EXPECT_TRUE(J.row(0).allFinite() && J.row(3).allFinite());
  EXPECT_TRUE(J.row(1).array().isNaN().all() && J.row(4).array().isNaN().all());
  EXPECT_TRUE(J.row(2).array().isNaN().all() && J.row(5).array().isNaN().all());
  EXPECT_EQ(ExtrinsicJacobian({}, {}, {}, {}).rows(), 0);
  EXPECT_THROW((void)ExtrinsicJacobian(rho, alpha, std::vector<double>(2), {}), ContractError);
  EXPECT_THROW((void)ExtrinsicJacobian(rho, alpha, phi, std::vector<double>(2)), ContractError);
  EXPECT_THROW((void)ExtrinsicJacobian(rho, alpha, phi, {}, 0.0), ContractError);
}

TEST(ExtrinsicEstimateCurvature, RecoversConcaveCircleFromExactScan) {
  const Scene scene = *BuiltinScene("circle");
  const std::vector<double> phi = Utm30Angles();
  const SceneRayCaster caster(scene);
  for (const Se2& pose : {*scene.default_pose, Se2(-1.2, 0.7, -2.5)}) {
    const CastResult scan = Cast(caster, pose, phi);
    const std::vector<double> kappa = EstimateCurvature(scan.rho, scan.alpha, phi);
    for (std::size_t i = 0; i < phi.size(); ++i) {  // ends included (one-sided there)
      EXPECT_NEAR(kappa[i], 0.5, 0.01) << pose.ToString() << " beam " << i;
    }
    // Wrapped (as the simulator reports) or unwrapped alpha: the same estimate.
    const std::vector<double> unwrapped = UnwrapAngles(scan.alpha);
    const std::vector<double> again = EstimateCurvature(scan.rho, unwrapped, phi);
    for (std::size_t i = 0; i < phi.size(); ++i) EXPECT_NEAR(again[i], kappa[i], 1e-9);
  }
}

TEST(ExtrinsicEstimateCurvature, RecoversConvexPillarWithNegativeSign) {
  const Vec2 center(2.5, 1.0);
  const double radius = 0.8;
  const Se2 pose(0.1, -0.2, 0.7);
  const Vec2 to_center = center - pose.translation();
  const double bearing = std::atan2(to_center.y(), to_center.x()) - pose.theta();
  const double half_width = std::asin(radius / to_center.norm());
  const std::vector<double> phi =
      EvenlySpacedAngles(201, bearing - half_width, bearing + half_width);
  const CastResult scan = Cast(SceneRayCaster(PillarScene(center, radius)), pose, phi);
  const std::vector<double> kappa = EstimateCurvature(scan.rho, scan.alpha, phi);
  int checked = 0;
  for (std::size_t i = 0; i < phi.size(); ++i) {
    if (!(std::abs(std::cos(scan.alpha[i] - phi[i])) > 0.2)) continue;
    ++checked;
    EXPECT_NEAR(kappa[i], -1.0 / radius, 0.02 / radius) << "beam " << i;
  }
  EXPECT_GT(checked, 150);
}

TEST(ExtrinsicEstimateCurvature, StraightWallsAndCornersGiveZero) {
  const Scene wall = WallScene({-10.0, -27.0}, {20.0, 25.0});
  const Se2 wall_pose(0.2, -0.3, -1.0);
  const std::vector<double> wall_phi = EvenlySpacedAngles(200, -1.2, 1.2);
  const CastResult wall_scan = Cast(SceneRayCaster(wall), wall_pose, wall_phi);
  for (const double k : EstimateCurvature(wall_scan.rho, wall_scan.alpha, wall_phi)) {
    EXPECT_NEAR(k, 0.0, 1e-9);
  }
  // The square: the normal turns by 90 degrees at each corner, which is not curvature.
  const Scene square = *BuiltinScene("square");
  const std::vector<double> phi = Utm30Angles();
  const CastResult scan = Cast(SceneRayCaster(square), *square.default_pose, phi);
  for (const double k : EstimateCurvature(scan.rho, scan.alpha, phi)) EXPECT_NEAR(k, 0.0, 1e-9);
}

TEST(ExtrinsicEstimateCurvature, MissingNeighboursFallBackToOneSidedThenZero) {
  // Beams from the centre of a circle of radius 2 (kappa = 0.5), with holes.
  const std::vector<double> phi = EvenlySpacedAngles(9, -0.4, 0.4);
  std::vector<double> rho(phi.size(), 2.0), alpha;
  for (const double p : phi) alpha.push_back(p + kPi);
  rho[2] = kNaN;  // beam 3 has only its right neighbour
  rho[5] = kNaN;  // with alpha[7] below: beam 6 has no neighbour, beam 8 (an end) neither
  alpha[7] = kNaN;
  const std::vector<double> kappa = EstimateCurvature(rho, alpha, phi);
  EXPECT_NEAR(kappa[0], 0.5, 1e-3);  // end: one-sided
  EXPECT_NEAR(kappa[1], 0.5, 1e-3);
  EXPECT_EQ(kappa[2], 0.0);  // not a reading
  EXPECT_NEAR(kappa[3], 0.5, 1e-3);
  EXPECT_NEAR(kappa[4], 0.5, 1e-3);
  EXPECT_EQ(kappa[6], 0.0);  // isolated: straight
  EXPECT_EQ(kappa[8], 0.0);
  EXPECT_EQ(EstimateCurvature(std::vector<double>{1.0}, std::vector<double>{kPi},
                              std::vector<double>{0.0}),
            std::vector<double>{0.0});
  EXPECT_TRUE(EstimateCurvature({}, {}, {}).empty());
  EXPECT_THROW((void)EstimateCurvature(rho, alpha, std::vector<double>(3)), ContractError);
}

}  // namespace
}  // namespace priormap::priorlets
