#include <cmath>
#include <limits>

#include <priormap/prf/sonar_multipath.hpp>

namespace priormap::prf {

std::optional<MirrorLeg> AxisMirror(const SonarCone& cone, const SonarView& view,
                                    std::span<const TaggedSegment> segments, const Window& window) {
  // The axis is angle 0, strictly inside [-h, h]: exactly one piece holds it in [from, to).
  const VisiblePiece* axis_piece = nullptr;
  for (const VisiblePiece& piece : view.pieces)
    if (piece.from <= 0.0 && 0.0 < piece.to) axis_piece = &piece;
  if (axis_piece == nullptr || axis_piece->segment < 0) return std::nullopt;
  const TaggedSegment& face = segments[static_cast<std::size_t>(axis_piece->segment)];
  const auto d1 =
      RaySegmentHit(cone.origin, cone.axis, face.segment.a, face.segment.b, cone.max_range);
  if (!d1) return std::nullopt;  // the axis grazes the piece's end: no face to mirror it
  const Vec2 along = face.segment.b - face.segment.a;
  const Vec2 normal = Perp(along) / along.norm();
  const Vec2 mirrored = cone.axis - 2.0 * cone.axis.dot(normal) * normal;
  MirrorLeg leg{.from = cone.origin + *d1 * cone.axis,
                .direction = mirrored,
                .axis_distance = *d1,
                .reach = 0.0,
                .mirror_tag = face.tag};
  leg.reach =
      std::min(cone.max_range - *d1,
               window.ContainsInterior(leg.from) ? window.DistanceToSide(leg.from, mirrored) : 0.0);
  leg.reach = std::max(leg.reach, 0.0);
  return leg;
}

std::optional<LegHit> FirstLegHit(const MirrorLeg& leg, const Coloring& coloring,
                                  const Edit* ignoring, std::span<const Segment> added) {
  std::optional<LegHit> best;
  const auto consider = [&](const Segment& s, std::int32_t tag) {
    if (tag == leg.mirror_tag) return;
    const auto t = RaySegmentHit(leg.from, leg.direction, s.a, s.b, leg.reach);
    // Ties (a vertex) go to the smaller tag, so that the result does not depend on the order
    // of the walk.
    if (t && (!best || *t < best->t || (*t == best->t && tag < best->tag))) best = {*t, tag};
  };
  if (leg.reach <= 0.0) return best;
  for (std::size_t k = 0; k < added.size(); ++k)
    consider(added[k], -1 - static_cast<std::int32_t>(k));
  // The cells in order along the leg, until one begins beyond the best hit so far. An edge in
  // several cells is tested in each: the minimum does not mind.
  WalkCells(coloring.grid(), leg.from, leg.PointAt(leg.reach), [&](int cell, double enter, double) {
    if (best && best->t < enter * leg.reach) return false;
    for (EdgeId e : coloring.cell_edges(cell))
      if (ignoring == nullptr || !ignoring->Removes(e)) consider(coloring.EdgeSegment(e), e);
    return true;
  });
  return best;
}

double MultipathLength(const MirrorLeg& leg, const std::optional<LegHit>& hit) {
  return hit ? leg.axis_distance + hit->t : std::numeric_limits<double>::infinity();
}

}  // namespace priormap::prf
