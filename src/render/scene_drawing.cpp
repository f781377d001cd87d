#include <cmath>

#include <priormap/core/segment.hpp>
#include <priormap/core/world_bounds.hpp>
#include <priormap/render/scene_drawing.hpp>

namespace priormap::render {
namespace {

const Color kWallColor{0.25, 0.25, 0.25};
const Color kClutterColor = palette::kOrange;

// Reading i's ray, in the world, from where it starts to the sensor's max range.
Segment MaxRangeRay(const Scan& scan, std::size_t i) {
  const Vec2 origin = scan.pose.Transform(scan.ReadingOrigin(i));
  return {origin, origin + scan.max_range * UnitVector(scan.angles[i] + scan.pose.theta())};
}

}  // namespace

void DrawScene(Figure& figure, const Scene& scene) {
  for (const SceneSurface& surface : scene.surfaces) {
    const Color color = surface.clutter ? kClutterColor : kWallColor;
    if (const auto* polyline = std::get_if<priormap::Polyline>(&surface.shape)) {
      if (surface.clutter && polyline->closed) {
        figure.FilledPolygon(Polygon{polyline->points}, color.WithAlpha(0.5), {color, 1.5, {}});
      } else {
        figure.Polyline(polyline->points, polyline->closed, {color, 3.0, {}});
      }
    } else {
      const Circle& circle = std::get<Circle>(surface.shape);
      if (surface.clutter) figure.FilledCircle(circle, color.WithAlpha(0.5));
      figure.CircleOutline(circle, {color, surface.clutter ? 1.5 : 3.0, {}});
    }
  }
}

void DrawScan(Figure& figure, const Scan& scan, const ScanStyle& style) {
  std::vector<Vec2> valid, outliers, normal_points;
  std::vector<double> normal_angles;
  for (std::size_t i = 0; i < scan.size(); ++i) {
    if (scan.status[i] == BeamStatus::kMaxRange && style.max_range_rays &&
        std::isfinite(scan.max_range)) {
      const Segment ray = MaxRangeRay(scan, i);
      figure.Line(ray.a, ray.b, {palette::kLightGray.WithAlpha(0.35), 0.5, {}});
    }
    if (!scan.IsValid(i)) continue;
    const Vec2 p = scan.PointInWorld(i);
    if (scan.sonar) {
      // The echo could have come from anywhere on the arc across its cone.
      const double axis = scan.angles[i] + scan.pose.theta(), half = scan.sonar->spread / 2;
      figure.Arc(scan.pose.Transform(scan.ReadingOrigin(i)), scan.ranges[i], axis - half,
                 axis + half, {style.valid.WithAlpha(0.4), 1.0, {}});
    }
    const bool outlier = scan.truth && scan.truth->outlier[i] != 0;
    (outlier ? outliers : valid).push_back(p);
    if (style.true_normals && scan.truth && std::isfinite(scan.truth->alpha[i]) && !outlier) {
      normal_points.push_back(p);
      normal_angles.push_back(scan.truth->alpha[i] + scan.pose.theta());
    }
  }
  if (!normal_points.empty()) {
    figure.Ticks(normal_points, normal_angles, style.normal_length_px, {palette::kGreen, 1.0, {}});
  }
  figure.Points(valid, style.valid, style.point_radius_px);
  figure.Points(outliers, style.outlier, style.point_radius_px * 1.4);
  if (style.pose) figure.PoseMarker(scan.pose, palette::kYellow, 12.0);
}

void DrawLog(Figure& figure, const Log& log, int stride) {
  const std::size_t step = static_cast<std::size_t>(std::max(stride, 1));
  std::vector<Vec2> points, trajectory;
  for (std::size_t k = 0; k < log.scans.size(); k += step) {
    const Scan& scan = log.scans[k];
    for (std::size_t i = 0; i < scan.size(); ++i) {
      if (scan.IsValid(i)) points.push_back(scan.PointInWorld(i));
    }
  }
  for (const Scan& scan : log.scans) trajectory.push_back(scan.pose.translation());
  figure.Points(points, palette::kBlue.WithAlpha(0.35), 0.8);
  figure.Polyline(trajectory, false, {palette::kVermillion, 1.5, {}});
}

Box2 ScanBounds(const Scan& scan) {
  Box2 box(scan.pose.translation());
  for (std::size_t i = 0; i < scan.size(); ++i) {
    if (scan.IsValid(i)) box.extend(scan.PointInWorld(i));
  }
  // With no echo at all, the max-range rays are all there is to show; unless the max range is
  // longer than any return may be (world_bounds.hpp), a finite stand-in for "none": such rays
  // are drawn, clipped, but cannot size the figure.
  if (scan.NumValid() == 0 && IsReturnWithinWorld(scan.max_range)) {
    for (std::size_t i = 0; i < scan.size(); ++i)
      if (scan.status[i] == BeamStatus::kMaxRange) box.extend(MaxRangeRay(scan, i).b);
  }
  return box;
}

Box2 LogBounds(const Log& log) {
  Box2 box;
  for (const Scan& scan : log.scans) box.extend(ScanBounds(scan));
  return box;
}

}  // namespace priormap::render
