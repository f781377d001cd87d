// The radial sweep of a sonar cone (Paskin & Thrun, Sec. 2.3, after Lee 1978): clip the edges to
// the cone's sector, sort their ends by angle, and sweep the angle with the active edges ordered
// by distance; the nearest active edge is what each direction sees. Angles within the cone are
// handled as slopes tau = tan(angle) (monotonic there), converted to angles only for the output.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <tuple>

#include <priormap/prf/sonar_visibility.hpp>

namespace priormap::prf {
namespace {

bool LexLess(const Vec2& p, const Vec2& q) {
  return p.x() < q.x() || (p.x() == q.x() && p.y() < q.y());
}

// The segment's ends in canonical order: the result of the sweep must not depend on it.
std::pair<Vec2, Vec2> Canonical(const Segment& s) {
  return LexLess(s.b, s.a) ? std::pair{s.b, s.a} : std::pair{s.a, s.b};
}

bool OnWindowBoundary(const Window& w, const Vec2& p) {
  return p.x() == w.min.x() || p.x() == w.max.x() || p.y() == w.min.y() || p.y() == w.max.y();
}

// True when the apex looks into the corner at v from inside: the two edges at v, to a and b, meet
// at less than 180° on its side, i.e. the apex lies strictly within the sector they span.
bool SeenFromInside(const Vec2& apex, const Vec2& v, const Vec2& a, const Vec2& b) {
  const Vec2 u1 = a - v, u2 = b - v, w = apex - v;
  const double span = Cross(u1, u2);
  if (span == 0.0) return false;  // a straight or folded vertex: no sector
  return Cross(u1, w) * span > 0.0 && Cross(w, u2) * span > 0.0;
}

// Whether the apex sees the vertex at v from inside (SeenFromInside), given the segments that
// may hold its two edges; a vertex with another number of edges among them counts as outside.
bool ConcaveCorner(const Vec2& apex, const Vec2& v, std::span<const TaggedSegment> segments) {
  Vec2 others[2];
  int found = 0;
  for (const TaggedSegment& t : segments) {
    const bool at_a = t.segment.a == v, at_b = t.segment.b == v;
    if (at_a == at_b) continue;
    if (found == 2) return false;
    others[found++] = at_a ? t.segment.b : t.segment.a;
  }
  return found == 2 && SeenFromInside(apex, v, others[0], others[1]);
}

Vec2 ToCone(const SonarCone& cone, const Vec2& p) {
  const Vec2 d = p - cone.origin;
  return {cone.axis.dot(d), Cross(cone.axis, d)};
}

// What limits a clipped segment at one end.
enum class Bound : std::uint8_t { kOwnEnd, kLowerSide, kUpperSide, kDisc };

struct ClipRange {
  double t0 = 0.0, t1 = 1.0;
  Bound bound0 = Bound::kOwnEnd, bound1 = Bound::kOwnEnd;
};

// The part of a + t (b - a), t in [0, 1], inside the sector of half-angle h (given by its
// cosine and sine) and radius `radius` around +x, and what bounds it; false when there is none
// (a single point counts).
bool ClipToSector(const Vec2& a, const Vec2& b, double cos_h, double sin_h, double radius,
                  ClipRange* clip) {
  const Vec2 d = b - a;
  *clip = ClipRange{};
  const auto raise = [&](double t, Bound bound) {
    if (t > clip->t0) *clip = {t, clip->t1, bound, clip->bound1};
  };
  const auto lower = [&](double t, Bound bound) {
    if (t < clip->t1) *clip = {clip->t0, t, clip->bound0, bound};
  };
  // The wedge is the intersection of two half-planes n . p <= 0 through the apex: below the
  // upper side (angle <= h) and above the lower one (angle >= -h).
  for (const auto& [n, side] : {std::pair{Vec2(-sin_h, cos_h), Bound::kUpperSide},
                                std::pair{Vec2(-sin_h, -cos_h), Bound::kLowerSide}}) {
    const double at_a = n.dot(a);
    const double rate = n.dot(d);
    if (rate == 0.0) {
      if (at_a > 0.0) return false;
      continue;
    }
    const double t = -at_a / rate;
    if (rate > 0.0)
      lower(t, side);
    else
      raise(t, side);
  }
  // The disc: |a + t d|^2 <= radius^2.
  const double qa = d.squaredNorm();
  const double qb = 2.0 * a.dot(d);
  const double qc = a.squaredNorm() - radius * radius;
  const double discriminant = qb * qb - 4.0 * qa * qc;
  if (!(discriminant >= 0.0)) return false;
  const double root = std::sqrt(discriminant);
  raise((-qb - root) / (2.0 * qa), Bound::kDisc);
  lower((-qb + root) / (2.0 * qa), Bound::kDisc);
  return clip->t0 <= clip->t1;
}

}  // namespace

bool ConeSweep::Nearer::operator()(std::uint32_t i, std::uint32_t j) const {
  if (i == j) return false;
  const Clipped& ci = sweep->clipped_[i];
  const Clipped& cj = sweep->clipped_[j];
  // Compared along the ray in the middle of the span both cover from the current event on:
  // there they are farthest apart. (The middle of the interval to the next event, which may be
  // an ulp wide, is no good: two edges leaving a shared vertex are at the same distance along
  // the ray through it, and the tie-break below would then decide which hides the other for
  // their whole span, as it did when another vertex lay on the same ray from the apex.)
  const double ray = 0.5 * (sweep->event_tau_ + std::min(ci.tau_hi, cj.tau_hi));
  const double ti = DistanceAt(ci, ray);
  const double tj = DistanceAt(cj, ray);
  if (ti != tj) return ti < tj;
  // By geometry, not by index, so that the input's order cannot matter.
  return std::tuple(ci.world_a.x(), ci.world_a.y(), ci.world_b.x(), ci.world_b.y()) <
         std::tuple(cj.world_a.x(), cj.world_a.y(), cj.world_b.x(), cj.world_b.y());
}

void ConeSweep::Clip(const SonarCone& cone, std::span<const TaggedSegment> segments,
                     const Window& window) {
  const double cos_h = trig_.cos_h, sin_h = trig_.sin_h, tan_h = trig_.tan_h;
  clipped_.clear();
  for (std::size_t index = 0; index < segments.size(); ++index) {
    const auto [p, q] = Canonical(segments[index].segment);
    Clipped c;
    c.a = ToCone(cone, p);
    c.b = ToCone(cone, q);
    // Both ends beyond the same side of the cone: a quick reject of most edges gathered.
    const double upper_a = c.a.y() * cos_h - c.a.x() * sin_h;
    const double upper_b = c.b.y() * cos_h - c.b.x() * sin_h;
    const double lower_a = -c.a.y() * cos_h - c.a.x() * sin_h;
    const double lower_b = -c.b.y() * cos_h - c.b.x() * sin_h;
    if ((upper_a > 0.0 && upper_b > 0.0) || (lower_a > 0.0 && lower_b > 0.0)) continue;
    c.numerator = Cross(c.a, c.b);
    if (c.numerator == 0.0) continue;  // on a line through the apex: seen edge-on
    ClipRange clip;
    if (!ClipToSector(c.a, c.b, cos_h, sin_h, cone.max_range, &clip) || !(clip.t0 < clip.t1))
      continue;
    c.world_a = p;
    c.world_b = q;
    const bool own0 = clip.bound0 == Bound::kOwnEnd, own1 = clip.bound1 == Bound::kOwnEnd;
    c.lo = own0 ? c.a : Vec2(c.a + clip.t0 * (c.b - c.a));
    c.hi = own1 ? c.b : Vec2(c.a + clip.t1 * (c.b - c.a));
    c.lo_end = own0 ? 0 : -1;
    c.hi_end = own1 ? 1 : -1;
    // Ends cut by a side of the cone are exactly on it, ends cut by the disc exactly at R, so
    // that no sliver of "nothing seen" appears from round-off.
    const auto slope = [&](const Vec2& e, Bound bound) {
      if (bound == Bound::kLowerSide) return -tan_h;
      if (bound == Bound::kUpperSide) return tan_h;
      return e.x() > 0.0 ? std::clamp(e.y() / e.x(), -tan_h, tan_h)
                         : (e.y() < 0.0 ? -tan_h : tan_h);
    };
    const auto distance = [&](const Vec2& e, Bound bound) {
      return bound == Bound::kDisc ? cone.max_range : std::min(e.norm(), cone.max_range);
    };
    c.tau_lo = slope(c.lo, clip.bound0);
    c.tau_hi = slope(c.hi, clip.bound1);
    c.lo_distance = distance(c.lo, clip.bound0);
    c.hi_distance = distance(c.hi, clip.bound1);
    if (c.tau_lo > c.tau_hi) {
      std::swap(c.lo, c.hi);
      std::swap(c.tau_lo, c.tau_hi);
      std::swap(c.lo_end, c.hi_end);
      std::swap(c.lo_distance, c.hi_distance);
    }
    if (c.tau_lo == c.tau_hi) continue;
    const auto corner = [&](int end) {
      return end >= 0 && !OnWindowBoundary(window, end == 0 ? c.world_a : c.world_b);
    };
    c.lo_corner = corner(c.lo_end);
    c.hi_corner = corner(c.hi_end);
    c.input = static_cast<int>(index);
    clipped_.push_back(c);
  }
}

void ConeSweep::Sweep(double tan_half, SonarView* view) {
  const auto k = static_cast<std::uint32_t>(clipped_.size());
  taus_.assign({-tan_half, tan_half});
  start_order_.resize(k);
  end_order_.resize(k);
  for (std::uint32_t i = 0; i < k; ++i) {
    taus_.push_back(clipped_[i].tau_lo);
    taus_.push_back(clipped_[i].tau_hi);
    start_order_[i] = end_order_[i] = i;
  }
  std::sort(taus_.begin(), taus_.end());
  taus_.erase(std::unique(taus_.begin(), taus_.end()), taus_.end());
  std::sort(start_order_.begin(), start_order_.end(), [&](std::uint32_t i, std::uint32_t j) {
    return clipped_[i].tau_lo < clipped_[j].tau_lo;
  });
  std::sort(end_order_.begin(), end_order_.end(), [&](std::uint32_t i, std::uint32_t j) {
    return clipped_[i].tau_hi < clipped_[j].tau_hi;
  });

  active_.clear();
  std::size_t next_start = 0, next_end = 0;
  view->pieces.clear();
  for (std::size_t e = 0; e + 1 < taus_.size(); ++e) {
    const double tau = taus_[e];
    // Segments ending here leave first (found by identity: no comparison at a stale slope),
    // then each starting one is placed by comparisons within the span it shares with each
    // active segment (Nearer).
    while (next_end < k && clipped_[end_order_[next_end]].tau_hi == tau)
      active_.erase(std::find(active_.begin(), active_.end(), end_order_[next_end++]));
    event_tau_ = tau;
    while (next_start < k && clipped_[start_order_[next_start]].tau_lo == tau) {
      const std::uint32_t i = start_order_[next_start++];
      active_.insert(std::lower_bound(active_.begin(), active_.end(), i, Nearer{this}), i);
    }
    const int seen = active_.empty() ? -1 : static_cast<int>(active_.front());
    // In slopes for now; Features turns them into angles.
    if (!view->pieces.empty() && view->pieces.back().segment == seen)
      view->pieces.back().to = taus_[e + 1];
    else
      view->pieces.push_back({.from = tau, .to = taus_[e + 1], .segment = seen});
  }
}

void ConeSweep::Features(const SonarCone& cone, std::span<const TaggedSegment> segments,
                         SonarView* view) {
  view->features.clear();
  view->corners.clear();
  view->contact_tags.clear();
  view->extent = 0.0;
  const double h = cone.half_spread;
  const double tan_h = trig_.tan_h;
  // Exactly ±h at the cone's sides.
  const auto angle = [&](double tau) {
    return tau == -tan_h ? -h : (tau == tan_h ? h : std::atan(tau));
  };
  double unseen = 0.0;  // angle through which nothing is seen
  for (VisiblePiece& piece : view->pieces) {
    const double tau_from = piece.from, tau_to = piece.to;
    piece.from = angle(tau_from);
    piece.to = angle(tau_to);
    if (piece.segment < 0) {
      view->extent = cone.max_range;
      unseen += piece.to - piece.from;
      continue;
    }
    const Clipped& c = clipped_[static_cast<std::size_t>(piece.segment)];
    // Where the piece's bounding rays meet the segment, at its clipped ends exactly.
    const auto distance_at = [&](double tau) {
      if (tau == c.tau_lo) return c.lo_distance;
      if (tau == c.tau_hi) return c.hi_distance;
      return std::min(DistanceAt(c, tau) * std::sqrt(1.0 + tau * tau), cone.max_range);
    };
    const double near_from = distance_at(tau_from);
    const double near_to = distance_at(tau_to);
    view->extent = std::max({view->extent, near_from, near_to});
    const Vec2 d = c.b - c.a;
    const double line_distance = std::abs(c.numerator) / d.norm();
    const Vec2 foot = c.a - c.a.dot(d) / d.squaredNorm() * d;
    const bool foot_seen =
        foot.x() > 0.0 && foot.y() >= tau_from * foot.x() && foot.y() <= tau_to * foot.x();
    SonarFeature face{.kind = SonarFeature::Kind::kFace,
                      .distance = line_distance,
                      .projection = std::numbers::pi / 2.0,
                      .subtended = piece.to - piece.from};
    if (!foot_seen) {
      // Away from the foot the distance grows along the line: the closest point is an end.
      face.distance = std::min(near_from, near_to);
      face.projection = std::asin(std::min(1.0, line_distance / face.distance));
    }
    view->features.push_back(face);
    // A vertex is visible when one of its edges is what is seen right beside it.
    if (tau_from == c.tau_lo && c.lo_corner)
      view->corners.push_back(c.lo_end == 0 ? c.world_a : c.world_b);
    if (tau_to == c.tau_hi && c.hi_corner)
      view->corners.push_back(c.hi_end == 0 ? c.world_a : c.world_b);
    view->contact_tags.push_back(segments[static_cast<std::size_t>(c.input)].tag);
    piece.segment = c.input;
  }
  view->seen_fraction = std::clamp(1.0 - unseen / (2.0 * h), 0.0, 1.0);
  std::sort(view->corners.begin(), view->corners.end(), LexLess);
  view->corners.erase(std::unique(view->corners.begin(), view->corners.end()), view->corners.end());
  for (const Vec2& corner : view->corners)
    view->features.push_back({.kind = SonarFeature::Kind::kCorner,
                              .distance = ToCone(cone, corner).norm(),
                              .projection = 0.0,
                              .subtended = 0.0,
                              .concave = ConcaveCorner(cone.origin, corner, segments)});
  std::sort(view->features.begin(), view->features.end(),
            [](const SonarFeature& f, const SonarFeature& g) {
              return std::tuple(f.distance, f.kind, f.projection, f.subtended, f.concave) <
                     std::tuple(g.distance, g.kind, g.projection, g.subtended, g.concave);
            });
  std::sort(view->contact_tags.begin(), view->contact_tags.end());
  view->contact_tags.erase(std::unique(view->contact_tags.begin(), view->contact_tags.end()),
                           view->contact_tags.end());
}

void ConeSweep::Compute(const SonarCone& cone, std::span<const TaggedSegment> segments,
                        const Window& window, SonarView* view) {
  if (trig_.h != cone.half_spread) trig_ = SectorTrig::Of(cone.half_spread);
  Clip(cone, segments, window);
  Sweep(trig_.tan_h, view);
  Features(cone, segments, view);
}

bool SegmentMeetsCone(const Segment& segment, const SonarCone& cone, double radius) {
  // A hair wider than the cone, so that what the sweep might see is never ruled out.
  const double h = std::min(cone.half_spread + 1e-9, std::numbers::pi / 2.0 - 1e-9);
  // Cones mostly share their spread: their trigonometry is computed once per thread.
  thread_local SectorTrig trig;
  if (trig.h != h) trig = SectorTrig::Of(h);
  ClipRange clip;
  return ClipToSector(ToCone(cone, segment.a), ToCone(cone, segment.b), trig.cos_h, trig.sin_h,
                      radius * (1.0 + 1e-9) + 1e-9, &clip);
}

}  // namespace priormap::prf
