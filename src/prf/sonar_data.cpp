#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include <priormap/prf/sonar_data.hpp>

namespace priormap::prf {

// A selection is options, not a file: its diagnostics have no position.
Result<SonarData> SelectSonarReadings(const Log& log, const SonarSelection& selection) {
  const std::size_t end = std::min(selection.end_scan.value_or(log.scans.size()), log.scans.size());
  if (selection.first_scan >= end)
    return Diagnostic{"", 0, 0,
                      fmt::format("the scan range {}:{} selects no scan (the log has {})",
                                  selection.first_scan, end, log.scans.size())};
  if (!(selection.max_range > 0.0)) return Diagnostic{"", 0, 0, "the max range must be positive"};
  SonarData data;
  // One R for all readings, so that every max reading means the same "no echo within R".
  data.max_range = selection.max_range;
  bool any_ring = false;
  for (std::size_t k = selection.first_scan; k < end; ++k) {
    if (!log.scans[k].sonar) continue;
    any_ring = true;
    data.max_range = std::min(data.max_range, log.scans[k].max_range);
  }
  if (!any_ring)
    return Diagnostic{"", 0, 0,
                      fmt::format("the scans {}:{} hold no sonar ring (is this a laser log?)",
                                  selection.first_scan, end)};
  for (std::size_t k = selection.first_scan; k < end; ++k) {
    const Scan& scan = log.scans[k];
    if (!scan.sonar || !scan.pose.IsFinite()) continue;
    const SonarFields& sonar = *scan.sonar;
    const std::size_t first_sensor = data.sensors.size();
    for (std::size_t i = 0; i < scan.size(); ++i) {
      const BeamStatus status = scan.status[i];
      if (status == BeamStatus::kInvalid) continue;
      SonarReading reading;
      reading.cone.origin = scan.pose.Transform(sonar.Origin(i));
      reading.cone.axis = UnitVector(scan.pose.theta() + scan.angles[i]);
      reading.cone.half_spread = sonar.spread / 2.0;
      reading.cone.max_range = data.max_range;
      reading.max_reading = status == BeamStatus::kMaxRange || scan.ranges[i] >= data.max_range;
      reading.range = reading.max_reading ? data.max_range : scan.ranges[i];
      // The ring's transducers that share a position share a sensor.
      const auto begin = data.sensors.begin() + static_cast<std::ptrdiff_t>(first_sensor);
      const auto found = std::find(begin, data.sensors.end(), reading.cone.origin);
      reading.sensor = static_cast<int>(found - data.sensors.begin());
      if (found == data.sensors.end()) data.sensors.push_back(reading.cone.origin);
      data.readings.push_back(reading);
    }
  }
  if (data.readings.empty())
    return Diagnostic{"", 0, 0, "the selected rings hold no usable reading"};
  return data;
}

Window WindowAround(const SonarData& data, double margin) {
  Box2 box;
  for (const Vec2& s : data.sensors) box.extend(s);
  for (const SonarReading& r : data.readings) {
    if (r.max_reading) continue;
    // The arc's ends and its middle bound it closely enough for a margin of a metre.
    const SonarCone& c = r.cone;
    const double cos_h = std::cos(c.half_spread), sin_h = std::sin(c.half_spread);
    for (const double side : {-1.0, 0.0, 1.0}) {
      const Vec2 direction(c.axis.x() * cos_h - side * c.axis.y() * sin_h,
                           c.axis.y() * cos_h + side * c.axis.x() * sin_h);
      box.extend(c.origin + r.range * (side == 0.0 ? c.axis : direction));
    }
  }
  const Vec2 grow = Vec2::Constant(margin);
  return {.min = box.min() - grow, .max = box.max() + grow};
}

}  // namespace priormap::prf
