#pragma once
// --sensor auto|laser|sonar, shared by `priormap prf` and `priormap grid`: which readings of a
// log a map is built from.

#include <cstddef>
#include <string>

#include <priormap/core/log.hpp>

namespace priormap::app {

enum class Sensor { kLaser, kSonar };

/// The names --sensor takes.
inline constexpr const char* kSensorNames[] = {"auto", "laser", "sonar"};

/// `choice` ("auto", "laser" or "sonar") for scans [first, end) of the log: auto is sonar when
/// those scans are sonar rings, laser when none is; a mix of both needs an explicit choice.
/// Throws UserError naming --sensor when the choice finds nothing to map.
[[nodiscard]] Sensor ResolveSensor(const std::string& choice, const Log& log, std::size_t first,
                                   std::size_t end);

}  // namespace priormap::app
