#pragma once
/// The geometry of a sonar cone's multipath reading (docs/sonar.md): after a specular miss, the
/// sound that went along the cone's axis is mirrored by the face it met there and may be heard
/// back from the next edge it meets, the reading being the length of the whole path (apex →
/// mirror → next edge). The sonar simulator makes such readings; the likelihood's multipath
/// component (SonarModel::multipath_weight) needs the same path in the map being sampled.

#include <cstdint>
#include <optional>
#include <span>

#include <priormap/core/segment.hpp>
#include <priormap/prf/coloring.hpp>
#include <priormap/prf/sonar_data.hpp>
#include <priormap/prf/sonar_visibility.hpp>
#include <priormap/prf/window.hpp>

namespace priormap::prf {

/// The leg of the axis's path beyond the face that mirrors it.
struct MirrorLeg {
  Vec2 from = Vec2::Zero();        ///< where the axis meets the face
  Vec2 direction = Vec2::UnitX();  ///< unit, mirrored at the face
  double axis_distance = 0.0;      ///< from the apex to `from`
  /// The leg is followed this far: to R − axis_distance (a longer path is a max reading) or to
  /// the window's side, beyond which the map says nothing.
  double reach = 0.0;
  std::int32_t mirror_tag =
      0;  ///< the face's segment, which the leg leaves and does not meet again

  [[nodiscard]] Vec2 PointAt(double t) const { return from + t * direction; }
};

/// The leg of `cone`'s axis mirrored at the face the axis sees in `view` (whose pieces index
/// `segments`), or nullopt when the axis sees no face within the cone's R. Bit for bit the same
/// whatever the order of the face's ends.
[[nodiscard]] std::optional<MirrorLeg> AxisMirror(const SonarCone& cone, const SonarView& view,
                                                  std::span<const TaggedSegment> segments,
                                                  const Window& window);

/// Where a leg first meets an edge, for t in (0, reach].
struct LegHit {
  double t = 0.0;
  /// The edge's id, or -1 - k for the k-th added segment.
  std::int32_t tag = 0;
};

/// The first edge the leg meets in `coloring`, passing over the edges `ignoring` removes and
/// taking `added` (tagged -1 - k) as edges, and never the mirror itself; nullopt when it meets
/// none within its reach.
[[nodiscard]] std::optional<LegHit> FirstLegHit(const MirrorLeg& leg, const Coloring& coloring,
                                                const Edit* ignoring,
                                                std::span<const Segment> added);

/// The length of the multipath reading: to the mirror and on to the leg's hit; +inf when the
/// leg meets nothing within its reach (not heard within R).
[[nodiscard]] double MultipathLength(const MirrorLeg& leg, const std::optional<LegHit>& hit);

}  // namespace priormap::prf
