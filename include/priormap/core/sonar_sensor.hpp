#pragma once
/// A simulated ring of sonar transducers (docs/sonar.md): each one hears the first echo from
/// anywhere in its cone. Surfaces echo when seen close to perpendicular, corners act as
/// reflectors and wall ends diffract weakly; a cone whose surfaces all reflect the wave away
/// (a specular miss) reports max range or, by multipath, a too-long reading.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <priormap/core/types.hpp>

namespace priormap {

struct SonarSensor {
  std::string name = "custom";
  /// Bearing of each transducer's axis in the robot frame, rad (the readings' angles).
  std::vector<double> bearings;
  /// Each transducer's position in the robot frame, m; empty: all at the robot's origin.
  std::vector<Vec2> offsets;
  double spread = 0.3490658503988659;  ///< full cone angle, rad (20 deg)
  double min_range = 0.17;             ///< echoes closer than this are not heard, m
  double max_range = 5.0;              ///< no echo within it: a max-range reading, m (<= 1e9)

  /// Range noise: Gaussian with standard deviation max(sigma_min, sigma_relative * range).
  double sigma_relative = 0.01;
  double sigma_min = 0.005;  ///< m

  /// Echo probability of a surface whose perpendicular foot lies in the cone (normal incidence).
  double surface_return = 0.95;
  /// Otherwise the echo fades with the smallest incidence angle ι seen in the cone (angle
  /// between the wave and the surface normal): surface_return · σ((critical − ι) / softness) /
  /// σ(critical / softness), σ the logistic function, so that it is surface_return at ι = 0.
  double critical_incidence = 0.1;    ///< rad (about 6 deg: surface roughness)
  double incidence_softness = 0.025;  ///< rad
  /// Echo probability of a corner seen from inside (two walls forming a reflector).
  double concave_corner_return = 0.85;
  /// Echo probability of a corner seen from outside, or of a wall's free end (diffraction).
  double convex_corner_return = 0.3;
  /// After a specular miss: probability that the wave, reflected by the surface on the axis,
  /// returns from the next surface it meets (a reading longer than any surface in the cone).
  double multipath_probability = 0.4;
  /// Probability that a reading is replaced by one uniform in [min_range, max_range).
  double spurious_probability = 0.01;
  /// Rays traced across each cone to find the parts of surfaces it sees (resolution of the
  /// simulation, not a property of the sensor).
  int rays_per_cone = 41;

  /// False with the reason in `why` when a parameter is out of range.
  [[nodiscard]] bool IsValid(std::string* why) const;
  /// Standard deviation of the range noise at `range`, m.
  [[nodiscard]] double Sigma(double range) const;

  /// pioneer8: a Pioneer 2's front ring, 8 transducers at -90, -50, -30, -10, 10, 30, 50, 90
  ///   deg on the robot's nose; pioneer16: front and rear rings;
  /// robond: the 8 bearings of ../shared/data/sonar-roboND (-90, -37.5, -22.5, -7.5, 7.5, 22.5,
  ///   37.5, 90 deg) at the robot's origin, 0.17-5.11 m.
  /// All with 20 deg cones and 1 % range noise.
  [[nodiscard]] static std::optional<SonarSensor> Preset(std::string_view name);
  [[nodiscard]] static std::vector<std::string> PresetNames();
};

}  // namespace priormap
