#pragma once
/// Localized sonar readings as the PRF sonar likelihood sees them (Paskin & Thrun, Sec. 2.3):
/// each reading is a cone from a known transducer position, with a reading that is either a
/// distance below the max range or a max-range reading ("no echo within R").

#include <cstddef>
#include <optional>
#include <vector>

#include <priormap/core/diagnostic.hpp>
#include <priormap/core/log.hpp>
#include <priormap/core/types.hpp>
#include <priormap/prf/window.hpp>

namespace priormap::prf {

/// The cone of one reading: apex, axis and half-angle, followed to R.
struct SonarCone {
  Vec2 origin = Vec2::Zero();
  Vec2 axis = Vec2::UnitX();                 ///< unit
  double half_spread = 0.17453292519943295;  ///< rad, in (0, pi/2)
  double max_range = 5.0;                    ///< R, m
};

struct SonarReading {
  SonarCone cone;
  double range = 0.0;  ///< the reading, when not max_reading
  bool max_reading = false;
  int sensor = 0;  ///< index into SonarData::sensors (the cone's apex)
};

struct SonarData {
  std::vector<Vec2> sensors;  ///< distinct transducer positions (apexes), per ring
  std::vector<SonarReading> readings;
  /// R: readings at or above it are max-range readings; cones are followed to it.
  double max_range = 0.0;
};

struct SonarSelection {
  std::size_t first_scan = 0;
  std::optional<std::size_t> end_scan{};  ///< one past the last; all scans when unset
  /// Caps the rings' own max range (the paper treated readings beyond 3.5 m as max range).
  double max_range = 5.0;
};

/// The readings of the sonar rings (scans with `sonar` fields) among log.scans[first_scan,
/// end_scan); other scans are passed over. Invalid readings (NaN, below min range) and rings
/// without a finite pose are left out. R is the smallest of selection.max_range and the rings'
/// own max ranges; readings at or above it become max-range readings. Fails, with a diagnostic
/// that has no file position, when the selection holds no sonar reading.
[[nodiscard]] Result<SonarData> SelectSonarReadings(const Log& log,
                                                    const SonarSelection& selection);

/// The smallest window holding every sensor and every reading's arc (the cone's far edge at
/// the reading), grown by `margin` on each side.
[[nodiscard]] Window WindowAround(const SonarData& data, double margin);

}  // namespace priormap::prf
