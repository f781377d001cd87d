#include <algorithm>
#include <cmath>
#include <variant>

#include <priormap/core/check.hpp>
#include <priormap/core/observed_area.hpp>

namespace priormap {

ObservedArea::ObservedArea(const Scene& scene, std::vector<SensorView> views, double band)
    : caster_(scene), views_(std::move(views)), band_(band) {
  PRIORMAP_CHECK(band >= 0.0, "the band behind surfaces must not be negative");
  for (const SensorView& view : views_)
    PRIORMAP_CHECK(view.fov > 0.0 && view.max_range > 0.0 && view.pose.IsFinite(),
                   "a sensor view needs a finite pose, a positive field of view and range");
}

Observation ObservedArea::Classify(const Vec2& p) const {
  bool behind = false;
  for (const SensorView& view : views_) {
    const Vec2 s = view.pose.translation();
    const Vec2 delta = p - s;
    const double d = delta.norm();
    if (d == 0.0) return Observation::kVisible;
    if (d > view.max_range + band_) continue;
    const double angle = std::atan2(delta.y(), delta.x());
    if (view.fov < kTwoPi && std::abs(AngleDifference(angle, view.pose.theta())) > 0.5 * view.fov)
      continue;
    const auto hit = caster_.Cast(Ray{s, angle}, std::min(d, view.max_range));
    // A point on the first surface met is seen (round-off may put it a hair beyond).
    const double tolerance = 1e-9 * std::max(1.0, d);
    if (!hit || hit->range >= d - tolerance) {
      if (d <= view.max_range + tolerance) return Observation::kVisible;
      continue;
    }
    if (d - hit->range <= band_) behind = true;
  }
  return behind ? Observation::kBehindSurface : Observation::kUnseen;
}

std::vector<Vec2> VisibleWallPoints(const Scene& scene, const ObservedArea& observed,
                                    double spacing) {
  PRIORMAP_CHECK(spacing > 0.0, "the spacing of wall points must be positive");
  std::vector<Vec2> points;
  const auto keep = [&](const Vec2& p) {
    if (observed.Classify(p) == Observation::kVisible) points.push_back(p);
  };
  for (const ScenePrimitive& wall : scene.Primitives()) {
    if (const auto* segment = std::get_if<Segment>(&wall.shape)) {
      const int n = std::max(1, static_cast<int>(std::ceil(segment->Length() / spacing)));
      for (int k = 0; k < n; ++k) keep(segment->PointAt((k + 0.5) / n));
    } else {
      const Circle& circle = std::get<Circle>(wall.shape);
      const int n = std::max(8, static_cast<int>(std::ceil(kTwoPi * circle.radius / spacing)));
      for (int k = 0; k < n; ++k)
        keep(circle.center + circle.radius * UnitVector(kTwoPi * (k + 0.5) / n));
    }
  }
  return points;
}

}  // namespace priormap
