#include <algorithm>
#include <cmath>
#include <utility>

#include <priormap/core/check.hpp>
#include <priormap/core/segment.hpp>

namespace priormap {

Vec2 Segment::Direction() const {
  const Vec2 d = b - a;
  const double length = d.norm();
  return length > 0.0 ? Vec2(d / length) : Vec2::Zero();
}

Box2 Segment::Bounds() const {
  Box2 box(a);
  box.extend(b);
  return box;
}

Vec2 ClosestPointOnSegment(const Segment& segment, const Vec2& p, double* t) {
  const Vec2 d = segment.b - segment.a;
  const double length_sq = d.squaredNorm();
  const double u = length_sq > 0.0 ? std::clamp((p - segment.a).dot(d) / length_sq, 0.0, 1.0) : 0.0;
  if (t) *t = u;
  return segment.a + u * d;
}

double PointSegmentDistance(const Vec2& p, const Segment& segment, Row2* J_distance_p) {
  const Vec2 delta = p - ClosestPointOnSegment(segment, p);
  const double distance = delta.norm();
  if (J_distance_p) {
    *J_distance_p = distance > 0.0 ? Row2(delta.transpose() / distance) : Row2::Zero();
  }
  return distance;
}

double SignedLineDistance(const Vec2& p, const Vec2& a, const Vec2& b, Row2* J_d_p, Row2* J_d_a,
                          Row2* J_d_b) {
  const Vec2 u = b - a;
  const Vec2 w = p - a;
  const double length = u.norm();
  PRIORMAP_CHECK(length > 0.0, "SignedLineDistance needs two distinct line points");
  const double cross = Cross(u, w);
  const double d = cross / length;
  const Row2 dd_dp = Perp(u).transpose() / length;
  // d cross / d u = (w.y, -w.x); d |u| / d u = u^T / |u|.
  const Row2 dd_db = Row2(w.y(), -w.x()) / length - d * u.transpose() / (length * length);
  if (J_d_p) *J_d_p = dd_dp;
  if (J_d_b) *J_d_b = dd_db;
  if (J_d_a) *J_d_a = -dd_dp - dd_db;  // translating p, a and b together leaves d unchanged
  return d;
}

std::optional<Vec2> IntersectSegments(const Segment& s, const Segment& t) {
  const Vec2 r = s.b - s.a;
  const Vec2 q = t.b - t.a;
  const double denominator = Cross(r, q);
  if (denominator == 0.0) return std::nullopt;
  const Vec2 w = t.a - s.a;
  const double u = Cross(w, q) / denominator;
  const double v = Cross(w, r) / denominator;
  if (u < 0.0 || u > 1.0 || v < 0.0 || v > 1.0) return std::nullopt;
  return s.a + u * r;
}

std::pair<double, double> ClipParametersToBox(const Vec2& a, const Vec2& b, const Box2& box) {
  const Vec2 d = b - a;
  double t0 = 0.0, t1 = 1.0;
  for (int k = 0; k < 2; ++k) {
    for (const auto& [p, q] :
         {std::pair{-d[k], a[k] - box.min()[k]}, std::pair{d[k], box.max()[k] - a[k]}}) {
      if (p == 0.0) {
        if (q < 0.0) return {1.0, 0.0};
        continue;
      }
      const double t = q / p;
      if (p < 0.0)
        t0 = std::max(t0, t);
      else
        t1 = std::min(t1, t);
    }
  }
  return {t0, t1};
}

std::optional<Segment> ClipSegmentToBox(const Segment& segment, const Box2& box) {
  const auto [t0, t1] = ClipParametersToBox(segment.a, segment.b, box);
  if (t0 > t1) return std::nullopt;
  const Vec2 d = segment.b - segment.a;
  return Segment{segment.a + t0 * d, segment.a + t1 * d};
}

}  // namespace priormap
