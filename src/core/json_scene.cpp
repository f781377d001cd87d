// priormap.scene JSON documents (docs/formats.md).
#include <span>
#include <string_view>

#include <fmt/format.h>

#include <priormap/core/file_io.hpp>
#include <priormap/core/json_io.hpp>
#include <priormap/core/world_bounds.hpp>

#include "json_document.hpp"

namespace priormap {
namespace {

using detail::JsonNode;
using detail::OrderedJson;

constexpr int kVersion = 1;

OrderedJson PointsToJson(const std::vector<Vec2>& points) {
  OrderedJson array = OrderedJson::array();
  for (const Vec2& p : points) array.push_back({p.x(), p.y()});
  return array;
}

std::vector<Vec2> ReadPoints(const JsonNode& node, std::string_view what) {
  const std::size_t n = detail::ArraySize(node, what);
  std::vector<Vec2> points(n);
  for (std::size_t i = 0; i < n; ++i)
    points[i] = detail::Point(detail::Element(node, i), "a point [x, y]");
  return points;
}

// Every key the reader takes, by object: any other is refused rather than ignored, as in the logs
// (a misspelt "clutter" would make an object a wall for the priors, a misspelt "default_pose"
// would simulate from the origin).
constexpr std::string_view kSceneKeys[] = {"format",   "version",      "name",
                                           "surfaces", "default_pose", "waypoints"};
constexpr std::string_view kPolylineKeys[] = {"type", "points", "closed", "clutter", "label"};
constexpr std::string_view kCircleKeys[] = {"type", "center", "radius", "clutter", "label"};

SceneSurface ReadSurface(const JsonNode& node) {
  detail::RequireObject(node, "a surface");
  SceneSurface surface;
  const JsonNode type_node = detail::Member(node, "type");
  const std::string type = detail::String(type_node, "the surface type");
  if (type == "polyline" || type == "circle") {
    const std::span<const std::string_view> known =
        type == "polyline" ? std::span<const std::string_view>(kPolylineKeys)
                           : std::span<const std::string_view>(kCircleKeys);
    detail::RefuseUnknownMembers(node, known, fmt::format("a {} surface", type));
  }
  if (type == "polyline") {
    Polyline polyline;
    const JsonNode points = detail::Member(node, "points");
    polyline.points = ReadPoints(points, "\"points\"");
    if (polyline.points.size() < 2) detail::Fail(points, "a polyline needs at least 2 points");
    if (const auto closed = detail::OptionalMember(node, "closed"))
      polyline.closed = detail::Boolean(*closed, "\"closed\"");
    surface.shape = std::move(polyline);
  } else if (type == "circle") {
    const Vec2 center = detail::Point(detail::Member(node, "center"), "the circle centre");
    const JsonNode radius_node = detail::Member(node, "radius");
    const double radius = detail::FiniteNumber(radius_node, "the radius");
    if (!(radius > 0.0))
      detail::Fail(radius_node, fmt::format("radius must be positive, got {}", radius));
    // The whole circle within the world, as every point of a scene: its bounds are drawn and
    // gridded like the points'.
    if (const auto beyond = CircleBeyondWorld(center.x(), center.y(), radius))
      detail::Fail(radius_node, *beyond);
    surface.shape = Circle{center, radius};
  } else {
    detail::Fail(
        type_node,
        fmt::format("expected a surface type (\"polyline\" or \"circle\"), got \"{}\"", type));
  }
  if (const auto clutter = detail::OptionalMember(node, "clutter"))
    surface.clutter = detail::Boolean(*clutter, "\"clutter\"");
  if (const auto label = detail::OptionalMember(node, "label"))
    surface.label = detail::String(*label, "\"label\"");
  return surface;
}

Scene ReadScene(const JsonNode& root) {
  detail::RequireFormat(root, "priormap.scene", kVersion);
  detail::RefuseUnknownMembers(root, kSceneKeys, "a priormap.scene document");
  Scene scene;
  if (const auto name = detail::OptionalMember(root, "name"))
    scene.name = detail::String(*name, "the scene name");
  const JsonNode surfaces = detail::Member(root, "surfaces");
  const std::size_t n = detail::ArraySize(surfaces, "\"surfaces\"");
  for (std::size_t i = 0; i < n; ++i) {
    const JsonNode surface = detail::Element(surfaces, i);
    scene.surfaces.push_back(ReadSurface(surface));
    if (const std::vector<std::string> problems = scene.surfaces.back().Problems();
        !problems.empty()) {
      detail::Fail(surface, problems.front());
    }
  }
  if (const auto pose = detail::OptionalMember(root, "default_pose"))
    scene.default_pose = detail::Pose(*pose, "the default pose");
  if (const auto waypoints = detail::OptionalMember(root, "waypoints"))
    scene.waypoints = ReadPoints(*waypoints, "\"waypoints\"");
  return scene;
}

// What ReadScene refuses besides a position beyond the world (Scene::FirstBeyondWorld): a
// surface that is not usable (a polyline of fewer than two points or with a segment of zero
// length, a radius <= 0 or not finite), a circle that reaches beyond the world, in the reader's
// own words, and a default pose whose heading is not finite.
std::optional<std::string> SceneRefusal(const Scene& scene) {
  for (std::size_t s = 0; s < scene.surfaces.size(); ++s) {
    const SceneSurface& surface = scene.surfaces[s];
    if (const std::vector<std::string> problems = surface.Problems(); !problems.empty())
      return fmt::format("surface {}: {}", s, problems.front());
    if (const auto* circle = std::get_if<Circle>(&surface.shape))
      if (const auto beyond =
              CircleBeyondWorld(circle->center.x(), circle->center.y(), circle->radius))
        return fmt::format("surface {}: {}", s, *beyond);
  }
  if (scene.default_pose) return HeadingNotFinite("default_pose", scene.default_pose->theta());
  return std::nullopt;
}

}  // namespace

std::string FormatJsonScene(const Scene& scene) {
  if (const auto beyond = scene.FirstBeyondWorld())
    throw IoError(CannotWriteBeyondWorld("the scene", *beyond));
  if (const auto refused = SceneRefusal(scene))
    throw IoError(CannotWriteRefused("the scene", *refused));
  OrderedJson j;
  j["format"] = "priormap.scene";
  j["version"] = kVersion;
  j["name"] = scene.name;
  OrderedJson surfaces = OrderedJson::array();
  for (const SceneSurface& surface : scene.surfaces) {
    OrderedJson s;
    if (const auto* polyline = std::get_if<Polyline>(&surface.shape)) {
      s["type"] = "polyline";
      s["points"] = PointsToJson(polyline->points);
      s["closed"] = polyline->closed;
    } else {
      const Circle& circle = std::get<Circle>(surface.shape);
      s["type"] = "circle";
      s["center"] = {circle.center.x(), circle.center.y()};
      s["radius"] = circle.radius;
    }
    s["clutter"] = surface.clutter;
    if (!surface.label.empty()) s["label"] = surface.label;
    surfaces.push_back(std::move(s));
  }
  j["surfaces"] = std::move(surfaces);
  if (scene.default_pose) j["default_pose"] = detail::PoseToJson(*scene.default_pose);
  if (!scene.waypoints.empty()) j["waypoints"] = PointsToJson(scene.waypoints);
  return detail::Dump(j, 2) + "\n";
}

Result<Scene> ParseJsonScene(std::string_view text, const std::string& name) {
  Result<detail::JsonDocument> document = detail::JsonDocument::Parse(text, name);
  if (!document) return document.diagnostics();
  try {
    return ReadScene(document.value().root());
  } catch (const detail::JsonSchemaError& error) {
    return document.value().Diagnose(error);
  }
}

Result<Scene> ReadJsonScene(const std::filesystem::path& path) {
  Result<std::string> text = ReadFileText(path);
  if (!text) return text.diagnostics();
  return ParseJsonScene(text.value(), path.string());
}

void WriteJsonScene(const Scene& scene, const std::filesystem::path& path) {
  WriteTextFileAtomically(path, FormatJsonScene(scene));
}

}  // namespace priormap
