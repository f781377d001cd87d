#pragma once
/// Baseline surface-normal estimators that the priorlet engine is benchmarked against: local PCA
/// on neighbouring beams, and one line fit per wall given the true segmentation (an oracle).
///
/// A normal is the angle alpha in the sensor frame of the normal pointing back towards the
/// sensor (Censi's CSM convention), wrapped to (-pi, pi] exactly like ScanTruth::alpha, so that
/// estimates and truth can be compared entry by entry. Beams without an estimate get NaN.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <priormap/core/scan.hpp>
#include <priormap/core/scene.hpp>

namespace priormap::priorlets {

/// The noise model a line fit assumes.
enum class LineFitModel {
  /// Total least squares on the points, weights 1 / sigma_i^2 (PCA): treats each point's noise
  /// as isotropic. With the real, radial noise it is slightly biased (the noise scatter adds
  /// sigma^2 u u^T, not sigma^2 I, to the point scatter) and not efficient.
  kOrthogonal,
  /// Maximum likelihood for noise along the beam: minimises the range residuals
  /// r_i - rho / cos(phi_i - alpha_out), weighted 1 / sigma_i^2 (Gauss-Newton started at the
  /// kOrthogonal fit). Equivalent to weighting orthogonal distances by 1 / (sigma_i cos)^2,
  /// where cos is that of the angle of incidence. Ignores Scan::precision (correlated noise).
  kRadial,
};

[[nodiscard]] const char* ToString(LineFitModel model);

struct PcaNormalOptions {
  /// Window of beams by index, i - k/2 .. i + k/2; odd, >= 3. Shorter windows are noisy on
  /// walls, longer ones blur corners; 31 (7.75 deg with the utm30) minimises the mean error on
  /// the square room with the utm30 at sigma = 1 cm (flat from 27 to 35; the errors for
  /// k = 5 .. 31 are printed by tests/priorlets/normal_baselines_test.cpp). k counts beams, so
  /// scale it with the angular resolution for other sensors.
  int k = 31;
  /// A window stops at the first jump larger than this between consecutive valid points, m, so
  /// that it does not join a wall to whatever is seen behind an occluding edge. The default is
  /// several times the point spacing of a utm30 on walls up to ~10 m at moderate incidence.
  double max_neighbour_distance = 0.2;
  /// kOrthogonal is PCA proper, the baseline of the literature.
  LineFitModel model = LineFitModel::kOrthogonal;

  [[nodiscard]] bool IsValid(std::string* why) const;
};

/// The normal of the line fitted to the valid readings `beams` (sensor frame, the direction
/// that points back along beam `facing_beam`, wrapped to (-pi, pi] as ScanTruth::alpha);
/// nullopt for fewer than two distinct points. The fit behind PcaNormals, and the engine's
/// initial normals.
[[nodiscard]] std::optional<double> FitLineNormal(const Scan& scan,
                                                  std::span<const std::size_t> beams,
                                                  std::size_t facing_beam,
                                                  LineFitModel model = LineFitModel::kOrthogonal);

/// One normal per beam from a line fitted to the valid readings in the beam's window (invalid
/// beams in the window are skipped, not replaced). Size scan.size(); NaN for beams that are not
/// valid and where the window holds fewer than 2 points. Precondition: options.IsValid().
[[nodiscard]] std::vector<double> PcaNormals(const Scan& scan,
                                             const PcaNormalOptions& options = {});

struct LineFitResult {
  std::vector<double> alpha;  ///< per beam: normal of its group's line, rad
  /// Per beam: distance from the sensor to its group's line, m (>= 0); the line is
  /// {p : p . (cos alpha, sin alpha) = -rho} in the sensor frame.
  std::vector<double> rho;
  /// Per beam: distance along the beam to its group's line (the reading corrected onto the
  /// line), m; NaN if the beam does not hit the line in front of the sensor.
  std::vector<double> range;
};

struct OracleLineFitOptions {
  /// kRadial by default: the oracle stands for the best that the true segmentation allows.
  LineFitModel model = LineFitModel::kRadial;
};

/// Fits one line per group of valid beams with the same label (label < 0: no group) and gives
/// every beam of the group that line. All outputs have size scan.size(); NaN for beams that are
/// not valid, have a negative label, or whose group has fewer than 2 points.
/// Precondition: labels.size() == scan.size().
[[nodiscard]] LineFitResult OracleLineFitNormals(const Scan& scan, std::span<const int> labels,
                                                 const OracleLineFitOptions& options = {});

/// The true segmentation into straight walls, for OracleLineFitNormals: truth.region (one
/// segment of a polyline) for beams that hit a segment of `scene`; -1 for beams that hit a
/// circle or nothing and for synthetic outliers (they are not on the wall). Precondition:
/// scan.truth is set and was simulated from `scene`.
[[nodiscard]] std::vector<int> StraightRegionLabels(const Scan& scan, const Scene& scene);

struct NormalErrorStats {
  double mean_deg = 0.0;  ///< mean smallest absolute angle between estimate and truth; NaN if none
  double max_deg = 0.0;   ///< NaN if count == 0
  std::size_t count = 0;  ///< beams compared
};

/// Errors |AngleDifference(estimate_i, truth_i)| over the beams where both are finite and, if
/// `mask` is not empty, mask_i != 0. Precondition: equal sizes (mask: empty or equal).
[[nodiscard]] NormalErrorStats CompareNormals(std::span<const double> estimate,
                                              std::span<const double> truth,
                                              std::span<const std::uint8_t> mask = {});

}  // namespace priormap::priorlets
