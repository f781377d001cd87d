#pragma once
/// A prior map of another kind than the robot's: straight wall segments, as extracted from aerial
/// imagery or a cadastral map, each parameterised by its two endpoints with an isotropic 1-sigma
/// endpoint error. Segments are grouped into structures one level up the hierarchy (buildings):
/// the segments of one GeoJSON feature form one building (Parsley & Julier, Sec. III).

#include <string>
#include <vector>

#include <priormap/core/types.hpp>

namespace priormap::slam {

struct PriorSegment {
  Vec2 a = Vec2::Zero();
  Vec2 b = Vec2::Zero();
  double std = 1.0;   ///< 1-sigma error of each endpoint coordinate, m (> 0)
  int building = -1;  ///< index into PriorMap::buildings
};

struct PriorMap {
  std::vector<PriorSegment> segments;
  std::vector<std::string> buildings;  ///< names of the structures one level up (one per feature)

  [[nodiscard]] bool empty() const { return segments.empty(); }
};

}  // namespace priormap::slam
