#pragma once
/// What a sonar cone sees of a coloring (Paskin & Thrun, Sec. 2.3, Fig. 3): the faces (parts of
/// edges, possibly partly hidden) and the corners (vertices) visible from the apex within the
/// cone and within R, found by a radial sweep over the edges that overlap the cone (Lee's radial
/// scan line) with O(k log k) comparisons for k edges.
///
/// The result depends only on the set of segments, not on their order or on the order of their
/// ends (each segment is taken with its ends in a canonical order, and ties between segments are
/// broken by their coordinates). So the view computed for a proposed edit (the coloring's edges
/// minus the removed ones, plus the added segments) equals, bit for bit, the one computed on the
/// coloring once the edit is applied.

#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include <priormap/core/segment.hpp>
#include <priormap/prf/sonar_data.hpp>
#include <priormap/prf/window.hpp>

namespace priormap::prf {

/// A segment given to the sweep, with a tag the caller uses to recognise it (an edge id, say).
struct TaggedSegment {
  Segment segment;
  std::int32_t tag = 0;
};

/// A feature that may echo (Paskin & Thrun, Sec. 2.3).
struct SonarFeature {
  enum class Kind : std::uint8_t { kFace = 0, kCorner = 1 };
  Kind kind = Kind::kFace;
  /// To the corner, or to the closest point of the face's visible part, m.
  double distance = 0.0;
  /// Faces: the angle between the wave to the closest point and the face, in (0, pi/2]; pi/2
  /// when the foot of the perpendicular from the apex is visible (normal incidence).
  double projection = 0.0;
  /// Faces: the angle the visible part subtends at the apex, rad.
  double subtended = 0.0;
  /// Corners: seen from inside, the two edges meeting at less than 180° on the apex's side (a
  /// corner reflector, which echoes strongly); false for a corner seen from outside (a tip,
  /// which only diffracts).
  bool concave = false;
};

/// One angular interval of the cone (angles relative to its axis, in [-h, h]) and the segment
/// seen through it: an index into the sweep's input, or -1 when nothing is seen within R.
struct VisiblePiece {
  double from = 0.0;
  double to = 0.0;
  int segment = -1;
};

struct SonarView {
  /// Consecutive pieces covering [-h, h]; neighbours see different segments.
  std::vector<VisiblePiece> pieces;
  /// Faces (one per piece that sees a segment) and corners, in depth order.
  std::vector<SonarFeature> features;
  /// The visible corners (vertices of the input segments not on the window's boundary),
  /// sorted by their coordinates.
  std::vector<Vec2> corners;
  /// Tags of the segments seen (the faces' segments), sorted, without repeats.
  std::vector<std::int32_t> contact_tags;
  /// The farthest point seen: R where some direction sees nothing.
  double extent = 0.0;
  /// The share of the cone's angle through which a face is seen within R (1: the sound meets
  /// a surface in every direction; 0: nothing within R to reflect it).
  double seen_fraction = 0.0;
};

/// A cone's half-angle with its trigonometry, kept while consecutive cones share it.
struct SectorTrig {
  double h = -1.0, cos_h = 0.0, sin_h = 0.0, tan_h = 0.0;
  static SectorTrig Of(double h) { return {h, std::cos(h), std::sin(h), std::tan(h)}; }
};

/// The radial sweep, with scratch space reused from call to call (copies start empty).
class ConeSweep {
 public:
  ConeSweep() = default;
  ConeSweep(const ConeSweep&) : ConeSweep() {}
  ConeSweep& operator=(const ConeSweep&) { return *this; }

  /// The view of `cone` given the segments that may overlap it (others are clipped away).
  /// Segment ends on the window's boundary are not corners (they are boundary vertices).
  void Compute(const SonarCone& cone, std::span<const TaggedSegment> segments, const Window& window,
               SonarView* view);

 private:
  // A segment clipped to the cone, in the cone's frame (x along the axis). Directions within
  // the cone (|angle| < pi/2) are ordered by their slope tau = y / x, which needs no
  // trigonometry: the sweep runs over tau.
  struct Clipped {
    Vec2 a, b;    // the whole segment (its ends in canonical order)
    Vec2 lo, hi;  // the clipped part's ends, lo at the smaller slope
    double tau_lo = 0.0, tau_hi = 0.0;
    double lo_distance = 0.0, hi_distance = 0.0;  // from the apex, at most R
    double numerator = 0.0;  // Cross(a, b): along a ray u the segment is at this / Cross(u, b - a)
    int lo_end = -1, hi_end = -1;  // 0: a, 1: b when the clipped end is the segment's own
    bool lo_corner = false, hi_corner = false;  // ... and a vertex off the window's boundary
    Vec2 world_a, world_b;
    int input = 0;  // index into the caller's segments
  };
  // Orders active segments by their distance along a ray both cover beyond the current event
  // (the middle of their common span; ties, which only overlapping segments could make, by
  // their coordinates); segments active together never cross, so the order holds from one
  // event to the next.
  struct Nearer {
    const ConeSweep* sweep;
    bool operator()(std::uint32_t i, std::uint32_t j) const;
  };

  // Along the ray (1, tau): the segment's line meets it at DistanceAt(c, tau) * (1, tau).
  [[nodiscard]] static double DistanceAt(const Clipped& c, double tau) {
    return c.numerator / Cross(Vec2(1.0, tau), c.b - c.a);
  }
  void Clip(const SonarCone& cone, std::span<const TaggedSegment> segments, const Window& window);
  void Sweep(double tan_half, SonarView* view);
  void Features(const SonarCone& cone, std::span<const TaggedSegment> segments, SonarView* view);

  std::vector<Clipped> clipped_;
  std::vector<double> taus_;
  std::vector<std::uint32_t> start_order_;
  std::vector<std::uint32_t> end_order_;
  // The segments spanning the current interval, nearest first: a sorted vector, cheaper than
  // a tree for the handful of edges a cone holds.
  std::vector<std::uint32_t> active_;
  double event_tau_ = 0.0;  ///< slope of the current event (where starting segments are placed)
  SectorTrig trig_;
};

/// True when the segment may meet the cone within `radius` (conservative: a hair wider).
[[nodiscard]] bool SegmentMeetsCone(const Segment& segment, const SonarCone& cone, double radius);

}  // namespace priormap::prf
