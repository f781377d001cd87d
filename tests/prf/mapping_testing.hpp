#pragma once
// A small laser log and a run in checkpointed sessions, for the tests of mapping runs.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <utility>
#include <variant>

#include <priormap/core/range_sensor.hpp>
#include <priormap/core/scene.hpp>
#include <priormap/core/simulate.hpp>
#include <priormap/prf/mapping.hpp>

namespace priormap::prf {

// A small simulated localized log's beams (every 8th beam of an lms200 along the l-room).
inline std::shared_ptr<const LaserData> RoomData() {
  const Scene scene = *BuiltinScene("l-room");
  const RangeSensor sensor = *RangeSensor::Preset("lms200");
  const Log log = SimulateLog(scene, sensor, TrajectoryFromWaypoints(scene.waypoints, 0.5, 1.0), 3);
  auto data = SelectBeams(
      log, {.first_scan = 0, .end_scan = std::nullopt, .beam_step = 8, .max_range = 8.0});
  return std::make_shared<const LaserData>(std::move(data).value());
}

// The sessions of RunInSessions, checkpointed in `directory`: each stops after `steps` steps
// per chain.
inline MappingSession StoppingSession(const std::filesystem::path& directory, std::uint64_t steps) {
  return {.checkpoint_directory = directory,
          .checkpoint_every_s = 1e9,
          .resume = false,
          .stop_after_steps = steps,
          .stop = nullptr};
}

// Runs `options` in sessions of `steps` steps per chain, each resuming from the last one's
// checkpoints in `directory`, until the run completes (at most 20 sessions): the last
// session's result and the number of sessions.
inline std::pair<MappingResult, int> RunInSessions(const MappingData& data,
                                                   const MappingOptions& options,
                                                   std::uint64_t steps,
                                                   const std::filesystem::path& directory) {
  MappingSession session = StoppingSession(directory, steps);
  int sessions = 0;
  MappingResult part;
  do {
    part = RunMapping(data, options, {}, session);
    session.resume = true;
    ++sessions;
  } while (!part.complete && sessions < 20);
  return {std::move(part), sessions};
}

}  // namespace priormap::prf
