#pragma once
/// The ground truth occupancy of a scene, for scoring maps made from its simulated data: a point
/// is white (free) when the robot can reach it from the scene's free space without crossing a
/// surface, and black otherwise (inside walls, behind them, inside clutter). Also the true walls
/// (the scene's segments and circles) and the distance to the nearest one.
///
/// Reachability is a flood fill over the centres of a fine raster, two neighbouring centres
/// joined when the segment between them touches no surface; a query point takes the colour of
/// a raster centre near it that it sees without crossing a surface. This is exact for every
/// free region and gap wider than the raster's cell (1 cm by default); thinner ones are not
/// resolved. Surfaces have no thickness: a free region behind an open wall (the corridor's
/// outside, reached through its doorway) is as white as the corridor.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <priormap/core/scene.hpp>

namespace priormap {

struct SceneTruthOptions {
  double resolution = 0.01;  ///< raster cell, m
  double margin = 0.1;       ///< raster beyond the surfaces and seeds, m (at least two cells)
};

class SceneTruth {
 public:
  /// `seeds`: points of the free space the robot is in (waypoints, sensor positions). Throws
  /// ContractError when there is none, or a seed lies on a surface, or the options are invalid.
  SceneTruth(const Scene& scene, std::span<const Vec2> seeds,
             const SceneTruthOptions& options = {});
  /// Seeded by the scene's waypoints and default pose (at least one of them must exist).
  [[nodiscard]] static SceneTruth OfScene(const Scene& scene,
                                          const SceneTruthOptions& options = {});

  /// True (black) when `p` is not reachable from the seeds. Points on a surface may go either
  /// way.
  [[nodiscard]] bool Occupied(const Vec2& p) const;
  /// Distance from `p` to the nearest surface (segment or circle curve); +inf without surfaces.
  [[nodiscard]] double DistanceToWall(const Vec2& p) const;
  /// The true walls: the scene's segments and circles (clutter included).
  [[nodiscard]] const std::vector<ScenePrimitive>& walls() const { return walls_; }

 private:
  [[nodiscard]] bool Blocked(const Vec2& a, const Vec2& b) const;
  [[nodiscard]] std::size_t Index(int ix, int iy) const {
    return static_cast<std::size_t>(iy) * static_cast<std::size_t>(nx_) +
           static_cast<std::size_t>(ix);
  }
  [[nodiscard]] Vec2 Centre(int ix, int iy) const {
    return origin_ + resolution_ * Vec2(ix + 0.5, iy + 0.5);
  }
  void MarkBarriers();
  void FloodFill(std::span<const Vec2> seeds);

  std::vector<ScenePrimitive> walls_;
  std::vector<Box2> bounds_;  ///< of each wall, for a cheap reject
  Vec2 origin_ = Vec2::Zero();
  double resolution_ = 0.01;
  int nx_ = 0;
  int ny_ = 0;
  std::vector<std::uint8_t> blocked_right_;  ///< the centre joins its +x neighbour through a wall
  std::vector<std::uint8_t> blocked_up_;     ///< ... its +y neighbour
  std::vector<std::uint8_t> near_wall_;      ///< a wall passes between the centre and a neighbour
  std::vector<std::uint8_t> free_;           ///< reachable
  bool outside_free_ = false;                ///< the colour beyond the raster (the unbounded face)
};

/// True when the closed segment ab meets the wall (a segment, or a circle's curve).
[[nodiscard]] bool SegmentTouchesWall(const Vec2& a, const Vec2& b, const ScenePrimitive& wall);

/// Distance from `p` to the wall (a segment, or a circle's curve).
[[nodiscard]] double DistanceToWall(const Vec2& p, const ScenePrimitive& wall);

/// Empty when no point lies on a surface of the scene; else which point lies on which surface.
/// SceneTruth takes only seeds off the surfaces.
[[nodiscard]] std::string PointOnASurface(const Scene& scene, std::span<const Vec2> points);

/// Empty when the scene's waypoints make a path a robot can drive: two distinct waypoints at
/// least, and no leg that meets a surface; else what is wrong.
[[nodiscard]] std::string WaypointPathProblem(const Scene& scene);

}  // namespace priormap
