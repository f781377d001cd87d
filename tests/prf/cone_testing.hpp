#pragma once
// Cones and segments for the tests of the sonar cone sweep (sonar_visibility.hpp).
#include <cstdint>
#include <numbers>
#include <random>
#include <vector>

#include <priormap/prf/sampler.hpp>
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

// The window of DenseArakSample.
inline const Window kArakSampleWindow{Vec2::Zero(), Vec2(6, 6)};

// A dense sample of the Arak process (p = 3 in a 6 m square): many edges, vertices and partial
// occlusions for a cone to see.
inline Coloring DenseArakSample(std::uint64_t seed) {
  SamplerOptions options;
  options.p = 3.0;
  PrfSampler sampler(Coloring(kArakSampleWindow, 0.5), options, seed);
  sampler.Run(60000);
  return sampler.coloring();
}

// A random cone in kArakSampleWindow: apex at least 0.5 m inside, any axis, half-angle in
// [min_half, min_half + half_span), R in [0.5, 3.5).
inline SonarCone RandomCone(std::mt19937_64& random, double min_half, double half_span) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  return Cone(Vec2(0.5 + 5.0 * unit(random), 0.5 + 5.0 * unit(random)),
              2.0 * std::numbers::pi * unit(random), min_half + half_span * unit(random),
              0.5 + 3.0 * unit(random));
}

}  // namespace priormap::prf
