#pragma once
/// A simulated planar range finder (laser): beams evenly spaced over a field of view, Gaussian
/// noise (optionally correlated between neighbours), outliers and missing returns.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace priormap {

struct RangeSensor {
  std::string name = "custom";
  int num_beams = 181;
  double fov = 3.141592653589793;  ///< rad; beams from -fov/2 to +fov/2 inclusive
  double sigma = 0.01;             ///< range noise standard deviation, m
  /// Correlation of the noise of neighbouring beams, in [0, 1): beams i and j have correlation
  /// correlation^|i - j| (scans carry the matching tridiagonal precision).
  double correlation = 0.0;
  double min_range = 0.0;  ///< m
  double max_range = 8.0;  ///< m; farther surfaces give a max-range reading
  /// Probability that a beam reports a spurious short reading, uniform in [min_range, true
  /// range) (people, dust, mixed pixels); marked in the ground truth as an outlier.
  double outlier_probability = 0.0;
  /// Probability that a beam gets no echo and reports max range.
  double dropout_probability = 0.0;

  /// False with the reason in `why` when a parameter is out of range.
  [[nodiscard]] bool IsValid(std::string* why) const;
  /// The beam angles phi_i, relative to the sensor x axis: evenly spaced from -fov/2 to fov/2;
  /// a single beam on the axis; a full circle (fov = 2 pi) in n equal steps from -pi, so that no
  /// direction is swept twice.
  [[nodiscard]] std::vector<double> BeamAngles() const;

  /// utm30: Hokuyo UTM-30LX, 1081 beams over 270 deg, sigma 1 cm, 0.1-30 m.
  /// lms200: SICK LMS200, 181 beams over 180 deg, sigma 1 cm, 0-8 m.
  [[nodiscard]] static std::optional<RangeSensor> Preset(std::string_view name);
  [[nodiscard]] static std::vector<std::string> PresetNames();
};

}  // namespace priormap
