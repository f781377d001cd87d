#pragma once
/// Prior segments that are the same wall. Footprint data holds a wall twice wherever two features
/// share it (adjacent buildings, a building and its part, two datasets overlaid): the copies are
/// collinear and overlap. The filter's hypotheses put a point on one line only
/// (StructurePriors::one_line_per_point), so for a point on such a wall the probability splits
/// between the copies, neither reaches p_accept and the wall is never used. Here each group of
/// copies becomes one wall before the filter sees the map.
///
/// Two segments are the same wall when
///  - each one's endpoints lie on the other's line within the segments' stated endpoint errors
///    (`std`): their perpendicular distances d = (d_1, d_2) from it pass d^T C^-1 d <= gate, C
///    their covariance when both segments are independent noisy images of one line
///    (sigma_p^2 I for the points, sigma_l^2 [(1 - t_i)(1 - t_j) + t_i t_j] for the line at the
///    points' projections t_1, t_2), and
///  - they overlap along it by at least half the shorter one: by this test, walls that continue
///    each other (the next building of a straight street front, a wall split by a vertex) are
///    not one.
/// Groups are closed transitively. The parts of a wall that one footprint splits at a vertex (a
/// straight facade drawn with an extra vertex, where a neighbour's wall meets it) are not one by
/// the overlap test above, but ContinuesWall joins them instead (see that function for when):
/// they meet at that vertex, so a point near it is gated with both and its probability splits
/// between them as between copies; in a cluster, that kept every point on the wall from being
/// related to it.
///
/// The gate (kSameWallChi2 = 0.5) is far tighter than a 99 % test, on purpose. The std is a
/// map's error against the world, and distinct walls often stand closer than 3 std: with 1 m,
/// the facing walls of two buildings 2-3 m apart, or an outdated outline 2 m out. In the urban
/// study a 99 % gate (9.21) merged those and cost 40 % of the accuracy, and a gate of 1 or 2
/// still merged a few outlines with their walls and took the runs' NEES out of its band more
/// often (30 runs, seed 1: 0.89 of the frames inside it -> 0.81). At 0.5, parallel walls of equal
/// length are one wall only when less than 0.7 std apart; the study is unchanged (seed 1) or
/// better (seed 2). The copies of one survey (shared vertices, or digitised to a fraction of the
/// std) always merge. A wall digitised twice independently (about 1.4 std apart on average)
/// merges in about one case of five; for a map overlaid from independent sources, a gate of 2
/// merges two of three and 9.21 nearly all, at the risk above.
///
/// The merged wall is a fit, not a fusion: the line through the group's endpoints (weighted by
/// 1 / std^2), spanning their extent, with the largest std of the group grown by the endpoints'
/// largest distance from that line. Copies of one survey (shared vertices) carry the same error,
/// so averaging them as independent measurements would be overconfident; identical copies give
/// back the segment itself.

#include <vector>

#include <priormap/slam/prior_map.hpp>

namespace priormap::slam {

/// The gate on the endpoints' distances from the other segment's line (chi2, 2 degrees of
/// freedom, at 22 %; see above).
inline constexpr double kSameWallChi2 = 0.5;

struct SameWalls {
  /// The walls: one segment per group, in the order of each group's first segment; a wall of one
  /// segment is that segment unchanged. Buildings as in the input; a wall's building is its first
  /// segment's, and its `shared_with` the other buildings of its segments (a wall two footprints
  /// share is a wall of both, so relations one level up count it for each).
  PriorMap map;
  /// Per wall, the input segments it stands for, ascending; the first names it.
  std::vector<std::vector<int>> members;
};

/// Whether prior segments `a` and `b` are the same wall (above). Segments of zero length never
/// are.
[[nodiscard]] bool IsSameWall(const PriorSegment& a, const PriorSegment& b,
                              double gate_chi2 = kSameWallChi2);

/// The largest turn between two parts of one straight wall that a footprint split at a vertex:
/// a redrawn facade bends by its digitiser's precision (2 degrees is 0.35 m over 10 m), a polygon
/// drawn for a round building or a curved facade by more, whatever its segments' std.
inline constexpr double kMaxContinuedTurnDeg = 2.0;

/// Whether `b` continues `a` at a vertex they share (bit for bit, as consecutive positions of one
/// GeoJSON line or ring do) along one line: within the test above, turning by at most
/// kMaxContinuedTurnDeg, and both walls of the same buildings (building and shared_with): one wall
/// that the footprint split. Walls of different buildings that continue each other (the next house
/// of a street front) are not joined. MergeSameWalls joins such parts only while all of them stay
/// within kMaxContinuedTurnDeg of each other: many slight turns (a polygon for a round building,
/// whose sides are short against their std) are a curve, not one wall.
[[nodiscard]] bool ContinuesWall(const PriorSegment& a, const PriorSegment& b,
                                 double gate_chi2 = kSameWallChi2);

/// The map's walls, each group of segments that are the same wall merged into one. O(n log n +
/// the pairs whose bounding boxes, grown by 3 std, meet).
[[nodiscard]] SameWalls MergeSameWalls(const PriorMap& map, double gate_chi2 = kSameWallChi2);

}  // namespace priormap::slam
