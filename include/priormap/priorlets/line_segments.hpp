#pragma once
/// Line segments from the straight regions of a MAP scan, in the convention of ROS's
/// laser_line_extraction (its LineSegment message): the line in polar form (radius >= 0 from the
/// sensor, angle of its normal), the 2x2 covariance of (radius, angle) row-major, and the
/// segment's start and end points, all in the sensor frame.
///
/// Each region with enough in-model points is fitted by total least squares to its corrected
/// points; a region whose points stray from the line (a circle's arc, say) gives no segment.
/// The covariance propagates the ranges' uncertainty through the fit (its Jacobian by central
/// differences): the posterior covariance of the ranges when the posterior kept it, else their
/// posterior standard deviations, else the sensor's noise.

#include <string>
#include <vector>

#include <priormap/core/scan.hpp>
#include <priormap/core/types.hpp>
#include <priormap/priorlets/engine.hpp>
#include <priormap/priorlets/posterior.hpp>

namespace priormap::priorlets {

struct LineSegment {
  double radius = 0.0;  ///< distance from the sensor to the line, m (>= 0)
  double angle = 0.0;   ///< direction of the line's normal seen from the sensor, rad, (-pi, pi]
  Mat2 covariance = Mat2::Zero();  ///< of (radius, angle)
  Vec2 start = Vec2::Zero();       ///< the region's first point projected on the line, m
  Vec2 end = Vec2::Zero();         ///< ... and its last
  BeamRange beams;                 ///< the region (first > last: across a full turn's seam)
  std::size_t points = 0;          ///< in-model points fitted
  double rms = 0.0;                ///< of their distances to the line, m
};

enum class SegmentCovarianceSource { kPosterior, kPosteriorDiagonal, kSensor };

struct LineSegmentOptions {
  std::size_t min_points = 5;
  /// A region is a segment only when its points lie this close to the fitted line (RMS), m.
  double max_rms = 0.02;
};

struct LineSegments {
  std::vector<LineSegment> segments;
  SegmentCovarianceSource covariance_source = SegmentCovarianceSource::kSensor;
};

/// The segments of `map` (from EstimateMapScan on `scan`); `posterior` may be null.
[[nodiscard]] LineSegments ExtractLineSegments(const Scan& scan, const MapScan& map,
                                               const Posterior* posterior,
                                               const LineSegmentOptions& options = {});

/// {"format": "priormap.line_segments", "header": {"frame_id", "stamp"}, "covariance_source",
///  "line_segments": [{"radius", "angle", "covariance": [4], "start": [2], "end": [2],
///  "beams": [first, last], "points", "rms"}]}: a LineSegmentList message as JSON, plus our
/// fields.
[[nodiscard]] std::string LineSegmentsToJson(const LineSegments& lines, const std::string& frame_id,
                                             double stamp);

}  // namespace priormap::priorlets
