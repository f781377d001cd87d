#pragma once
/// Localized laser measurements as the PRF likelihood sees them (Paskin & Thrun, Sec. 2.2): each
/// beam is a ray from a known sensor position with a reading that is either a distance below the
/// model's max range or a max-range reading ("nothing within R").

#include <cstddef>
#include <optional>
#include <vector>

#include <priormap/core/diagnostic.hpp>
#include <priormap/core/log.hpp>
#include <priormap/core/types.hpp>
#include <priormap/prf/window.hpp>

namespace priormap::prf {

struct LaserBeam {
  Vec2 origin = Vec2::Zero();
  Vec2 direction = Vec2::UnitX();  ///< unit
  double range = 0.0;              ///< the reading, when not max_reading
  bool max_reading = false;
  int sensor = 0;  ///< index into LaserData::sensors
};

struct LaserData {
  std::vector<Vec2> sensors;  ///< positions of the scans' sensors
  std::vector<LaserBeam> beams;
  /// R: readings at or above it are max-range readings; beams are followed to it.
  double max_range = 0.0;
};

struct LaserSelection {
  std::size_t first_scan = 0;
  std::optional<std::size_t> end_scan{};  ///< one past the last; all scans when unset
  std::size_t beam_step = 1;              ///< every beam_step-th beam of each scan
  /// Caps the sensor's own max range (long beams cost walk time and say little indoors).
  double max_range = 20.0;
};

/// The beams of log.scans[first_scan, end_scan). Invalid readings (NaN, below min range,
/// flagged) and scans without a finite pose are left out. R is the smallest of
/// selection.max_range and the scans' own max ranges; readings at or above it become max-range
/// readings. Fails, with a diagnostic that has no file position (the selection is not a file),
/// when the selection is empty or out of range.
[[nodiscard]] Result<LaserData> SelectBeams(const Log& log, const LaserSelection& selection);

/// The smallest window holding every sensor and every reading's end point, grown by `margin`
/// on each side.
[[nodiscard]] Window WindowAround(const LaserData& data, double margin);

}  // namespace priormap::prf
