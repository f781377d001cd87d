#pragma once
/// A prior map of another kind than the robot's: straight wall segments, as extracted from aerial
/// imagery or a cadastral map, each parameterised by its two endpoints with an isotropic 1-sigma
/// endpoint error. Segments are grouped into structures one level up the hierarchy (buildings):
/// the segments of one GeoJSON feature form one building (Parsley & Julier, Sec. III).

#include <string>
#include <vector>

#include <priormap/core/types.hpp>
#include <priormap/core/world_bounds.hpp>

namespace priormap::slam {

/// The largest endpoint 1-sigma a prior segment may have, m: the world's bound
/// (kMaxWorldCoordinate). An error larger than the world says no more than "anywhere in it", and
/// the filter squares it into covariances and multiplies those together, so without a bound a
/// finite std (1e200) gives an infinite variance and then NaN estimates.
inline constexpr double kMaxPriorStd = kMaxWorldCoordinate;

/// Whether `std` is a valid PriorSegment::std: finite, > 0 and at most kMaxPriorStd.
[[nodiscard]] inline bool IsValidPriorStd(double std) {
  return std > 0.0 && std <= kMaxPriorStd;
}

struct PriorSegment {
  Vec2 a = Vec2::Zero();
  Vec2 b = Vec2::Zero();
  double std = 1.0;   ///< 1-sigma error of each endpoint coordinate, m (IsValidPriorStd)
  int building = -1;  ///< index into PriorMap::buildings
  /// The other buildings this wall is part of, ascending. A wall that neighbours share is one
  /// segment of each footprint; merged into one wall (MergeSameWalls), it is still a wall of
  /// each. Empty for a segment as read from a map.
  std::vector<int> shared_with{};
};

struct PriorMap {
  std::vector<PriorSegment> segments;
  std::vector<std::string> buildings;  ///< names of the structures one level up (one per feature)

  [[nodiscard]] bool empty() const { return segments.empty(); }
};

}  // namespace priormap::slam
