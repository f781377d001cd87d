#pragma once
/// Drawing the core types (scenes, scans, logs) on a Figure with the toolkit's conventions.

#include <priormap/core/log.hpp>
#include <priormap/core/scene.hpp>
#include <priormap/render/figure.hpp>

namespace priormap::render {

struct ScanStyle {
  Color valid = palette::kBlue;
  Color outlier = palette::kVermillion;  ///< readings the ground truth marks as outliers
  double point_radius_px = 1.6;
  bool max_range_rays = true;  ///< faint rays for max-range readings
  bool true_normals = true;    ///< ticks along true_alpha, when the scan has ground truth
  double normal_length_px = 7.0;
  bool pose = true;
};

/// The walls (dark), circles and clutter (orange) of a scene.
void DrawScene(Figure& figure, const Scene& scene);
/// A scan in the world frame, with the sensor pose and, when known, true normals and outliers.
void DrawScan(Figure& figure, const Scan& scan, const ScanStyle& style = {});
/// All scans of a log as points (every `stride`-th scan) and the trajectory of scan poses.
void DrawLog(Figure& figure, const Log& log, int stride = 1);

/// World bounding box of a scan's valid readings and its pose (and of its max-range rays when it
/// has no valid reading and its max range is one a return could have, world_bounds.hpp).
[[nodiscard]] Box2 ScanBounds(const Scan& scan);
/// World bounding box of all valid readings and poses of a log.
[[nodiscard]] Box2 LogBounds(const Log& log);

}  // namespace priormap::render
