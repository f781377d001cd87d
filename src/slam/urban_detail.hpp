#pragma once
/// The steps of MakeUrbanWorld (urban_scenario.hpp), private to the slam module.

#include <cstdint>
#include <vector>

#include <priormap/core/rng.hpp>
#include <priormap/slam/urban_scenario.hpp>

namespace priormap::slam::detail {

/// The world's random streams: Rng::ForStream(seed, kWorldStream + part). Runs use streams
/// 0, 1, ... (their run index), which never come near.
inline constexpr std::uint64_t kWorldStream = std::uint64_t{1} << 62;

/// The city's streets run along x = i pitch and y = j pitch (pitch = block_size + street_width)
/// for i in [kCityStreetMinX, kCityStreetMaxX], j in [kCityStreetMinY, kCityStreetMaxY]; blocks
/// fill the cells between them. The route (RouteWaypoints) keeps one ring of blocks between itself
/// and the city's edge.
inline constexpr int kCityStreetMinX = -3;
inline constexpr int kCityStreetMaxX = 3;
inline constexpr int kCityStreetMinY = -2;
inline constexpr int kCityStreetMaxY = 3;

/// The outward normal of edge `wall` of a counter-clockwise polygon.
[[nodiscard]] inline Vec2 OutwardNormal(const Segment& wall) {
  return -wall.Normal();
}

/// The blocks and their buildings; walls[4 b + i] is edge i of building b, and street_facing
/// says whether a wall looks onto a street (rather than onto a neighbour or the city's edge).
struct City {
  std::vector<Polygon> buildings;
  std::vector<Segment> walls;
  std::vector<int> wall_building;
  std::vector<bool> street_facing;
};

/// Blocks of 1-4 axis-aligned rectangular buildings on the grid of streets around the route.
[[nodiscard]] City BuildCity(const UrbanScenarioOptions& options, Rng& rng);

/// The fixed route (street-centreline waypoints, in units of the block pitch) and its start.
[[nodiscard]] std::vector<Vec2> RouteWaypoints(const UrbanScenarioOptions& options, Se2* start);

/// Drives the waypoints with Bailey & Nieto's steering controller; fills world->controls and
/// world->poses (world->waypoints and wheelbase must be set).
void DriveRoute(const UrbanScenarioOptions& options, const Se2& start, UrbanWorld* world);

/// Frames at steps 0, observe_every, 2 observe_every, ... <= steps.
[[nodiscard]] std::vector<int> FrameSteps(std::size_t steps, int observe_every);

/// Per frame, the beacons visible from poses[frame_steps[f]]: within range and the field of
/// view, on the outer side of their wall if on one, with no wall crossing the sight line.
[[nodiscard]] std::vector<std::vector<VisibleBeacon>> Visibility(
    const City& city, const std::vector<Se2>& poses, const std::vector<int>& frame_steps,
    const std::vector<Beacon>& beacons, const UrbanScenarioOptions& options);

/// Beacons along the street-facing walls where the route sees them (from at least one frame),
/// exactly round(off_wall_fraction n) of them then moved off their wall.
[[nodiscard]] std::vector<Beacon> PlaceBeacons(const City& city, const std::vector<Se2>& poses,
                                               const std::vector<int>& frame_steps,
                                               const UrbanScenarioOptions& options, Rng& rng);

/// True when no wall crosses the open sight line from `from` to `to` (crossings within 1e-6 m of
/// `to` are ignored, so a point on a wall is not hidden by that wall).
[[nodiscard]] bool LineOfSight(const Vec2& from, const Vec2& to, const std::vector<Segment>& walls,
                               const std::vector<int>& candidate_walls);

}  // namespace priormap::slam::detail
