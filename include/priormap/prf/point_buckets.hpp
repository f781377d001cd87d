#pragma once
/// Points hashed into square buckets, for "is any of them within r of p" when r is at most the
/// bucket size (the scores' nearness tests over many points).

#include <cmath>
#include <cstdint>
#include <span>
#include <unordered_map>
#include <vector>

#include <priormap/core/types.hpp>

namespace priormap::prf {

class PointBuckets {
 public:
  PointBuckets(std::span<const Vec2> points, double size) : size_(size) {
    for (const Vec2& q : points) buckets_[Key(Bucket(q.x()), Bucket(q.y()))].push_back(q);
  }
  [[nodiscard]] bool AnyWithin(const Vec2& p, double r) const {
    const std::int64_t bx = Bucket(p.x()), by = Bucket(p.y());
    for (std::int64_t dx = -1; dx <= 1; ++dx)
      for (std::int64_t dy = -1; dy <= 1; ++dy) {
        const auto it = buckets_.find(Key(bx + dx, by + dy));
        if (it == buckets_.end()) continue;
        for (const Vec2& q : it->second)
          if ((q - p).squaredNorm() <= r * r) return true;
      }
    return false;
  }

 private:
  [[nodiscard]] std::int64_t Bucket(double v) const {
    return static_cast<std::int64_t>(std::floor(v / size_));
  }
  static std::uint64_t Key(std::int64_t x, std::int64_t y) {
    return (static_cast<std::uint64_t>(x) << 32) ^ static_cast<std::uint32_t>(y);
  }
  double size_;
  std::unordered_map<std::uint64_t, std::vector<Vec2>> buckets_;
};

}  // namespace priormap::prf
