#pragma once
/// A simulated world: surfaces made of wall polylines and circles, some marked as clutter.
/// Ground-truth ids follow the priorlets paper (Sec. II-A): the environment is partitioned into
/// surfaces (connected objects) and each surface into regions (one straight wall, one circle).

#include <optional>
#include <string>
#include <variant>
#include <vector>

#include <priormap/core/circle.hpp>
#include <priormap/core/polyline.hpp>
#include <priormap/core/se2.hpp>

namespace priormap {

/// One connected object of a scene.
struct SceneSurface {
  std::variant<Polyline, Circle> shape;
  bool clutter = false;  ///< not described by any structural prior (boxes, bins, people)
  std::string label;     ///< free text for figures and documentation

  /// Empty when usable; otherwise what is wrong (degenerate segments, radius <= 0, non-finite
  /// coordinates, polylines with fewer than two points).
  [[nodiscard]] std::vector<std::string> Problems() const;
};

/// The smallest piece a ray can hit: one segment of a polyline or one circle.
struct ScenePrimitive {
  std::variant<Segment, Circle> shape;
  int surface = -1;  ///< index into Scene::surfaces
  int region = -1;   ///< index into Scene::Primitives(); unique in the scene
  bool clutter = false;
};

struct Scene {
  std::string name;
  std::vector<SceneSurface> surfaces;
  /// A sensor pose that sees every wall of the scene (used when the user gives none).
  std::optional<Se2> default_pose;
  /// A path for simulated logs (visited in order, at constant speed).
  std::vector<Vec2> waypoints;

  /// Primitives in surface order; region ids are their positions in this list.
  [[nodiscard]] std::vector<ScenePrimitive> Primitives() const;
  /// Bounding box of all surfaces (empty box for an empty scene).
  [[nodiscard]] Box2 Bounds() const;
  /// Empty when the scene is usable; otherwise what is wrong, surface problems prefixed by
  /// "surface K: ".
  [[nodiscard]] std::vector<std::string> Problems() const;
  /// The first position of the scene beyond the world (world_bounds.hpp), named ("surface 2:
  /// point 0 x = 1e+300", "surface 0: the circle centre y = nan", "default_pose y = ...",
  /// "waypoint 3 x = ..."), or nullopt. Writers refuse such a scene: the reader would refuse the
  /// file. A circle must also lie within the world whole, which is a matter of its radius
  /// (CircleBeyondWorld, whose message the reader and the writer share).
  [[nodiscard]] std::optional<std::string> FirstBeyondWorld() const;
};

/// Names of the built-in scenes: square, rectangle, circle, two-circles, l-room, corridor,
/// office, l-office (corridors with rooms behind doorways; their free space is the inside of
/// one closed wall polyline, and their default pose, in the corridor, cannot see every wall).
[[nodiscard]] std::vector<std::string> BuiltinSceneNames();

/// A built-in scene, centred on the origin; nullopt for an unknown name.
[[nodiscard]] std::optional<Scene> BuiltinScene(std::string_view name);

}  // namespace priormap
