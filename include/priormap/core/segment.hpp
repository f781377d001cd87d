#pragma once
/// Line segments, and distances of points to segments and to infinite lines.

#include <optional>
#include <utility>

#include <priormap/core/types.hpp>

namespace priormap {

struct Segment {
  Vec2 a = Vec2::Zero();
  Vec2 b = Vec2::Zero();

  [[nodiscard]] double Length() const { return (b - a).norm(); }
  /// Unit vector from a to b (zero for a degenerate segment).
  [[nodiscard]] Vec2 Direction() const;
  /// Unit normal, Direction() rotated by +90 degrees (points to the left of a -> b).
  [[nodiscard]] Vec2 Normal() const { return Perp(Direction()); }
  /// a + t (b - a).
  [[nodiscard]] Vec2 PointAt(double t) const { return a + t * (b - a); }
  [[nodiscard]] Vec2 Midpoint() const { return 0.5 * (a + b); }
  [[nodiscard]] Box2 Bounds() const;
};

/// The point of `segment` closest to `p`; `t` (optional) receives its parameter in [0, 1].
[[nodiscard]] Vec2 ClosestPointOnSegment(const Segment& segment, const Vec2& p,
                                         double* t = nullptr);

/// Euclidean distance from `p` to `segment`. J_distance_p (1x2) is the unit vector from the
/// closest point to p, and zero where the distance is zero (the derivative does not exist).
[[nodiscard]] double PointSegmentDistance(const Vec2& p, const Segment& segment,
                                          Row2* J_distance_p = nullptr);

/// Signed orthogonal distance from `p` to the infinite line through a and b, positive when p is
/// to the left of a -> b: cross(b - a, p - a) / |b - a|. This is the implicit point-on-line
/// function of prior-map SLAM (Parsley & Julier, Sec. IV). Precondition: a != b.
[[nodiscard]] double SignedLineDistance(const Vec2& p, const Vec2& a, const Vec2& b,
                                        Row2* J_d_p = nullptr, Row2* J_d_a = nullptr,
                                        Row2* J_d_b = nullptr);

/// The intersection point of two closed segments, if they meet in exactly one point
/// (collinear overlapping segments give nullopt).
[[nodiscard]] std::optional<Vec2> IntersectSegments(const Segment& s, const Segment& t);

/// The parameters [t0, t1] of the part of a + t (b - a), t in [0, 1], inside the closed box
/// (Liang & Barsky); t0 > t1 when there is none. Exactly 0 and 1 for an end inside the box, so
/// that a caller can keep the end itself rather than a + 1 (b - a).
[[nodiscard]] std::pair<double, double> ClipParametersToBox(const Vec2& a, const Vec2& b,
                                                            const Box2& box);

/// The part of `segment` inside the closed box (Liang & Barsky), if any; a segment that only
/// touches the box gives a single point (a == b).
[[nodiscard]] std::optional<Segment> ClipSegmentToBox(const Segment& segment, const Box2& box);

}  // namespace priormap
