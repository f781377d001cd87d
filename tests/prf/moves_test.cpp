// The proposals' Hastings ratios, exactly: a move and the move that undoes it must have
// opposite log proposal ratios, and the local recolor's ratio must count grid neighbourhoods
// as brute force does. (The chain tests in prior_stats_test.cpp check the ratios' derivation
// against the Arak process's closed forms.)
#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <priormap/core/rng.hpp>
#include <priormap/prf/sampler.hpp>

#include "prf/brute_force.hpp"

namespace priormap::prf {
namespace {

const Window kUnit{Vec2::Zero(), Vec2::Ones()};

// Guide points along two walls of the unit square's interior and a few stray ones.
std::shared_ptr<const BirthGuide> Guide(double pair_radius) {
  std::vector<Vec2> points;
  for (int i = 0; i <= 30; ++i) {
    points.emplace_back(0.1 + 0.8 * i / 30.0, 0.4);
    points.emplace_back(0.6, 0.05 + 0.9 * i / 30.0);
  }
  Rng rng(12);
  for (int i = 0; i < 10; ++i) points.emplace_back(rng.Uniform(), rng.Uniform());
  return std::make_shared<const BirthGuide>(points, pair_radius, 0.03);
}

SamplerOptions Options(double p) {
  SamplerOptions options;
  options.p = p;
  options.birth_scale = 0.3;
  options.step_scales = {0.01, 0.05, 0.2};
  options.guide = Guide(options.birth_scale);
  options.weights[MoveKind::kEdgeShift] = 1.0;  // off by default, on here so that it is tested
  return options;
}

// A state of the prior chain after `steps` steps.
PrfSampler Warmed(double p, std::uint64_t seed, std::uint64_t steps) {
  PrfSampler sampler(Coloring(kUnit, 0.125), Options(p), seed);
  sampler.Run(steps);
  return sampler;
}

using Segments = std::vector<std::pair<Vec2, Vec2>>;

Segments Canonical(Segments segments) {
  for (auto& [a, b] : segments)
    if (std::lexicographical_compare(b.data(), b.data() + 2, a.data(), a.data() + 2))
      std::swap(a, b);
  std::sort(segments.begin(), segments.end(), [](const auto& x, const auto& y) {
    return std::lexicographical_compare(x.first.data(), x.first.data() + 2, y.first.data(),
                                        y.first.data() + 2) ||
           (x.first == y.first &&
            std::lexicographical_compare(x.second.data(), x.second.data() + 2, y.second.data(),
                                         y.second.data() + 2));
  });
  return segments;
}

Segments Removed(const Coloring& c, const Edit& edit) {
  Segments out;
  for (EdgeId e : edit.removed_edges) out.emplace_back(c.EdgeSegment(e).a, c.EdgeSegment(e).b);
  return Canonical(out);
}

Segments Added(const Coloring& c, const Edit& edit) {
  const auto pos = [&](VertexRef r) {
    return r.is_new() ? edit.new_vertices[static_cast<std::size_t>(r.new_index())].position
                      : c.vertex(r.id()).position;
  };
  Segments out;
  for (const auto& [a, b] : edit.added_edges) out.emplace_back(pos(a), pos(b));
  return Canonical(out);
}

// Proposes `forward` until one is valid, applies it, then proposes `reverse` from the new
// state until it undoes the first; the two log proposal ratios must cancel. Returns false when
// the state offers no valid forward move. `corner_completion` and `neighbour_birth` set the
// vertex births' shares of corner completions and neighbour births.
bool ExpectReversible(MoveType forward, MoveType reverse, double p, std::uint64_t seed,
                      double corner_completion = 0.0, double neighbour_birth = 0.0) {
  SamplerOptions options = Options(p);
  options.corner_completion = corner_completion;
  options.neighbour_birth = neighbour_birth;
  PrfSampler sampler(Warmed(p, seed, 3000).coloring(), options, seed);
  Edit edit;
  EditEffect effect;
  double log_q = 0.0;
  int tries = 0;
  while (!(sampler.Propose(forward, &edit, &log_q) && sampler.coloring().Evaluate(edit, &effect)))
    if (++tries == 100000) return false;
  const Segments removed = Removed(sampler.coloring(), edit);
  const Segments added = Added(sampler.coloring(), edit);
  Coloring after = sampler.coloring();
  after.Apply(edit, effect);
  PrfSampler undo(after, sampler.options(), seed + 1000);
  Edit back;
  double log_q_back = 0.0;
  for (int attempt = 0; attempt < 2000000; ++attempt) {
    if (!undo.Propose(reverse, &back, &log_q_back)) continue;
    if (Removed(undo.coloring(), back) != added || Added(undo.coloring(), back) != removed)
      continue;
    EXPECT_NEAR(log_q + log_q_back, 0.0, 1e-9)
        << MoveTypeName(forward) << " then " << MoveTypeName(reverse) << ", seed " << seed;
    return true;
  }
  ADD_FAILURE() << "no " << MoveTypeName(reverse) << " undid the " << MoveTypeName(forward)
                << ", seed " << seed;
  return true;
}

TEST(MoveRatios, BirthsAndDeathsCancel) {
  for (std::uint64_t seed = 1; seed <= 8; ++seed) {
    EXPECT_TRUE(ExpectReversible(MoveType::kTriangleBirth, MoveType::kTriangleDeath, 1.0, seed));
    EXPECT_TRUE(ExpectReversible(MoveType::kBoundaryTriangleBirth, MoveType::kBoundaryTriangleDeath,
                                 1.0, seed));
    EXPECT_TRUE(ExpectReversible(MoveType::kCornerBirth, MoveType::kCornerDeath, 1.0, seed));
    EXPECT_TRUE(ExpectReversible(MoveType::kVertexBirth, MoveType::kVertexDeath, 2.0, seed));
    EXPECT_TRUE(ExpectReversible(MoveType::kVertexBirth, MoveType::kVertexDeath, 2.0, seed, 0.9));
    EXPECT_TRUE(
        ExpectReversible(MoveType::kVertexBirth, MoveType::kVertexDeath, 2.0, seed, 0.05, 0.9));
    EXPECT_TRUE(ExpectReversible(MoveType::kGuidedTriangleBirth, MoveType::kGuidedTriangleDeath,
                                 1.0, seed));
    // The undoing death may take the pair from either vertex: its density must sum both reads.
    EXPECT_TRUE(
        ExpectReversible(MoveType::kVertexPairBirth, MoveType::kVertexPairDeath, 2.0, seed));
  }
}

TEST(MoveRatios, RecolorsUndoThemselves) {
  int tested = 0;
  for (std::uint64_t seed = 1; seed <= 8; ++seed) {
    tested += ExpectReversible(MoveType::kRecolor, MoveType::kRecolor, 1.0, seed);
    tested += ExpectReversible(MoveType::kLocalRecolor, MoveType::kLocalRecolor, 2.0, seed);
  }
  EXPECT_GE(tested, 12);  // a sparse state may offer no valid recolor
}

// Proposes `type` `tries` times from the sampler's state and calls check(edit) on each proposal
// the state offers, whose log proposal ratio must be 0 (a move that is its own reverse); returns
// how many were checked.
template <typename Check>
int ForEachSymmetricProposal(PrfSampler& sampler, MoveType type, int tries, Check&& check) {
  int checked = 0;
  for (int i = 0; i < tries; ++i) {
    Edit edit;
    double log_q = 1.0;
    if (!sampler.Propose(type, &edit, &log_q)) continue;
    EXPECT_EQ(log_q, 0.0) << MoveTypeName(type);
    check(edit);
    ++checked;
  }
  return checked;
}

// Both ends move by one vector: the shifted edge keeps its direction and length, its neighbours'
// far ends stay, and a free triangle is never shifted. (Its ratio, 1, is checked by the closed
// forms in prior_stats_test.cpp and prior_potentials_test.cpp: a continuous move has no discrete
// reverse for ExpectReversible to find.)
TEST(MoveRatios, EdgeShiftMovesBothEndsAlike) {
  PrfSampler sampler = Warmed(2.0, 5, 4000);
  const Coloring& c = sampler.coloring();
  const auto check = [&](const Edit& edit) {
    ASSERT_EQ(edit.removed_vertices.size(), 2u);
    ASSERT_EQ(edit.new_vertices.size(), 2u);
    ASSERT_EQ(edit.added_edges.size(), 3u);
    const Vec2 a = c.vertex(edit.removed_vertices[0]).position;
    const Vec2 b = c.vertex(edit.removed_vertices[1]).position;
    const Vec2 shift = edit.new_vertices[0].position - a;
    EXPECT_LT((edit.new_vertices[1].position - b - shift).norm(), 1e-12);
    const VertexId p = edit.added_edges[0][0].id();
    const VertexId q = edit.added_edges[2][1].id();
    EXPECT_NE(p, q);
    // p, a, b, q is a path of the coloring.
    EXPECT_EQ(Removed(c, edit),
              Canonical({{c.vertex(p).position, a}, {a, b}, {b, c.vertex(q).position}}));
  };
  EXPECT_GT(ForEachSymmetricProposal(sampler, MoveType::kEdgeShift, 2000, check), 1000);
}

// P(propose the pair) = (1/|E|)(1/|N(e1)| + 1/|N(e2)|) with N(e) the other edges sharing a
// grid cell with e, before the move for the forward and after it for the reverse.
TEST(MoveRatios, LocalRecolorCountsNeighbourhoodsAsBruteForce) {
  int checked = 0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    PrfSampler sampler = Warmed(3.0, seed, 5000);
    const Coloring& before = sampler.coloring();
    for (int i = 0; i < 200; ++i) {
      Edit edit;
      EditEffect effect;
      double log_q = 0.0;
      if (!sampler.Propose(MoveType::kLocalRecolor, &edit, &log_q)) continue;
      if (!before.Evaluate(edit, &effect)) continue;
      const Segment e1 = before.EdgeSegment(edit.removed_edges[0]);
      const Segment e2 = before.EdgeSegment(edit.removed_edges[1]);
      const double forward = 1.0 / CellNeighboursByBruteForce(before, e1.a, e1.b, {}) +
                             1.0 / CellNeighboursByBruteForce(before, e2.a, e2.b, {});
      Coloring after = before;
      after.Apply(edit, effect);
      const Segments added = Added(before, edit);
      const double reverse =
          1.0 / CellNeighboursByBruteForce(after, added[0].first, added[0].second, {}) +
          1.0 / CellNeighboursByBruteForce(after, added[1].first, added[1].second, {});
      EXPECT_NEAR(log_q, std::log(reverse / forward), 1e-12);
      ++checked;
    }
  }
  EXPECT_GT(checked, 100);
}

// The slide keeps the direction of the edge it slides along, and its interval [−½, 1] of
// (v' − v)/(v − w) maps onto the reverse's: lengths within [½, 2] of each other.
TEST(MoveRatios, SlideKeepsTheEdgeDirection) {
  PrfSampler sampler = Warmed(2.0, 3, 4000);
  const Coloring& c = sampler.coloring();
  const int checked =
      ForEachSymmetricProposal(sampler, MoveType::kSlide, 500, [&](const Edit& edit) {
        const VertexId v = edit.removed_vertices[0];
        const Vec2 moved = edit.new_vertices[0].position;
        const VertexId w = edit.added_edges[1][1].id();  // (new, w): the edge that keeps direction
        const Vec2 old_vector = c.vertex(v).position - c.vertex(w).position;
        const Vec2 new_vector = moved - c.vertex(w).position;
        EXPECT_NEAR(Cross(old_vector, new_vector), 0.0, 1e-12);
        EXPECT_GT(old_vector.dot(new_vector), 0.0);
        const double ratio = new_vector.norm() / old_vector.norm();
        EXPECT_GE(ratio, 0.5 - 1e-12);
        EXPECT_LE(ratio, 2.0 + 1e-12);
      });
  EXPECT_GT(checked, 400);
}

TEST(MoveCounters, AddUpOverAChain) {
  SamplerOptions options = Options(1.0);
  // Off by default, on here so that they are counted.
  options.weights[MoveKind::kVertexJump] = 1.0;
  options.weights[MoveKind::kVertexPair] = 1.0;
  options.vertex_jump_reach = 0.3;
  PrfSampler sampler(Coloring(kUnit, 0.125), options, 9);
  sampler.Run(20000);
  EXPECT_EQ(Total(sampler.counters()).proposed, 20000u);
  for (int t = 0; t < kNumMoveTypes; ++t)
    EXPECT_GT(sampler.counters()[static_cast<std::size_t>(t)].accepted, 0u)
        << MoveTypeName(static_cast<MoveType>(t));
}

TEST(MoveCounters, SwitchedOffKindsAreNeverProposed) {
  SamplerOptions options = Options(1.0);
  options.weights = MoveWeights{};
  options.weights[MoveKind::kRecolor] = 0.0;
  options.weights[MoveKind::kSlide] = 0.0;
  PrfSampler sampler(Coloring(kUnit, 0.125), options, 2);
  sampler.Run(5000);
  EXPECT_EQ(sampler.counters()[static_cast<std::size_t>(MoveType::kRecolor)].proposed, 0u);
  EXPECT_EQ(sampler.counters()[static_cast<std::size_t>(MoveType::kSlide)].proposed, 0u);
  EXPECT_GT(sampler.counters()[static_cast<std::size_t>(MoveType::kLocalRecolor)].proposed, 0u);
}

TEST(MoveKinds, NamesRoundTrip) {
  for (int k = 0; k < kNumMoveKinds; ++k) {
    const auto kind = static_cast<MoveKind>(k);
    EXPECT_EQ(ParseMoveKind(MoveKindName(kind)), kind);
  }
  EXPECT_EQ(ParseMoveKind("teleport"), std::nullopt);
}

}  // namespace
}  // namespace priormap::prf

namespace priormap::prf {
namespace {

// The births' proposal densities q against the base measure μ, checked directly by the
// importance-sampling identity E_q[g / q] = ∫ g dμ over q's support (μ: Lebesgue on positions,
// divided by the orderings of exchangeable new vertices). A density that is wrong the same way
// in a birth and its death passes the reversal test above; this one catches it.
class BirthDensity : public ::testing::Test {
 protected:
  static constexpr int kDraws = 200000;
  static constexpr double r = 0.3;
  SamplerOptions options_ = Options(1.0);
};

TEST_F(BirthDensity, TriangleIntegratesToTheMeasureOfItsSupport) {
  PrfSampler sampler(Coloring(kUnit, 0.125), options_, 5);  // empty: n' = 3 and log q' = log 1
  const auto chebyshev = [](const Vec2& a, const Vec2& b) { return (a - b).cwiseAbs().maxCoeff(); };
  double sum = 0.0;
  for (int i = 0; i < kDraws; ++i) {
    Edit edit;
    double log_q = 0.0;
    ASSERT_TRUE(sampler.Propose(MoveType::kTriangleBirth, &edit, &log_q));
    bool inside = true;
    for (const NewVertex& v : edit.new_vertices)
      inside = inside && kUnit.ContainsInterior(v.position);
    if (inside) sum += std::exp(log_q);  // 1 / q, as log q_reverse = log(3/3) = 0
  }
  // ∫ 1{all in W} dμ = (1/3!) ∫_{W³} 1{some vertex has the other two within r}: by plain Monte
  // Carlo over uniform triples.
  Rng rng(8);
  int covered = 0;
  for (int i = 0; i < kDraws; ++i) {
    const Vec2 a(rng.Uniform(), rng.Uniform()), b(rng.Uniform(), rng.Uniform()),
        c(rng.Uniform(), rng.Uniform());
    covered += (chebyshev(a, b) <= r && chebyshev(a, c) <= r) ||
               (chebyshev(b, a) <= r && chebyshev(b, c) <= r) ||
               (chebyshev(c, a) <= r && chebyshev(c, b) <= r);
  }
  const double expected = static_cast<double>(covered) / kDraws / 6.0;
  EXPECT_NEAR(sum / kDraws, expected, 0.03 * expected);
}

TEST_F(BirthDensity, GuidedTriangleIntegratesToTheMeasureOfItsSupport) {
  PrfSampler sampler(Coloring(kUnit, 0.125), options_, 9);  // empty: n' = 3 and log q' = log 1
  const BirthGuide& guide = *options_.guide;
  double sum = 0.0;
  for (int i = 0; i < kDraws; ++i) {
    Edit edit;
    double log_q = 0.0;
    ASSERT_TRUE(sampler.Propose(MoveType::kGuidedTriangleBirth, &edit, &log_q));
    bool inside = true;
    for (const NewVertex& v : edit.new_vertices)
      inside = inside && kUnit.ContainsInterior(v.position);
    if (inside) sum += std::exp(log_q);  // 1 / q
  }
  // ∫ 1{all in W} dμ over q's support = (1/3!) ∫_{W³} 1{q > 0}: by plain Monte Carlo over
  // uniform triples, with the support decided by the density under test (its values are what
  // the draws above check).
  Rng rng(10);
  int covered = 0;
  constexpr int kUniformDraws = 2000000;
  for (int i = 0; i < kUniformDraws; ++i) {
    const Vec2 a(rng.Uniform(), rng.Uniform()), b(rng.Uniform(), rng.Uniform()),
        c(rng.Uniform(), rng.Uniform());
    covered += guide.Density(a, b, c) > 0.0;
  }
  const double expected = static_cast<double>(covered) / kUniformDraws / 6.0;
  EXPECT_NEAR(sum / kDraws, expected, 0.03 * expected);
}

TEST_F(BirthDensity, BoundaryTriangleIntegratesToTheMeasureOfItsSupport) {
  PrfSampler sampler(Coloring(kUnit, 0.125), options_, 6);  // empty: n' = 1
  double sum = 0.0;
  for (int i = 0; i < kDraws; ++i) {
    Edit edit;
    double log_q = 0.0;
    if (sampler.Propose(MoveType::kBoundaryTriangleBirth, &edit, &log_q)) sum += std::exp(log_q);
  }
  // μ of the support: ½ ∫∫ ds1 ds2 (same side, |s1 − s2| ≤ r) · ∫ dv (square of side 2r).
  const double pairs = 4.0 * (2.0 * r * 1.0 - r * r);
  const double expected = 0.5 * pairs * 4.0 * r * r;
  EXPECT_NEAR(sum / kDraws, expected, 0.01 * expected);
}

TEST_F(BirthDensity, CornerEdgeIntegratesToTheMeasureOfItsSupport) {
  PrfSampler sampler(Coloring(kUnit, 0.125), options_, 7);  // empty: n_b' = 2, π_death = 1
  double sum = 0.0;
  for (int i = 0; i < kDraws; ++i) {
    Edit edit;
    double log_q = 0.0;
    if (sampler.Propose(MoveType::kCornerBirth, &edit, &log_q)) sum += std::exp(log_q);
  }
  // Four corners, each with both distances in [0, r): μ = 4 r².
  EXPECT_NEAR(sum / kDraws, 4.0 * r * r, 1e-9);
}

// Draws `draws` vertex births from the sampler's state and calls f(1/q, e, u, w, v) on each:
// 1/q = 1 / (q(e) q(v | e)), the birth on edge e from u to w at v.
template <typename F>
void ForEachVertexBirth(PrfSampler& sampler, int draws, F&& f) {
  const Coloring& c = sampler.coloring();
  const double n_after = static_cast<double>(c.interior_vertices().size() + 1);
  for (int i = 0; i < draws; ++i) {
    Edit edit;
    double log_q = 0.0;
    ASSERT_TRUE(sampler.Propose(MoveType::kVertexBirth, &edit, &log_q));
    const EdgeId e = edit.removed_edges[0];
    f(std::exp(log_q) * n_after, e, c.vertex(c.edge(e).vertices[0]).position,
      c.vertex(c.edge(e).vertices[1]).position, edit.new_vertices[0].position);
  }
}

// Two integrals of the vertex birth's density: over its whole support (the widest rectangle
// along each edge) and over the narrowest rectangle alone. The second is what tells a mixture
// of widths from a density uniform on the widest rectangle, whose 1/q integrates to the same.
void ExpectVertexBirthsIntegrateToTheirRectangles(const std::vector<double>& widths, int draws) {
  SamplerOptions options = Options(2.0);
  options.vertex_birth_widths = widths;
  PrfSampler sampler(Warmed(2.0, 4, 3000).coloring(), options, 8);
  const Coloring& c = sampler.coloring();
  const double narrowest = *std::min_element(widths.begin(), widths.end());
  const double widest = *std::max_element(widths.begin(), widths.end());
  double whole = 0.0;
  double narrow = 0.0;
  ForEachVertexBirth(sampler, draws,
                     [&](double inverse_q, EdgeId e, const Vec2& u, const Vec2& w, const Vec2& v) {
                       const double length = c.edge(e).length;
                       whole += inverse_q;
                       if (std::abs(Cross(w - u, v - u)) / length <= narrowest * length)
                         narrow += inverse_q;
                     });
  // Σ_e the area of the rectangle along e of half-width κ|e|.
  double widest_area = 0.0;
  double narrowest_area = 0.0;
  for (EdgeId e : c.edge_ids()) {
    widest_area += 2.0 * widest * std::pow(c.edge(e).length, 2);
    narrowest_area += 2.0 * narrowest * std::pow(c.edge(e).length, 2);
  }
  EXPECT_NEAR(whole / draws, widest_area, 0.01 * widest_area);
  EXPECT_NEAR(narrow / draws, narrowest_area, 0.02 * narrowest_area);
}

TEST_F(BirthDensity, VertexBirthIntegratesToTheRectanglesAlongTheEdges) {
  ExpectVertexBirthsIntegrateToTheirRectangles({0.5}, kDraws);
}

TEST_F(BirthDensity, VertexBirthsOfMixedWidthsIntegrateToEachRectangle) {
  ExpectVertexBirthsIntegrateToTheirRectangles({0.25, 3.0}, kDraws);
}

// The vertices beyond the ends of edge e (none beyond an end on the window's side), found anew.
std::vector<Vec2> BeyondEndsOf(const Coloring& c, EdgeId e) {
  std::vector<Vec2> beyond;
  for (VertexId end : c.edge(e).vertices) {
    const ColoringVertex& vertex = c.vertex(end);
    if (vertex.side != kInterior) continue;
    const EdgeId other = vertex.edges[0] == e ? vertex.edges[1] : vertex.edges[0];
    beyond.push_back(c.vertex(c.Other(other, end)).position);
  }
  return beyond;
}

// The corner ahead of edge e, found anew: where the lines through the edges beyond its ends meet,
// ahead of both ends, solved as a 2×2 system.
std::optional<Vec2> CornerAheadOf(const Coloring& c, EdgeId e) {
  const std::vector<Vec2> beyond = BeyondEndsOf(c, e);
  if (beyond.size() != 2) return std::nullopt;  // an end on the window's side
  const Vec2& pu = c.vertex(c.edge(e).vertices[0]).position;
  const Vec2& pw = c.vertex(c.edge(e).vertices[1]).position;
  const Vec2 du = pu - beyond[0];
  const Vec2 dw = pw - beyond[1];
  Eigen::Matrix2d system;
  system << du.x(), -dw.x(), du.y(), -dw.y();
  if (std::abs(system.determinant()) <= 1e-9 * du.norm() * dw.norm()) return std::nullopt;
  const Eigen::Vector2d ahead = system.partialPivLu().solve(pw - pu);
  if (ahead(0) <= 0.0 || ahead(1) <= 0.0) return std::nullopt;
  return pu + ahead(0) * du;
}

// With corner completion or neighbour births on, the vertex birth's density mixes up to three
// parts: the rectangle along the edge, the square around the corner ahead and the squares around
// the vertices beyond the ends. 1/q integrates over each part to its area (a neighbour square
// that holds v counts once for each anchor it is drawn around), so a density that left out or
// misweighed any part would miss it.
// `corner_tolerance`: the relative error allowed on the corners' squares, which fewer draws reach
// when corner completion has the smaller share.
void ExpectAnchoredBirthsIntegrateToTheirParts(double corner_completion, double neighbour_birth,
                                               double corner_tolerance, std::uint64_t seed,
                                               int draws) {
  SamplerOptions options = Options(2.0);
  options.corner_completion = corner_completion;
  options.corner_completion_jitter = 0.02;
  options.neighbour_birth = neighbour_birth;
  options.neighbour_birth_jitter = 0.03;
  PrfSampler sampler(Warmed(2.0, 4, 3000).coloring(), options, seed);
  const Coloring& c = sampler.coloring();
  const double hc = options.corner_completion_jitter;
  const double hn = options.neighbour_birth_jitter;
  double rectangles = 0.0;
  double corner_squares = 0.0;
  double neighbour_squares = 0.0;
  ForEachVertexBirth(sampler, draws,
                     [&](double inverse_q, EdgeId e, const Vec2& u, const Vec2& w, const Vec2& v) {
                       const double length = c.edge(e).length;
                       const double t = (w - u).dot(v - u) / (length * length);
                       const double offset = std::abs(Cross(w - u, v - u)) / length;
                       if (t >= 0.0 && t <= 1.0 && offset <= 0.5 * length) rectangles += inverse_q;
                       const std::optional<Vec2> corner = CornerAheadOf(c, e);
                       if (corner && (v - *corner).cwiseAbs().maxCoeff() <= hc)
                         corner_squares += inverse_q;
                       for (const Vec2& anchor : BeyondEndsOf(c, e))
                         if ((v - anchor).cwiseAbs().maxCoeff() <= hn)
                           neighbour_squares += inverse_q;
                     });
  double rectangle_area = 0.0;
  int corners = 0;
  int anchors = 0;
  for (EdgeId e : c.edge_ids()) {
    rectangle_area += 2.0 * 0.5 * std::pow(c.edge(e).length, 2);
    if (CornerAheadOf(c, e)) ++corners;
    anchors += static_cast<int>(BeyondEndsOf(c, e).size());
  }
  EXPECT_NEAR(rectangles / draws, rectangle_area, 0.02 * rectangle_area);
  if (corner_completion > 0.0) {
    ASSERT_GE(corners, 3) << "too few corners ahead for the test to mean something";
    const double corner_area = corners * 4.0 * hc * hc;
    EXPECT_NEAR(corner_squares / draws, corner_area, corner_tolerance * corner_area);
  }
  if (neighbour_birth > 0.0) {
    const double neighbour_area = anchors * 4.0 * hn * hn;
    EXPECT_NEAR(neighbour_squares / draws, neighbour_area, 0.03 * neighbour_area);
  }
}

TEST_F(BirthDensity, CornerCompletionIntegratesToItsSquaresAndRectangles) {
  ExpectAnchoredBirthsIntegrateToTheirParts(0.5, 0.0, 0.03, 9, kDraws);
}

TEST_F(BirthDensity, NeighbourBirthsIntegrateToTheirSquares) {
  ExpectAnchoredBirthsIntegrateToTheirParts(0.3, 0.4, 0.04, 10, kDraws);
}

// The vertices beyond v's neighbours (none beyond a neighbour on the window's side), found anew.
std::vector<Vec2> BeyondNeighboursOf(const Coloring& c, VertexId v) {
  std::vector<Vec2> beyond;
  for (EdgeId e : c.vertex(v).edges) {
    const VertexId neighbour = c.Other(e, v);
    const ColoringVertex& n = c.vertex(neighbour);
    if (n.side != kInterior) continue;
    const EdgeId other = n.edges[0] == e ? n.edges[1] : n.edges[0];
    beyond.push_back(c.vertex(c.Other(other, neighbour)).position);
  }
  return beyond;
}

struct Box {
  Vec2 lo;
  Vec2 hi;
};

Box SquareAround(const Vec2& centre, double h) {
  return {centre - Vec2::Constant(h), centre + Vec2::Constant(h)};
}

// The area of the union of a few axis-aligned boxes, by inclusion and exclusion.
double UnionArea(const std::vector<Box>& boxes) {
  double area = 0.0;
  const std::size_t n = boxes.size();
  for (std::size_t subset = 1; subset < (std::size_t{1} << n); ++subset) {
    Box meet{Vec2::Constant(-1e300), Vec2::Constant(1e300)};
    int members = 0;
    for (std::size_t k = 0; k < n; ++k)
      if (subset & (std::size_t{1} << k)) {
        meet.lo = meet.lo.cwiseMax(boxes[k].lo);
        meet.hi = meet.hi.cwiseMin(boxes[k].hi);
        ++members;
      }
    const Vec2 extent = (meet.hi - meet.lo).cwiseMax(0.0);
    area += (members % 2 == 1 ? 1.0 : -1.0) * extent.x() * extent.y();
  }
  return area;
}

// The vertex jump's density, written anew from docs/prf-moves.md: ½ over the squares around the
// vertices beyond the neighbours, ½ in the far square around the vertex (all of it without
// such vertices).
double JumpDensity(const Vec2& from, const Vec2& to, const std::vector<Vec2>& beyond,
                   const SamplerOptions& options) {
  const auto square = [&to](const Vec2& centre, double h) {
    return (to - centre).cwiseAbs().maxCoeff() <= h ? 1.0 / (4.0 * h * h) : 0.0;
  };
  const double far = square(from, options.vertex_jump_reach);
  if (beyond.empty()) return far;
  double squares = 0.0;
  for (const Vec2& anchor : beyond) squares += square(anchor, options.vertex_jump_jitter);
  return 0.5 * squares / static_cast<double>(beyond.size()) + 0.5 * far;
}

// Every jump's log proposal ratio is that of the densities above, and the draws follow the
// forward density: over the jumps the sampler returns, 1/q integrates over each part of the
// density (the far square, the square around the vertex beyond the first neighbour, the one
// beyond the second) to the area of that part the jump can land on, so a part drawn too often,
// too rarely or never would miss its area. A jump can land anywhere in the far square; in the
// rest of a neighbour's neighbour's square only when the vertex lies in one of those squares
// (the jump back may then draw it from its square), and is refused otherwise.
TEST(MoveRatios, VertexJumpsDrawAndWeighTheirSquares) {
  SamplerOptions options = Options(2.0);
  options.weights[MoveKind::kVertexJump] = 1.0;
  options.vertex_jump_reach = 0.3;
  options.vertex_jump_jitter = 0.05;
  PrfSampler sampler(Warmed(2.0, 6, 4000).coloring(), options, 17);
  const Coloring& c = sampler.coloring();
  const auto interior = c.interior_vertices();
  ASSERT_GE(interior.size(), 10u) << "too few vertices for the test to mean something";
  const auto inside = [](const Vec2& x, const Box& box) {
    return (x.array() >= box.lo.array()).all() && (x.array() <= box.hi.array()).all();
  };
  // The squares of the density at v: the far one, then those beyond the first and the second
  // neighbour in the order of v's edges, as the sampler's (none beyond a boundary neighbour).
  const auto squares_of = [&](VertexId v) {
    const Vec2& from = c.vertex(v).position;
    std::array<std::optional<Box>, 3> squares{SquareAround(from, options.vertex_jump_reach)};
    const std::vector<Vec2> beyond = BeyondNeighboursOf(c, v);
    std::size_t next = 0;
    for (std::size_t k = 0; k < 2; ++k)
      if (c.vertex(c.Other(c.vertex(v).edges[k], v)).side == kInterior)
        squares[k + 1] = SquareAround(beyond[next++], options.vertex_jump_jitter);
    return squares;
  };

  // The area of each part a jump can land on, averaged over the vertex drawn.
  std::array<double, 3> expected{};
  int in_a_square = 0;
  for (VertexId v : interior) {
    const Vec2& from = c.vertex(v).position;
    const auto squares = squares_of(v);
    const Box& far = *squares[0];
    bool near_an_anchor = false;
    for (std::size_t k = 1; k < 3; ++k) near_an_anchor |= squares[k] && inside(from, *squares[k]);
    in_a_square += near_an_anchor;
    expected[0] += UnionArea({far});
    for (std::size_t k = 1; k < 3; ++k) {
      if (!squares[k]) continue;
      const Box reachable{squares[k]->lo.cwiseMax(far.lo), squares[k]->hi.cwiseMin(far.hi)};
      expected[k] += UnionArea({near_an_anchor ? *squares[k] : reachable});
    }
  }
  for (double& area : expected) area /= static_cast<double>(interior.size());

  const int draws = 400000;
  std::array<double, 3> sum{};
  std::array<double, 3> sum2{};
  int far_jumps = 0;
  for (int i = 0; i < draws; ++i) {
    Edit edit;
    double log_q = 0.0;
    if (!sampler.Propose(MoveType::kVertexJump, &edit, &log_q)) continue;
    ASSERT_EQ(edit.removed_vertices.size(), 1u);
    ASSERT_EQ(edit.new_vertices.size(), 1u);
    const VertexId v = edit.removed_vertices[0];
    const Vec2& from = c.vertex(v).position;
    const Vec2& to = edit.new_vertices[0].position;
    const std::vector<Vec2> beyond = BeyondNeighboursOf(c, v);
    const double forward = JumpDensity(from, to, beyond, options);
    const double reverse = JumpDensity(to, from, beyond, options);
    ASSERT_GT(forward, 0.0);
    ASSERT_GT(reverse, 0.0);
    EXPECT_NEAR(log_q, std::log(reverse) - std::log(forward), 1e-9);
    far_jumps += (to - from).cwiseAbs().maxCoeff() > options.step_scales.back();
    const auto squares = squares_of(v);
    for (std::size_t k = 0; k < 3; ++k)
      if (squares[k] && inside(to, *squares[k])) {
        sum[k] += 1.0 / forward;
        sum2[k] += 1.0 / (forward * forward);
      }
  }
  const char* const parts[] = {"far square", "square beyond the first neighbour",
                               "square beyond the second neighbour"};
  for (std::size_t k = 0; k < 3; ++k) {
    const double mean = sum[k] / draws;
    const double standard_error = std::sqrt((sum2[k] / draws - mean * mean) / draws);
    EXPECT_NEAR(mean, expected[k], 4.0 * standard_error + 1e-3 * expected[k])
        << parts[k] << ": expected " << expected[k] << ", ±" << standard_error;
  }
  // The states where the two cases differ are there, and so are the far jumps that no
  // random-walk step reaches.
  EXPECT_GE(in_a_square, 1);
  EXPECT_GT(far_jumps, 1000);
}

}  // namespace
}  // namespace priormap::prf
