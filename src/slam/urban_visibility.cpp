// What the range-bearing sensor of the urban study sees: beacons within range and the field of
// view whose sight line no building wall crosses (Parsley & Julier, Fig. 3's occlusions).
#include <cmath>

#include <priormap/core/angles.hpp>

#include "urban_detail.hpp"

namespace priormap::slam::detail {

bool LineOfSight(const Vec2& from, const Vec2& to, const std::vector<Segment>& walls,
                 const std::vector<int>& candidate_walls) {
  constexpr double kEndTolerance = 1e-6;  // m
  const Vec2 r = to - from;
  const double t_max = 1.0 - kEndTolerance / r.norm();
  for (const int w : candidate_walls) {
    // from + t r = a + u s with t in (0, t_max) and u in [0, 1]; parallel walls (a sight line
    // exactly along a wall's line) count as not crossing it.
    const Vec2 s = walls[w].b - walls[w].a;
    const double denominator = Cross(r, s);
    if (std::abs(denominator) < 1e-12) continue;
    const Vec2 q = walls[w].a - from;
    const double t = Cross(q, s) / denominator;
    const double u = Cross(q, r) / denominator;
    if (t > 0.0 && t < t_max && u >= 0.0 && u <= 1.0) return false;
  }
  return true;
}

std::vector<int> FrameSteps(std::size_t steps, int observe_every) {
  // Frame 0 is at the start, where the pose is known, so the map is anchored there.
  std::vector<int> frame_steps;
  for (std::size_t k = 0; k <= steps; k += static_cast<std::size_t>(observe_every)) {
    frame_steps.push_back(static_cast<int>(k));
  }
  return frame_steps;
}

std::vector<std::vector<VisibleBeacon>> Visibility(const City& city, const std::vector<Se2>& poses,
                                                   const std::vector<int>& frame_steps,
                                                   const std::vector<Beacon>& beacons,
                                                   const UrbanScenarioOptions& options) {
  // A range prefilter per frame: only the walls of buildings whose bounding box comes within
  // max_range can hide anything (a few dozen of the few hundred walls).
  std::vector<Box2> boxes;
  for (const Polygon& building : city.buildings) boxes.push_back(building.Bounds());
  const double max_range2 = options.max_range * options.max_range;
  std::vector<char> near_building(boxes.size());
  std::vector<int> near_walls;
  std::vector<std::vector<VisibleBeacon>> visible(frame_steps.size());
  for (std::size_t f = 0; f < frame_steps.size(); ++f) {
    const Se2& pose = poses[frame_steps[f]];
    const Vec2 p = pose.translation();
    for (std::size_t b = 0; b < boxes.size(); ++b) {
      near_building[b] = boxes[b].exteriorDistance(p) <= options.max_range;
    }
    near_walls.clear();
    for (std::size_t w = 0; w < city.walls.size(); ++w) {
      if (near_building[city.wall_building[w]]) near_walls.push_back(static_cast<int>(w));
    }
    for (std::size_t i = 0; i < beacons.size(); ++i) {
      const Beacon& beacon = beacons[i];
      const Vec2 d = beacon.position - p;
      const double range2 = d.squaredNorm();
      if (range2 > max_range2 || range2 == 0.0) continue;
      const double bearing = WrapAngle(std::atan2(d.y(), d.x()) - pose.theta());
      if (std::abs(bearing) > 0.5 * options.fov) continue;
      // A beacon on a wall shows on the wall's outer side only (its inner side is indoors).
      if (beacon.on_wall && OutwardNormal(city.walls[beacon.wall]).dot(d) >= 0.0) continue;
      if (!LineOfSight(p, beacon.position, city.walls, near_walls)) continue;
      visible[f].push_back({static_cast<int>(i), std::sqrt(range2), bearing});
    }
  }
  return visible;
}

}  // namespace priormap::slam::detail
