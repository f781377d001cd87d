#pragma once
// A uniform grid over the prior map's segments, so that gating a landmark looks at the segments
// near it instead of all of them.

#include <vector>

#include <priormap/slam/prior_map.hpp>

namespace priormap::slam::detail {

class SegmentGrid {
 public:
  /// Each segment is registered in every cell its bounding box, grown by `pad` metres, touches.
  SegmentGrid(const PriorMap& map, double cell_size, double pad);

  /// Segments registered in the cell of `p` (each once).
  [[nodiscard]] const std::vector<int>& Near(const Vec2& p) const;

 private:
  [[nodiscard]] long CellIndex(long ix, long iy) const { return iy * nx_ + ix; }

  Vec2 origin_ = Vec2::Zero();
  double cell_ = 1.0;
  long nx_ = 0, ny_ = 0;
  std::vector<std::vector<int>> cells_;
  std::vector<int> empty_;
};

}  // namespace priormap::slam::detail
