#include "segment_grid.hpp"

#include <algorithm>
#include <cmath>

namespace priormap::slam::detail {

SegmentGrid::SegmentGrid(const PriorMap& map, double cell_size, double pad) : cell_(cell_size) {
  if (map.segments.empty()) return;
  Box2 box;
  for (const PriorSegment& s : map.segments) {
    box.extend(s.a);
    box.extend(s.b);
  }
  origin_ = box.min() - Vec2::Constant(pad);
  const Vec2 extent = box.sizes() + Vec2::Constant(2.0 * pad);
  // Bounded so that a map spanning a continent in metres cannot exhaust memory: cells grow.
  constexpr long kMaxCells = 1L << 22;
  while ((std::floor(extent.x() / cell_) + 1) * (std::floor(extent.y() / cell_) + 1) >
         static_cast<double>(kMaxCells)) {
    cell_ *= 2.0;
  }
  nx_ = static_cast<long>(std::floor(extent.x() / cell_)) + 1;
  ny_ = static_cast<long>(std::floor(extent.y() / cell_)) + 1;
  cells_.resize(static_cast<std::size_t>(nx_ * ny_));
  for (std::size_t i = 0; i < map.segments.size(); ++i) {
    const PriorSegment& s = map.segments[i];
    const Vec2 lo = s.a.cwiseMin(s.b) - Vec2::Constant(pad) - origin_;
    const Vec2 hi = s.a.cwiseMax(s.b) + Vec2::Constant(pad) - origin_;
    const long x0 = std::clamp(static_cast<long>(std::floor(lo.x() / cell_)), 0L, nx_ - 1);
    const long x1 = std::clamp(static_cast<long>(std::floor(hi.x() / cell_)), 0L, nx_ - 1);
    const long y0 = std::clamp(static_cast<long>(std::floor(lo.y() / cell_)), 0L, ny_ - 1);
    const long y1 = std::clamp(static_cast<long>(std::floor(hi.y() / cell_)), 0L, ny_ - 1);
    for (long iy = y0; iy <= y1; ++iy) {
      for (long ix = x0; ix <= x1; ++ix) cells_[CellIndex(ix, iy)].push_back(static_cast<int>(i));
    }
  }
}

const std::vector<int>& SegmentGrid::Near(const Vec2& p) const {
  if (cells_.empty() || !p.allFinite()) return empty_;
  const Vec2 q = (p - origin_) / cell_;
  if (q.x() < 0.0 || q.y() < 0.0) return empty_;
  const auto ix = static_cast<long>(q.x());
  const auto iy = static_cast<long>(q.y());
  if (ix >= nx_ || iy >= ny_) return empty_;
  return cells_[CellIndex(ix, iy)];
}

}  // namespace priormap::slam::detail
