#include "sensor_choice.hpp"

#include <fmt/format.h>

#include "cli_support.hpp"

namespace priormap::app {

Sensor ResolveSensor(const std::string& choice, const Log& log, std::size_t first,
                     std::size_t end) {
  std::size_t rings = 0, lasers = 0;
  for (std::size_t k = first; k < end && k < log.scans.size(); ++k)
    (log.scans[k].sonar ? rings : lasers) += 1;
  if (choice == "laser" || (choice == "auto" && rings == 0)) {
    if (lasers == 0)
      throw UserError(
          "--sensor laser: the selected scans are all sonar rings (use --sensor sonar)");
    return Sensor::kLaser;
  }
  if (choice == "sonar" || (choice == "auto" && lasers == 0)) {
    if (rings == 0)
      throw UserError("--sensor sonar: the selected scans hold no sonar ring (a laser log?)");
    return Sensor::kSonar;
  }
  throw UserError(fmt::format(
      "the selected scans mix {} sonar rings and {} laser scans: choose one with --sensor laser "
      "or --sensor sonar",
      rings, lasers));
}

}  // namespace priormap::app
