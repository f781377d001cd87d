#pragma once
/// Samples the Arak prior with no data and compares the chain's averages with the process's
/// closed forms: the evidence that every move's Hastings ratio is right (a wrong ratio biases
/// the stationary distribution). Used by the tests and by `priormap prf prior-stats`.

#include <cstdint>
#include <vector>

#include <priormap/prf/batch_means.hpp>
#include <priormap/prf/moves.hpp>
#include <priormap/prf/replica_exchange.hpp>
#include <priormap/prf/sampler.hpp>

namespace priormap::prf {

struct PriorStatsOptions {
  double p = 1.0;
  double window = 1.0;             ///< side L of the square window [0, L]²
  std::uint64_t samples = 20000;   ///< recorded states
  std::uint64_t thin = 100;        ///< sampler steps between recorded states
  std::uint64_t burn_in = 100000;  ///< steps before the first record
  std::uint64_t seed = 1;
  std::vector<double> distances{0.05, 0.1, 0.2, 0.4};  // in units of the window side
  int segments_per_distance = 16;  ///< fixed segments of each length, placed at random
  int colour_points = 16;          ///< fixed points whose colours give P(black)
  /// Guide points of the guided triangle births, in units of the window side (none: the kind
  /// is off). Any points will do: the guide changes the proposals, never the target, which is
  /// what the closed forms check. Their pair radius is birth_scale; their jitter:
  std::vector<Vec2> guide_points;
  double guide_jitter = 0.03;  ///< in units of the window side
  std::size_t batches = 40;
  /// The temperatures of a replica-exchange ladder (1 first, increasing) whose cold replica is
  /// the chain recorded, its replicas offering swaps every `thin` steps; empty: one chain. The
  /// swaps must leave the closed forms alone.
  std::vector<double> ladder;
  /// Sampler settings; birth_scale, step_scales and the corner completion and neighbour birth
  /// jitters are multiplied by the window side.
  SamplerOptions sampler{.p = 1.0,
                         .orientation = {},
                         .free_space = 0.0,
                         .weights = {},
                         .birth_scale = 0.3,
                         .vertex_birth_widths = {0.5},
                         .guide = nullptr,
                         .step_scales = {0.01, 0.05, 0.2},
                         .temperature = 1.0,
                         .check_invariants = false};
};

struct DistanceStats {
  double distance = 0.0;  ///< absolute length
  Estimate same_colour;
  double expected_same_colour = 0.0;
  Estimate crossings;
  double expected_crossings = 0.0;
  Estimate no_crossing;  ///< P(no crossing) = e^{−2pd} for Poisson crossings
  double expected_no_crossing = 0.0;
};

struct PriorStatsResult {
  Estimate edges;
  double expected_edges = 0.0;
  Estimate black_fraction;
  std::vector<DistanceStats> by_distance;
  MoveCounters counters{};
  std::vector<SwapCounter> swaps;  ///< per adjacent pair of the ladder's rungs
  std::uint64_t steps = 0;         ///< per replica
  double seconds = 0.0;
};

[[nodiscard]] PriorStatsResult RunPriorStats(const PriorStatsOptions& options);

/// |estimate − expected| in standard errors (infinite when the error is zero and they differ).
[[nodiscard]] double StandardScore(const Estimate& estimate, double expected);

}  // namespace priormap::prf
