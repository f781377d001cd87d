// Property-based tests (rapidcheck) of the geometry's invariants: SE(2) group laws and its action
// on points, and ray casting against an independent solution of the ray-segment system. Every
// failing case shrinks to a small counterexample.
#include <cmath>

#include <Eigen/Dense>
#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/ray_cast.hpp>
#include <priormap/core/se2.hpp>

namespace priormap {
namespace {

// A coordinate in [-10, 10] m and an angle in (-pi, pi], on a fine lattice so that shrinking
// moves towards simple values.
rc::Gen<double> Coordinate() {
  return rc::gen::map(rc::gen::inRange(-100000, 100001), [](int v) { return v * 1e-4; });
}
rc::Gen<double> Angle() {
  return rc::gen::map(rc::gen::inRange(-314159, 314160), [](int v) { return v * 1e-5; });
}
rc::Gen<Se2> Pose() {
  return rc::gen::apply([](double x, double y, double t) { return Se2(x, y, t); }, Coordinate(),
                        Coordinate(), Angle());
}
rc::Gen<Vec2> Point() {
  return rc::gen::apply([](double x, double y) { return Vec2(x, y); }, Coordinate(), Coordinate());
}

RC_GTEST_PROP(GeometryProperties, Se2IsAGroupActingOnThePlane, ()) {
  const Se2 a = *Pose(), b = *Pose(), c = *Pose();
  const Vec2 p = *Point();
  RC_ASSERT(IsApprox((a * b) * c, a * (b * c), 1e-9));
  RC_ASSERT(IsApprox(a * Se2(), a, 1e-12));
  RC_ASSERT(IsApprox(a * a.Inverse(), Se2(), 1e-9));
  RC_ASSERT(IsApprox(a.Inverse().Inverse(), a, 1e-9));
  // The action: (ab)p = a(bp), distances are kept, the inverse undoes it.
  RC_ASSERT(((a * b) * p - a * (b * p)).norm() < 1e-9);
  RC_ASSERT(std::abs((a * p - a * Vec2::Zero()).norm() - p.norm()) < 1e-9);
  RC_ASSERT((a.InverseTransform(a * p) - p).norm() < 1e-9);
}

RC_GTEST_PROP(GeometryProperties, RayCastAgreesWithTheRaySegmentSystem, ()) {
  const Vec2 origin = *Point();
  const double angle = *Angle();
  const Segment segment{*Point(), *Point()};
  const Vec2 direction(std::cos(angle), std::sin(angle));
  const Vec2 along = segment.b - segment.a;
  // origin + t d = a + s (b - a): solved by Eigen's LU, apart from the caster's own code.
  Eigen::Matrix2d m;
  m << direction, -along;
  const double det = m.determinant();
  // Near-parallel rays and degenerate segments are a matter of tolerance, not of the property.
  RC_PRE(std::abs(det) > 1e-6 && along.norm() > 1e-3);
  const Vec2 ts = m.partialPivLu().solve(segment.a - origin);
  const double t = ts.x(), s = ts.y();
  const auto hit = CastRay(Ray{origin, angle}, segment);
  const double margin = 1e-9;
  if (t > kMinRayRange + margin && s > margin && s < 1.0 - margin) {
    RC_ASSERT(hit.has_value());
    RC_ASSERT(std::abs(hit->range - t) < 1e-7 * std::max(1.0, t));
    // The normal is the segment's, facing the ray.
    const Vec2 normal(std::cos(hit->normal_angle), std::sin(hit->normal_angle));
    RC_ASSERT(std::abs(normal.dot(along.normalized())) < 1e-9);
    RC_ASSERT(normal.dot(direction) < 0.0);
  } else if (t < -margin || s < -margin || s > 1.0 + margin) {
    RC_ASSERT(!hit.has_value());
  }
}

}  // namespace
}  // namespace priormap
