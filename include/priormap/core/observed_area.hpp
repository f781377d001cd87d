#pragma once
/// The part of a scene that a set of sensor poses observed, for scoring maps only where data
/// could say something. A point is
///   - visible from a pose when it lies within the sensor's range and field of view and the
///     straight line from the sensor reaches it without meeting a surface (a point on the first
///     surface met counts as visible: the sensor sees the surface itself);
///   - behind a surface when the line meets a surface within range at most `band` before it:
///     the thin layer just behind a seen surface, which the sensor observes as occupied;
///   - unseen otherwise.
/// Visibility is geometric, over every direction in the field of view, not only along the beams
/// of some data: the gaps between diverging beams are observed area (the "sparse" part a map
/// must fill in). It does not depend on the kind of range sensor (laser, sonar), only on where
/// it stood, which way it looked, and how far it reaches.

#include <cstdint>
#include <vector>

#include <priormap/core/angles.hpp>
#include <priormap/core/scene.hpp>
#include <priormap/core/scene_ray_caster.hpp>
#include <priormap/core/se2.hpp>

namespace priormap {

/// One sensor pose with the reach of its sensor.
struct SensorView {
  Se2 pose;                ///< T_world_sensor
  double fov = kTwoPi;     ///< rad, centred on the sensor's x axis
  double max_range = 8.0;  ///< m
};

enum class Observation : std::uint8_t { kUnseen = 0, kVisible = 1, kBehindSurface = 2 };

class ObservedArea {
 public:
  /// Throws ContractError for a negative band or a view with a non-positive fov or range.
  ObservedArea(const Scene& scene, std::vector<SensorView> views, double band);

  /// Visible from any view wins over behind a surface.
  [[nodiscard]] Observation Classify(const Vec2& p) const;

  [[nodiscard]] const std::vector<SensorView>& views() const { return views_; }
  [[nodiscard]] double band() const { return band_; }

 private:
  SceneRayCaster caster_;
  std::vector<SensorView> views_;
  double band_ = 0.0;
};

/// Points along the scene's surfaces (segments and circles), one every `spacing` metres or less,
/// that some view sees: the visible true walls, for the fraction of them a map recovers.
[[nodiscard]] std::vector<Vec2> VisibleWallPoints(const Scene& scene, const ObservedArea& observed,
                                                  double spacing);

}  // namespace priormap
