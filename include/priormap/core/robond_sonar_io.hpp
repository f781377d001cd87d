#pragma once
/// The sonar data of Udacity's RoboND occupancy-grid project (../shared/data/sonar-roboND,
/// docs/formats.md): a measurement file of lines "t_ms z_0 .. z_7" (ranges in millimetres,
/// 5110 = no echo) and a pose file of lines "t_ms x_mm y_mm theta" (theta in tenths of a
/// degree), line k of one matching line k of the other, the times increasing strictly. Each line
/// pair becomes one sonar ring.

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <priormap/core/diagnostic.hpp>
#include <priormap/core/log.hpp>

namespace priormap {

struct RoboNdSonarOptions {
  /// The transducers' bearings, rad; the data's README: -90, -37.5, -22.5, -7.5, 7.5, 22.5,
  /// 37.5, 90 deg, all at the robot's origin.
  std::vector<double> bearings = RoboNdBearings();
  double spread = 0.3490658503988659;  ///< full cone angle, rad (20 deg, the upstream beta)
  double min_range = 0.17;             ///< m: readings below are invalid (the upstream Zmin)
  /// Readings at or above this many millimetres mean "no echo" (max-range readings); it is
  /// also the scans' max range.
  double no_echo_mm = 5110.0;
  /// Range noise given to each reading: max(sigma_min, sigma_relative * range).
  double sigma_relative = 0.01;
  double sigma_min = 0.005;  ///< m

  [[nodiscard]] static std::vector<double> RoboNdBearings();
};

/// Parses the two files' text (named in diagnostics, which point at file:line:col); a time
/// not after the previous line's (a line copied or moved) is an error. The log's
/// scans are sonar rings (channel "SONAR") at the given poses; pose_source is kGroundTruth
/// (the upstream project calls its poses exact).
[[nodiscard]] Result<Log> ParseRoboNdSonar(std::string_view measurements,
                                           const std::string& measurements_name,
                                           std::string_view poses, const std::string& poses_name,
                                           const RoboNdSonarOptions& options = {});

/// Reads and parses the two files (plain or gzip-compressed).
[[nodiscard]] Result<Log> ReadRoboNdSonar(const std::filesystem::path& measurements,
                                          const std::filesystem::path& poses,
                                          const RoboNdSonarOptions& options = {});

}  // namespace priormap
