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

const std::vector<std::pair<std::string, std::function<Scene()>>>& Registry() {
  static const std::vector<std::pair<std::string, std::function<Scene()>>> registry = {
      {"square", Square},          {"rectangle", Rectangle}, {"circle", CircularRoom},
      {"two-circles", TwoCircles}, {"l-room", LRoom},        {"corridor", Corridor}};
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
