#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>

#include <priormap/core/check.hpp>
#include <priormap/core/rng.hpp>
#include <priormap/prf/arak.hpp>
#include <priormap/prf/prior_stats.hpp>

namespace priormap::prf {
namespace {

struct TestSegment {
  Vec2 a;
  Vec2 b;
};

// A segment of length `length` at a uniform position and direction, wholly inside the window.
TestSegment PlaceSegment(const Window& window, double length, Rng& rng) {
  for (;;) {
    const Vec2 a(rng.Uniform(window.min.x(), window.max.x()),
                 rng.Uniform(window.min.y(), window.max.y()));
    const Vec2 b = a + length * UnitVector(rng.Uniform(0.0, 2.0 * std::numbers::pi));
    if (window.ContainsInterior(b)) return {a, b};
  }
}

}  // namespace

double StandardScore(const Estimate& estimate, double expected) {
  const double difference = std::abs(estimate.mean - expected);
  if (estimate.standard_error > 0.0) return difference / estimate.standard_error;
  return difference == 0.0 ? 0.0 : std::numeric_limits<double>::infinity();
}

PriorStatsResult RunPriorStats(const PriorStatsOptions& options) {
  PRIORMAP_CHECK(options.p > 0.0 && options.window > 0.0, "p and the window must be positive");
  PRIORMAP_CHECK(options.samples >= 2 * options.batches && options.thin > 0,
                 "prior statistics need at least two records per batch and thin > 0");
  for (double d : options.distances)
    PRIORMAP_CHECK(d > 0.0 && d < 1.0, "distances are fractions of the window side in (0, 1)");
  const auto start = std::chrono::steady_clock::now();
  const double side = options.window;
  const Window window{Vec2::Zero(), Vec2::Constant(side)};

  SamplerOptions sampler_options = options.sampler;
  sampler_options.p = options.p;
  sampler_options.birth_scale *= side;
  for (double& scale : sampler_options.step_scales) scale *= side;
  sampler_options.corner_completion_jitter *= side;
  sampler_options.neighbour_birth_jitter *= side;
  sampler_options.vertex_jump_reach *= side;
  sampler_options.vertex_jump_jitter *= side;
  if (!options.guide_points.empty()) {
    std::vector<Vec2> guide_points;
    for (const Vec2& g : options.guide_points) guide_points.push_back(side * g);
    sampler_options.guide = std::make_shared<const BirthGuide>(
        std::move(guide_points), sampler_options.birth_scale, options.guide_jitter * side);
  }
  // About one expected edge per cell keeps crossing tests and local recolors cheap.
  const double expected_edges = ExpectedEdges(options.p, window);
  const int cells_per_side =
      std::clamp(static_cast<int>(std::ceil(std::sqrt(expected_edges))), 2, 64);
  // The chain, or the replicas of a ladder (the first seeded as the lone chain would be).
  const std::vector<double> temperatures =
      options.ladder.empty() ? std::vector<double>{1.0} : options.ladder;
  std::vector<std::unique_ptr<PrfSampler>> replicas;
  for (std::size_t k = 0; k < temperatures.size(); ++k)
    replicas.push_back(
        std::make_unique<PrfSampler>(Coloring(window, side / cells_per_side), sampler_options,
                                     k == 0 ? options.seed : SplitMix64(options.seed + k)));
  ReplicaLadder ladder(std::move(replicas), temperatures, SplitMix64(options.seed ^ 0x5eed));
  ladder.set_scale(options.sampler.temperature);  // a lone chain keeps its temperature
  std::uint64_t round = 0;
  const auto advance = [&](std::uint64_t steps) {
    ladder.Run(steps);
    ladder.Exchange(round++);
  };

  Rng placement = Rng::ForStream(options.seed, 1);
  std::vector<Vec2> points;
  for (int i = 0; i < options.colour_points; ++i)
    points.emplace_back(placement.Uniform(0.0, side), placement.Uniform(0.0, side));
  std::vector<std::vector<TestSegment>> segments(options.distances.size());
  for (std::size_t k = 0; k < options.distances.size(); ++k)
    for (int i = 0; i < options.segments_per_distance; ++i)
      segments[k].push_back(PlaceSegment(window, options.distances[k] * side, placement));

  for (std::uint64_t done = 0; done < options.burn_in; done += options.thin)
    advance(std::min(options.thin, options.burn_in - done));
  const std::size_t n = options.samples;
  std::vector<double> edges(n), black(n);
  std::vector<std::vector<double>> same(segments.size(), std::vector<double>(n)),
      crossings(segments.size(), std::vector<double>(n)),
      none(segments.size(), std::vector<double>(n));
  for (std::size_t i = 0; i < n; ++i) {
    advance(options.thin);
    const Coloring& coloring = ladder.cold().coloring();
    edges[i] = coloring.stats().edges;
    int black_points = 0;
    for (const Vec2& q : points) black_points += coloring.ColourAt(q) == Colour::kBlack;
    black[i] = static_cast<double>(black_points) / static_cast<double>(points.size());
    for (std::size_t k = 0; k < segments.size(); ++k) {
      double even = 0.0, total = 0.0, zero = 0.0;
      for (const TestSegment& s : segments[k]) {
        const int count = coloring.CountCrossings(s.a, s.b);
        even += count % 2 == 0;
        total += count;
        zero += count == 0;
      }
      const double m = static_cast<double>(segments[k].size());
      same[k][i] = even / m;
      crossings[k][i] = total / m;
      none[k][i] = zero / m;
    }
  }

  PriorStatsResult result;
  result.edges = BatchMeans(edges, options.batches);
  result.expected_edges = expected_edges;
  result.black_fraction = BatchMeans(black, options.batches);
  for (std::size_t k = 0; k < segments.size(); ++k) {
    DistanceStats stats;
    stats.distance = options.distances[k] * side;
    stats.same_colour = BatchMeans(same[k], options.batches);
    stats.expected_same_colour = SameColourProbability(options.p, stats.distance);
    stats.crossings = BatchMeans(crossings[k], options.batches);
    stats.expected_crossings = ExpectedCrossings(options.p, stats.distance);
    stats.no_crossing = BatchMeans(none[k], options.batches);
    stats.expected_no_crossing = std::exp(-stats.expected_crossings);
    result.by_distance.push_back(stats);
  }
  result.counters = ladder.cold().counters();
  result.swaps = ladder.swaps();
  result.steps = options.burn_in + options.thin * options.samples;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace priormap::prf
