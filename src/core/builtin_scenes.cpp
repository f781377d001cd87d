#include <algorithm>
#include <functional>
#include <utility>

#include <priormap/core/angles.hpp>
#include <priormap/core/scene.hpp>

namespace priormap {
namespace {

SceneSurface Walls(std::vector<Vec2> points, bool closed, std::string label) {
  return {Polyline{std::move(points), closed}, false, std::move(label)};
}

SceneSurface Pillar(Vec2 center, double radius, bool clutter, std::string label) {
  return {Circle{center, radius}, clutter, std::move(label)};
}

// An axis-aligned box of clutter centred at `c`.
SceneSurface Box(Vec2 c, double width, double height, std::string label) {
  const double w = width / 2, h = height / 2;
  return {Polyline{{c + Vec2(-w, -h), c + Vec2(w, -h), c + Vec2(w, h), c + Vec2(-w, h)}, true},
          true, std::move(label)};
}

Scene RectangularRoom(std::string name, double width, double height, Se2 pose) {
  const double w = width / 2, h = height / 2;
  Scene scene;
  scene.name = std::move(name);
  scene.surfaces.push_back(Walls({{-w, -h}, {w, -h}, {w, h}, {-w, h}}, true, "walls"));
  scene.default_pose = pose;
  const double mw = w / 2, mh = h / 2;
  scene.waypoints = {{-mw, -mh}, {mw, -mh}, {mw, mh}, {-mw, mh}, {-mw, -mh}};
  return scene;
}

Scene Square() {
  return RectangularRoom("square", 4.0, 4.0, Se2(-1.0, -1.0, kPi / 4));
}

Scene Rectangle() {
  return RectangularRoom("rectangle", 6.0, 4.0, Se2(-1.5, -1.0, 0.6));
}

Scene CircularRoom() {
  Scene scene;
  scene.name = "circle";
  scene.surfaces.push_back(Pillar({0.0, 0.0}, 2.0, false, "circular wall"));
  scene.default_pose = Se2(0.5, -0.4, 0.3);
  scene.waypoints = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}, {1, 0}};
  return scene;
}

Scene TwoCircles() {
  Scene scene;
  scene.name = "two-circles";
  scene.surfaces.push_back(Pillar({-0.95, 0.25}, 0.6, false, "large pillar"));
  scene.surfaces.push_back(Pillar({1.2, -0.5}, 0.35, false, "small pillar"));
  scene.default_pose = Se2(0.0, -2.5, kPi / 2);
  scene.waypoints = {{-2.5, -2.5}, {2.5, -2.5}, {2.5, 2.5}, {-2.5, 2.5}, {-2.5, -2.5}};
  return scene;
}

Scene LRoom() {
  Scene scene;
  scene.name = "l-room";
  scene.surfaces.push_back(
      Walls({{-3, -3}, {3, -3}, {3, 0}, {0, 0}, {0, 3}, {-3, 3}}, true, "walls"));
  scene.surfaces.push_back(Box({-0.8, -2.3}, 0.5, 0.3, "box"));
  scene.surfaces.push_back(Pillar({-2.3, -0.6}, 0.15, true, "bin"));
  scene.default_pose = Se2(-1.5, -1.5, kPi / 4);
  scene.waypoints = {{-1.5, -1.5}, {2.2, -1.5}, {2.2, -0.6}, {-0.6, -0.6},
                     {-0.6, 2.2},  {-1.5, 2.2}, {-1.5, -1.5}};
  return scene;
}

Scene Corridor() {
  Scene scene;
  scene.name = "corridor";
  // One wall surface; the gap between its ends at x in [1.5, 2.5] is a doorway.
  scene.surfaces.push_back(
      Walls({{1.5, 1}, {-10, 1}, {-10, -1}, {10, -1}, {10, 1}, {2.5, 1}}, false, "walls"));
  scene.default_pose = Se2(0.0, 0.0, kPi / 2);
  scene.waypoints = {{-8, -0.3}, {8, -0.3}, {8, 0.3}, {-8, 0.3}, {-8, -0.3}};
  return scene;
}

// A room opening on a corridor wall through a doorway, in world coordinates along the wall's
// axis (x for a horizontal wall, y for a vertical one).
struct DoorRoom {
  double from, to;            // the room's extent along the wall
  double door_from, door_to;  // the doorway's, strictly inside the room's
  double depth;               // away from the corridor, beyond the wall
};

// The free space of a corridor (a polygon walked counter-clockwise, axis-aligned) and of the
// rooms opening on its walls, as one closed wall polyline with the free space inside. Walls
// between corridor and rooms are `wall` thick, so each doorway is a short passage framed by
// four corners, as in a real building.
Polyline CorridorWithRooms(const std::vector<Vec2>& corridor,
                           const std::vector<std::vector<DoorRoom>>& rooms_by_side, double wall) {
  std::vector<Vec2> points;
  for (std::size_t i = 0; i < corridor.size(); ++i) {
    const Vec2& base = corridor[i];
    const Vec2 along = (corridor[(i + 1) % corridor.size()] - base).normalized();
    const Vec2 outward = -Perp(along);  // the free space is on the left
    const int axis = along.x() != 0.0 ? 0 : 1;
    // s along the walk from `base`; o away from the corridor.
    const auto at = [&](double world_along, double o) {
      return Vec2(base + (world_along - base[axis]) * along[axis] * along + o * outward);
    };
    points.push_back(base);
    std::vector<DoorRoom> rooms =
        i < rooms_by_side.size() ? rooms_by_side[i] : std::vector<DoorRoom>{};
    // In walking order; a room's near side is where the walk meets it first.
    std::sort(rooms.begin(), rooms.end(), [&](const DoorRoom& a, const DoorRoom& b) {
      return a.from * along[axis] < b.from * along[axis];
    });
    for (const DoorRoom& r : rooms) {
      const bool forward = along[axis] > 0.0;
      const double near = forward ? r.from : r.to, far = forward ? r.to : r.from;
      const double door_near = forward ? r.door_from : r.door_to;
      const double door_far = forward ? r.door_to : r.door_from;
      for (const auto& [s, o] : {std::pair{door_near, 0.0},
                                 {door_near, wall},
                                 {near, wall},
                                 {near, wall + r.depth},
                                 {far, wall + r.depth},
                                 {far, wall},
                                 {door_far, wall},
                                 {door_far, 0.0}})
        points.push_back(at(s, o));
    }
  }
  return {std::move(points), true};
}

// The scene moved so that its bounds are centred on the origin, as every built-in scene is.
Scene Centred(Scene scene) {
  const Vec2 shift = -scene.Bounds().center();
  for (SceneSurface& surface : scene.surfaces) {
    if (auto* polyline = std::get_if<Polyline>(&surface.shape))
      for (Vec2& p : polyline->points) p += shift;
    else
      std::get<Circle>(surface.shape).center += shift;
  }
  for (Vec2& w : scene.waypoints) w += shift;
  if (scene.default_pose)
    scene.default_pose =
        Se2(scene.default_pose->translation() + shift, scene.default_pose->theta());
  return scene;
}

// A straight corridor with seven rooms on its two sides, seen mostly through their doorways
// (a sonar study scene: Paskin & Thrun's Fig. 5 finds rooms from a corridor).
Scene Office() {
  Scene scene;
  scene.name = "office";
  const std::vector<Vec2> corridor = {{-10, -1}, {10, -1}, {10, 1}, {-10, 1}};
  const std::vector<DoorRoom> south = {
      {-9.6, -4.6, -5.7, -4.8, 3.5}, {-4.4, 0.6, -0.4, 0.5, 3.5}, {3.0, 9.6, 3.3, 4.2, 3.5}};
  const std::vector<DoorRoom> north = {{-9.6, -5.6, -6.7, -5.8, 4.0},
                                       {-5.4, -0.4, -1.5, -0.6, 4.0},
                                       {1.0, 5.0, 1.3, 2.2, 4.0},
                                       {5.2, 9.6, 8.5, 9.4, 4.0}};
  scene.surfaces.push_back(
      {CorridorWithRooms(corridor, {south, {}, north, {}}, 0.2), false, "walls"});
  scene.default_pose = Se2(0.0, 0.0, 0.0);
  // Along the corridor, into one room and out again.
  scene.waypoints = {{-9, 0}, {1.75, 0}, {1.75, 3.5}, {1.75, -0.3}, {9, -0.3}};
  return Centred(std::move(scene));
}

// An L-shaped corridor (like ../shared/data/sonar-roboND's) with rooms on both sides of both
// legs, one of them inside the L.
Scene LOffice() {
  Scene scene;
  scene.name = "l-office";
  const std::vector<Vec2> corridor = {{-8, -1}, {4, -1}, {4, -9}, {6, -9}, {6, 1}, {-8, 1}};
  const std::vector<DoorRoom> inside_south = {{-7.5, -2.0, -3.2, -2.3, 4.0},
                                              {-1.8, 3.8, -1.5, -0.6, 3.8}};
  const std::vector<DoorRoom> inside_west = {{-8.5, -5.2, -6.3, -5.4, 3.3}};
  const std::vector<DoorRoom> east = {{-8.8, -4.8, -7.0, -6.1, 4.0}, {-4.6, 0.8, -2.2, -1.3, 3.0}};
  const std::vector<DoorRoom> north = {
      {1.9, 5.8, 4.5, 5.4, 4.0}, {-3.3, 1.7, -3.0, -2.1, 4.0}, {-7.5, -3.5, -4.6, -3.7, 4.0}};
  scene.surfaces.push_back(
      {CorridorWithRooms(corridor, {inside_south, inside_west, {}, east, north, {}}, 0.2), false,
       "walls"});
  scene.default_pose = Se2(5.0, 0.0, -kPi / 2);
  scene.waypoints = {{-7, 0},    {-2.55, 0},   {-2.55, 3.0}, {-2.55, -0.2}, {5, -0.2},
                     {5, -6.55}, {8.2, -6.55}, {5.2, -6.55}, {5.2, -8.3}};
  return Centred(std::move(scene));
}

const std::vector<std::pair<std::string, std::function<Scene()>>>& Registry() {
  static const std::vector<std::pair<std::string, std::function<Scene()>>> registry = {
      {"square", Square},          {"rectangle", Rectangle}, {"circle", CircularRoom},
      {"two-circles", TwoCircles}, {"l-room", LRoom},        {"corridor", Corridor},
      {"office", Office},          {"l-office", LOffice}};
  return registry;
}

}  // namespace

std::vector<std::string> BuiltinSceneNames() {
  std::vector<std::string> names;
  for (const auto& entry : Registry()) names.push_back(entry.first);
  return names;
}

std::optional<Scene> BuiltinScene(std::string_view name) {
  for (const auto& [entry_name, make] : Registry()) {
    if (entry_name == name) return make();
  }
  return std::nullopt;
}

}  // namespace priormap
