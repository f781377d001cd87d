#pragma once
// Where the corner between two regions of one surface lies, from their estimated lines.
//
// The priors say how the normals of neighbouring regions relate, not which region the reading
// right at a corner belongs to: a beam a few millimetres from the corner is within the noise of
// both walls' lines, so the fit alone decides it by chance. The regions' lines, fitted to
// hundreds of points, place the corner far more precisely than one reading does, and a
// continuous surface puts it between the last beam of one region and the first of the next
// (a ray on one side of the corner's bearing hits one wall, on the other side the other).
#include <span>

namespace priormap::priorlets {

struct CornerCheck {
  // The two tangent lines turn by at least min_turn: where they meet means something.
  bool turned = false;
  // ... and they meet in front of the sensor (if far from the border's bearing, see shift, the
  // two regions are not the sides of one corner but one hides the other).
  bool corner = false;
  // The lines hardly turn but lie apart: each point is farther from the other's line than a
  // corner turning by min_turn between them would put it. A step, where one surface hides
  // another behind it, not a corner.
  bool step = false;
  double bearing = 0.0;  ///< of the lines' intersection, rad, sensor frame
  // Beams the border must move for the corner to lie between its two points: -k hands the last
  // k points before the border to the region after it, +k the first k after it to the one before.
  int shift = 0;
};

struct CornerOptions {
  double min_turn = 0.17;  ///< rad (10 deg): below, the intersection is too ill-conditioned
};

// Points j = 0..n-1 of consecutive in-model beams with bearings phi[j] (increasing), ranges
// rho[j] and normals alpha[j] (towards the sensor); the border lies between points `border` and
// `border + 1`. The lines are the tangents at those two points. The shift counts points up to the
// ends of the spans; the caller decides how far a border may move.
[[nodiscard]] CornerCheck CheckCorner(std::span<const double> phi, std::span<const double> rho,
                                      std::span<const double> alpha, std::size_t border,
                                      const CornerOptions& options = {});

}  // namespace priormap::priorlets
