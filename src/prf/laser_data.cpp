#include <algorithm>

#include <fmt/format.h>

#include <priormap/prf/laser_data.hpp>

namespace priormap::prf {

// A selection is options, not a file: its diagnostics have no position.
Result<LaserData> SelectBeams(const Log& log, const LaserSelection& selection) {
  const std::size_t end = std::min(selection.end_scan.value_or(log.scans.size()), log.scans.size());
  if (selection.first_scan >= end)
    return Diagnostic{"", 0, 0,
                      fmt::format("the scan range {}:{} selects no scan (the log has {})",
                                  selection.first_scan, end, log.scans.size())};
  if (selection.beam_step == 0) return Diagnostic{"", 0, 0, "the beam step must be at least 1"};
  if (!(selection.max_range > 0.0)) return Diagnostic{"", 0, 0, "the max range must be positive"};
  LaserData data;
  // One R for all beams, so that every max reading means the same "nothing within R".
  data.max_range = selection.max_range;
  for (std::size_t k = selection.first_scan; k < end; ++k)
    data.max_range = std::min(data.max_range, log.scans[k].max_range);
  for (std::size_t k = selection.first_scan; k < end; ++k) {
    const Scan& scan = log.scans[k];
    if (!scan.pose.IsFinite()) continue;
    const int sensor = static_cast<int>(data.sensors.size());
    bool used = false;
    for (std::size_t i = 0; i < scan.size(); i += selection.beam_step) {
      const BeamStatus status = scan.status[i];
      if (status == BeamStatus::kInvalid) continue;
      LaserBeam beam;
      beam.origin = scan.pose.translation();
      beam.direction = UnitVector(scan.pose.theta() + scan.angles[i]);
      beam.max_reading = status == BeamStatus::kMaxRange || scan.ranges[i] >= data.max_range;
      beam.range = beam.max_reading ? data.max_range : scan.ranges[i];
      beam.sensor = sensor;
      data.beams.push_back(beam);
      used = true;
    }
    if (used) data.sensors.push_back(scan.pose.translation());
  }
  if (data.beams.empty()) return Diagnostic{"", 0, 0, "the selected scans hold no usable reading"};
  return data;
}

Window WindowAround(const LaserData& data, double margin) {
  Box2 box;
  for (const Vec2& s : data.sensors) box.extend(s);
  for (const LaserBeam& beam : data.beams)
    if (!beam.max_reading) box.extend(beam.origin + beam.range * beam.direction);
  const Vec2 grow = Vec2::Constant(margin);
  return {.min = box.min() - grow, .max = box.max() + grow};
}

}  // namespace priormap::prf
