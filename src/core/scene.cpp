#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include <priormap/core/scene.hpp>
#include <priormap/core/world_bounds.hpp>

namespace priormap {
namespace {

bool IsFinite(const Vec2& p) {
  return std::isfinite(p.x()) && std::isfinite(p.y());
}

void AddPolylineProblems(const Polyline& polyline, std::vector<std::string>& problems) {
  if (polyline.points.size() < 2) {
    problems.push_back("a polyline needs at least 2 points");
    return;
  }
  if (!std::all_of(polyline.points.begin(), polyline.points.end(), IsFinite)) {
    problems.push_back("non-finite point");
  }
  for (std::size_t i = 0; i < polyline.NumSegments(); ++i) {
    if (polyline.segment(i).Length() == 0.0) {
      problems.push_back(fmt::format("segment {} has zero length", i));
    }
  }
}

}  // namespace

std::vector<ScenePrimitive> Scene::Primitives() const {
  std::vector<ScenePrimitive> primitives;
  for (std::size_t s = 0; s < surfaces.size(); ++s) {
    const SceneSurface& surface = surfaces[s];
    const auto add = [&](std::variant<Segment, Circle> shape) {
      primitives.push_back({std::move(shape), static_cast<int>(s),
                            static_cast<int>(primitives.size()), surface.clutter});
    };
    if (const auto* polyline = std::get_if<Polyline>(&surface.shape)) {
      for (std::size_t i = 0; i < polyline->NumSegments(); ++i) add(polyline->segment(i));
    } else {
      add(std::get<Circle>(surface.shape));
    }
  }
  return primitives;
}

Box2 Scene::Bounds() const {
  Box2 box;
  for (const SceneSurface& surface : surfaces) {
    std::visit([&](const auto& shape) { box.extend(shape.Bounds()); }, surface.shape);
  }
  return box;
}

std::vector<std::string> SceneSurface::Problems() const {
  std::vector<std::string> problems;
  if (const auto* polyline = std::get_if<Polyline>(&shape)) {
    AddPolylineProblems(*polyline, problems);
  } else {
    const Circle& circle = std::get<Circle>(shape);
    if (!IsFinite(circle.center)) problems.push_back("non-finite circle centre");
    if (!(circle.radius > 0.0 && std::isfinite(circle.radius))) {
      problems.push_back("circle radius must be positive and finite");
    }
  }
  return problems;
}

namespace {

std::optional<std::string> SurfaceBeyondWorld(const SceneSurface& surface) {
  if (const auto* polyline = std::get_if<Polyline>(&surface.shape)) {
    for (std::size_t i = 0; i < polyline->points.size(); ++i) {
      const Vec2& p = polyline->points[i];
      if (auto beyond = CoordinateBeyondWorld(fmt::format("point {}", i), p.x(), p.y()))
        return beyond;
    }
    return std::nullopt;
  }
  // The circle's far side is the radius's business (CircleBeyondWorld), in the reader's words.
  const Vec2& c = std::get<Circle>(surface.shape).center;
  return CoordinateBeyondWorld("the circle centre", c.x(), c.y());
}

}  // namespace

std::optional<std::string> Scene::FirstBeyondWorld() const {
  for (std::size_t s = 0; s < surfaces.size(); ++s)
    if (const auto beyond = SurfaceBeyondWorld(surfaces[s]))
      return fmt::format("surface {}: {}", s, *beyond);
  if (default_pose) {
    if (auto beyond = CoordinateBeyondWorld("default_pose", default_pose->x(), default_pose->y()))
      return beyond;
  }
  for (std::size_t i = 0; i < waypoints.size(); ++i) {
    const Vec2& p = waypoints[i];
    if (auto beyond = CoordinateBeyondWorld(fmt::format("waypoint {}", i), p.x(), p.y()))
      return beyond;
  }
  return std::nullopt;
}

std::vector<std::string> Scene::Problems() const {
  std::vector<std::string> problems;
  for (std::size_t s = 0; s < surfaces.size(); ++s) {
    for (const std::string& p : surfaces[s].Problems()) {
      problems.push_back(fmt::format("surface {}: {}", s, p));
    }
  }
  if (default_pose && !default_pose->IsFinite()) problems.push_back("default pose is not finite");
  for (const Vec2& p : waypoints) {
    if (!IsFinite(p)) problems.push_back("waypoint is not finite");
  }
  return problems;
}

}  // namespace priormap
