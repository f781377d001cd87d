#pragma once
// Cones and segments for the tests of the sonar cone sweep (sonar_visibility.hpp).
#include <cstdint>
#include <vector>

#include <priormap/prf/sonar_visibility.hpp>

namespace priormap::prf {

// The window the tests' segments lie in.
inline const Window kConeTestWindow{Vec2(-10, -10), Vec2(10, 10)};

inline SonarCone Cone(Vec2 origin, double axis_angle, double half_spread, double max_range) {
  return {.origin = origin,
          .axis = UnitVector(axis_angle),
          .half_spread = half_spread,
          .max_range = max_range};
}

// Segments tagged with their index, as the sweep takes them.
inline std::vector<TaggedSegment> Tagged(const std::vector<Segment>& segments) {
  std::vector<TaggedSegment> tagged;
  for (std::size_t i = 0; i < segments.size(); ++i)
    tagged.push_back({segments[i], static_cast<std::int32_t>(i)});
  return tagged;
}

// What `cone` sees of `segments` in kConeTestWindow.
inline SonarView ViewOf(const SonarCone& cone, const std::vector<Segment>& segments) {
  ConeSweep sweep;
  SonarView view;
  sweep.Compute(cone, Tagged(segments), kConeTestWindow, &view);
  return view;
}

}  // namespace priormap::prf
