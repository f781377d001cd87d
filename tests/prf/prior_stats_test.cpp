// The proof of detailed balance: with no data, chains of the sampler must reproduce the Arak
// process's closed forms (Paskin & Thrun, Sec. 1.3.2) in the unit square: E|E| = 4p + 4πp²,
// P(black) = ½, P(same colour at distance d) = ½(1 + e^{−4pd}), and crossings of a fixed segment
// of length d Poisson with mean 2pd (mean and P(none) = e^{−2pd}). Each within 4 batch-means
// standard errors. Besides the whole move set, subsets that are still irreducible run each move
// kind without the others, so that a wrong ratio in one cannot hide behind another.
//
// PRIORMAP_PRF_CHAIN_SCALE multiplies the chains' lengths: 1 in the default suite, more in the
// `slow` label (prf_slow_tests).
#include <ostream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <priormap/core/rng.hpp>
#include <priormap/prf/prior_stats.hpp>

#ifndef PRIORMAP_PRF_CHAIN_SCALE
#define PRIORMAP_PRF_CHAIN_SCALE 1
#endif

namespace priormap::prf {
namespace {

constexpr double kMaxStandardErrors = 4.0;

void ExpectMatchesArak(const PriorStatsResult& r, const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_LE(StandardScore(r.edges, r.expected_edges), kMaxStandardErrors)
      << "mean edges " << r.edges.mean << " ± " << r.edges.standard_error << ", expected "
      << r.expected_edges;
  EXPECT_LE(StandardScore(r.black_fraction, 0.5), kMaxStandardErrors)
      << "P(black) " << r.black_fraction.mean << " ± " << r.black_fraction.standard_error;
  for (const DistanceStats& d : r.by_distance) {
    EXPECT_LE(StandardScore(d.same_colour, d.expected_same_colour), kMaxStandardErrors)
        << "d = " << d.distance << ": same colour " << d.same_colour.mean << " ± "
        << d.same_colour.standard_error << ", expected " << d.expected_same_colour;
    EXPECT_LE(StandardScore(d.crossings, d.expected_crossings), kMaxStandardErrors)
        << "d = " << d.distance << ": crossings " << d.crossings.mean << " ± "
        << d.crossings.standard_error << ", expected " << d.expected_crossings;
    EXPECT_LE(StandardScore(d.no_crossing, d.expected_no_crossing), kMaxStandardErrors)
        << "d = " << d.distance << ": P(no crossing) " << d.no_crossing.mean << " ± "
        << d.no_crossing.standard_error << ", expected " << d.expected_no_crossing;
    // The errors must be small enough for the comparison to mean something.
    EXPECT_LT(d.same_colour.standard_error, 0.02);
  }
  EXPECT_LT(r.edges.standard_error, 0.05 * r.expected_edges);
}

// Guide points for the guided triangle births: points along three walls, as range data would
// give, and scattered ones that spread guided births over most of the window, so that they make
// a good part of the structure and a wrong density shows in the statistics. The guide changes
// only the proposals, so the closed forms hold whatever it holds.
std::vector<Vec2> GuidePoints() {
  std::vector<Vec2> points;
  for (int i = 0; i <= 40; ++i) {
    const double t = i / 40.0;
    points.emplace_back(0.1 + 0.8 * t, 0.3);
    points.emplace_back(0.7, 0.1 + 0.6 * t);
    points.emplace_back(0.2 + 0.3 * t, 0.6 + 0.3 * t);
  }
  Rng rng(3);
  for (int i = 0; i < 300; ++i) points.emplace_back(rng.Uniform(), rng.Uniform());
  return points;
}

PriorStatsOptions Chain(double p, std::uint64_t seed) {
  PriorStatsOptions options;
  options.guide_points = GuidePoints();
  options.p = p;
  options.seed = seed;
  options.samples = 20000 * PRIORMAP_PRF_CHAIN_SCALE;
  options.thin = p > 3.0 ? 200 : 100;
  options.burn_in = 200000;
  // In units of the window side; they matter only where vertex jumps are on.
  options.sampler.vertex_jump_reach = 0.3;
  options.sampler.vertex_jump_jitter = 0.1;
  return options;
}

class WholeMoveSet : public ::testing::TestWithParam<double> {};

TEST_P(WholeMoveSet, MatchesTheArakProcess) {
  const double p = GetParam();
  PriorStatsOptions options = Chain(p, 12);
  // Off by default; the whole set has them.
  options.sampler.weights[MoveKind::kEdgeShift] = 2.0;
  options.sampler.weights[MoveKind::kVertexJump] = 1.0;
  options.sampler.weights[MoveKind::kVertexPair] = 1.0;
  const PriorStatsResult r = RunPriorStats(options);
  ExpectMatchesArak(r, "p = " + std::to_string(p));
  for (const MoveCounter& c : r.counters) EXPECT_GT(c.accepted, 0u);
}

std::string ScaleName(const ::testing::TestParamInfo<double>& param) {
  return "p_times_10_is_" + std::to_string(static_cast<int>(param.param * 10));
}

INSTANTIATE_TEST_SUITE_P(ScaleParameter, WholeMoveSet, ::testing::Values(0.5, 1.0, 2.0, 4.0),
                         ScaleName);

struct Subset {
  std::string name;
  std::vector<MoveKind> kinds;
  MoveKind emphasised;  // the kind under test, given three times the weight
  std::vector<double> vertex_birth_widths{0.5};
  double corner_completion = 0.0;
  double corner_completion_jitter = 0.05;  // in units of the window side
  double neighbour_birth = 0.0;
  double neighbour_birth_jitter = 0.1;  // in units of the window side
};

// The base set: births and deaths of every structure and boundary moves (which carry path ends
// from side to side). Each further kind is run alone with the base; each base kind is dropped
// where the rest still reaches every coloring.
const std::vector<MoveKind> kBase{MoveKind::kTriangle, MoveKind::kBoundaryTriangle,
                                  MoveKind::kCorner, MoveKind::kVertex, MoveKind::kBoundaryMove};

std::vector<Subset> Subsets() {
  std::vector<Subset> subsets{{"base", kBase, MoveKind::kVertex}};
  for (MoveKind extra :
       {MoveKind::kInteriorMove, MoveKind::kSlide, MoveKind::kRecolor, MoveKind::kLocalRecolor}) {
    std::string name = "base_and_";
    name += MoveKindName(extra);
    Subset s{name, kBase, extra};
    s.kinds.push_back(extra);
    subsets.push_back(s);
  }
  // Edge shifts, off in the default weights, against the base.
  subsets.push_back({"base_and_edge_shift",
                     {MoveKind::kTriangle, MoveKind::kBoundaryTriangle, MoveKind::kCorner,
                      MoveKind::kVertex, MoveKind::kBoundaryMove, MoveKind::kEdgeShift},
                     MoveKind::kEdgeShift});
  // Vertex jumps against the base: the jump back must weigh the neighbours' neighbours' squares
  // and the far square by the same mixture.
  subsets.push_back({"base_and_vertex_jump",
                     {MoveKind::kTriangle, MoveKind::kBoundaryTriangle, MoveKind::kCorner,
                      MoveKind::kVertex, MoveKind::kBoundaryMove, MoveKind::kVertexJump},
                     MoveKind::kVertexJump});
  // Vertex pairs against the base, narrow and of mixed widths: a pair's density must sum its two
  // reads, and the second vertex's rectangle must follow the first.
  subsets.push_back({"base_and_vertex_pair",
                     {MoveKind::kTriangle, MoveKind::kBoundaryTriangle, MoveKind::kCorner,
                      MoveKind::kVertex, MoveKind::kBoundaryMove, MoveKind::kVertexPair},
                     MoveKind::kVertexPair});
  subsets.push_back({"base_and_mixed_vertex_pair",
                     {MoveKind::kTriangle, MoveKind::kBoundaryTriangle, MoveKind::kCorner,
                      MoveKind::kVertex, MoveKind::kBoundaryMove, MoveKind::kVertexPair},
                     MoveKind::kVertexPair,
                     {0.25, 3.0}});
  // Vertex births four times as wide (--vertex-birth-widths 2), whose deaths straighten tall
  // bends, and a mixture of a narrow and a wide width: the density and the death's refusal
  // outside the widest rectangle must still pair up.
  subsets.push_back({"base_with_wide_vertex_births", kBase, MoveKind::kVertex, {2.0}});
  subsets.push_back({"base_with_mixed_vertex_births", kBase, MoveKind::kVertex, {0.25, 3.0}});
  // Half the vertex births near the corner ahead of their edge: a death must weigh the corner
  // it removes by the same mixture.
  subsets.push_back({"base_with_corner_completion", kBase, MoveKind::kVertex, {0.5}, 0.5, 0.4});
  // Half the vertex births next to a vertex beyond their edge's ends: a death must weigh a
  // vertex next to its neighbour's neighbour by the same mixture.
  subsets.push_back(
      {"base_with_neighbour_births", kBase, MoveKind::kVertex, {0.5}, 0.0, 0.05, 0.5, 0.2});
  // Closed polygons without triangle births: a recolor of two edges of one path closes a loop.
  subsets.push_back({"without_triangle",
                     {MoveKind::kBoundaryTriangle, MoveKind::kCorner, MoveKind::kVertex,
                      MoveKind::kBoundaryMove, MoveKind::kRecolor},
                     MoveKind::kBoundaryTriangle});
  // Bends on one side from a corner edge and a vertex birth, carried over by boundary moves.
  subsets.push_back(
      {"without_boundary_triangle",
       {MoveKind::kTriangle, MoveKind::kCorner, MoveKind::kVertex, MoveKind::kBoundaryMove},
       MoveKind::kCorner});
  // Guided triangles in place of the blind ones (closed polygons also come from recolors, as
  // without_triangle shows), so that their births and deaths carry the interior structure.
  subsets.push_back({"guided_instead_of_triangle",
                     {MoveKind::kGuidedTriangle, MoveKind::kBoundaryTriangle, MoveKind::kCorner,
                      MoveKind::kVertex, MoveKind::kBoundaryMove, MoveKind::kRecolor},
                     MoveKind::kGuidedTriangle});
  // Straight boundary-to-boundary edges from a vertex death on a boundary triangle.
  subsets.push_back({"without_corner",
                     {MoveKind::kTriangle, MoveKind::kBoundaryTriangle, MoveKind::kVertex,
                      MoveKind::kBoundaryMove},
                     MoveKind::kTriangle});
  return subsets;
}

// gtest names the parameter in test listings by this instead of its bytes.
void PrintTo(const Subset& subset, std::ostream* out) {
  *out << subset.name;
}

class MoveSubset : public ::testing::TestWithParam<Subset> {};

TEST_P(MoveSubset, MatchesTheArakProcess) {
  const Subset& subset = GetParam();
  PriorStatsOptions options = Chain(1.0, 23);
  options.sampler.weights.weight.fill(0.0);
  for (MoveKind kind : subset.kinds) options.sampler.weights[kind] = 1.0;
  options.sampler.weights[subset.emphasised] = 3.0;
  options.sampler.vertex_birth_widths = subset.vertex_birth_widths;
  options.sampler.corner_completion = subset.corner_completion;
  options.sampler.corner_completion_jitter = subset.corner_completion_jitter;
  options.sampler.neighbour_birth = subset.neighbour_birth;
  options.sampler.neighbour_birth_jitter = subset.neighbour_birth_jitter;
  const PriorStatsResult r = RunPriorStats(options);
  ExpectMatchesArak(r, subset.name);
}

std::string SubsetName(const ::testing::TestParamInfo<Subset>& param) {
  return param.param.name;
}

INSTANTIATE_TEST_SUITE_P(EachMoveKind, MoveSubset, ::testing::ValuesIn(Subsets()), SubsetName);

// Replica exchange leaves the cold replica's law alone: it still matches the closed forms, while
// its hottest replica alone, run as one chain, is far from them (its energy 2pL is divided by
// the temperature, the reference measure is not), so swaps that ignored the energies, or a
// tempered density that counted λ, would pull the cold replica off.
TEST(ReplicaExchange, TheColdReplicaMatchesTheArakProcess) {
  PriorStatsOptions options = Chain(1.0, 31);
  options.ladder = GeometricLadder(3, 2.25);
  const PriorStatsResult r = RunPriorStats(options);
  ExpectMatchesArak(r, "ladder 1, 1.5, 2.25");
  ASSERT_EQ(r.swaps.size(), 2u);
  for (const SwapCounter& swaps : r.swaps) {
    EXPECT_GT(swaps.rate(), 0.05) << "swaps too rare for the test to mean something";
    EXPECT_LT(swaps.rate(), 0.95);
  }

  PriorStatsOptions hottest = Chain(1.0, 31);
  hottest.sampler.temperature = 2.25;
  const PriorStatsResult h = RunPriorStats(hottest);
  EXPECT_GT(StandardScore(h.edges, h.expected_edges), 10.0)
      << "mean edges at T = 2.25: " << h.edges.mean << ", Arak's " << h.expected_edges;
}

}  // namespace
}  // namespace priormap::prf
