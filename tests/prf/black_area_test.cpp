// The black area of a coloring and its change under an edit (the free-space prior's
// potential): BlackAreaChange gives ± the area of a flipped region that holds nothing of the
// coloring, the difference of the lobes of a bow tie, and refuses any other, and a chain with the
// free-space prior keeps its running black area equal to the coloring's after every step.
#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include <gtest/gtest.h>

#include <priormap/core/polygon.hpp>
#include <priormap/prf/black_area.hpp>
#include <priormap/prf/coloring.hpp>
#include <priormap/prf/sampler.hpp>

namespace priormap::prf {
namespace {

// The anchor of a coloring of this window is at about (2.06, 1.59).
const Window kWindow{Vec2::Zero(), Vec2(4, 3)};
constexpr double kCell = 0.5;
// A black 0.6 m square island, away from the anchor: 0.36 m².
const std::array<Vec2, 4> kIsland = {Vec2(1.5, 0.6), Vec2(2.1, 0.6), Vec2(2.1, 1.2),
                                     Vec2(1.5, 1.2)};

Coloring Island(Colour anchor) {
  std::vector<NewVertex> vertices;
  for (const Vec2& p : kIsland) vertices.push_back({p, kInterior});
  const std::vector<std::array<int, 2>> edges = {{0, 1}, {1, 2}, {2, 3}, {3, 0}};
  auto built = Coloring::FromGraph(kWindow, kCell, vertices, edges, anchor);
  return std::get<Coloring>(std::move(built));
}

// A triangle birth, as the sampler proposes it (PrfSampler::AddTriangle).
Edit TriangleBirth(const Vec2& a, const Vec2& b, const Vec2& c) {
  Edit edit;
  for (const Vec2& x : {a, b, c}) {
    edit.new_vertices.push_back({x, kInterior});
    edit.flipped_region.push_back(x);
  }
  for (int k = 0; k < 3; ++k)
    edit.added_edges.push_back({VertexRef::New(k), VertexRef::New((k + 1) % 3)});
  return edit;
}

VertexId VertexAt(const Coloring& coloring, const Vec2& p) {
  for (VertexId v : coloring.interior_vertices())
    if (coloring.vertex(v).position == p) return v;
  ADD_FAILURE() << "no vertex at (" << p.transpose() << ")";
  return kNoVertex;
}

TEST(BlackArea, OfAnIslandIsItsAreaAndOfItsComplementTheRest) {
  EXPECT_NEAR(BlackArea(Island(Colour::kWhite)), 0.36, 1e-12);
  EXPECT_NEAR(BlackArea(Island(Colour::kBlack)), 12.0 - 0.36, 1e-12);
  EXPECT_EQ(BlackArea(Coloring(kWindow, kCell, Colour::kWhite)), 0.0);
  EXPECT_NEAR(BlackArea(Coloring(kWindow, kCell, Colour::kBlack)), 12.0, 1e-12);
  // A sampler with the free-space prior starts its running area from its first coloring (and
  // keeps none without the prior).
  SamplerOptions options;
  options.free_space = 0.5;
  EXPECT_NEAR(PrfSampler(Island(Colour::kBlack), options, 1).black_area(), 12.0 - 0.36, 1e-12);
  options.free_space = 0.0;
  EXPECT_EQ(PrfSampler(Island(Colour::kBlack), options, 1).black_area(), 0.0);
}

TEST(BlackAreaChange, OfATriangleBornInWhiteIsPlusItsArea) {
  Coloring coloring = Island(Colour::kWhite);
  const Edit birth = TriangleBirth(Vec2(3, 0.5), Vec2(3.5, 0.5), Vec2(3.2, 1.0));
  EditEffect effect;
  ASSERT_TRUE(coloring.Evaluate(birth, &effect));
  const auto change = BlackAreaChange(coloring, birth);
  ASSERT_TRUE(change);
  EXPECT_NEAR(*change, 0.125, 1e-12);
  // Its death flips the same region back: minus the area.
  const auto added = coloring.Apply(birth, effect);
  EXPECT_NEAR(BlackArea(coloring), 0.36 + 0.125, 1e-12);
  Edit death;
  for (EdgeId e : added) death.removed_edges.push_back(e);
  for (const Vec2& p : {Vec2(3, 0.5), Vec2(3.5, 0.5), Vec2(3.2, 1.0)}) {
    death.removed_vertices.push_back(VertexAt(coloring, p));
    death.flipped_region.push_back(p);
  }
  ASSERT_TRUE(coloring.Evaluate(death, &effect));
  const auto back = BlackAreaChange(coloring, death);
  ASSERT_TRUE(back);
  EXPECT_NEAR(*back, -0.125, 1e-12);
}

TEST(BlackAreaChange, OfATriangleBornInBlackIsMinusItsArea) {
  for (const Colour anchor : {Colour::kWhite, Colour::kBlack}) {
    const Coloring coloring = Island(anchor);
    // Inside the island, and in the white (or black) around it, whatever the anchor's colour.
    const Edit inside = TriangleBirth(Vec2(1.6, 0.7), Vec2(2.0, 0.7), Vec2(1.8, 1.1));
    const Edit outside = TriangleBirth(Vec2(3, 0.5), Vec2(3.5, 0.5), Vec2(3.2, 1.0));
    EditEffect effect;
    ASSERT_TRUE(coloring.Evaluate(inside, &effect));
    ASSERT_TRUE(coloring.Evaluate(outside, &effect));
    const double sign = anchor == Colour::kWhite ? 1.0 : -1.0;
    ASSERT_TRUE(BlackAreaChange(coloring, inside));
    EXPECT_NEAR(*BlackAreaChange(coloring, inside), -sign * 0.08, 1e-12);
    ASSERT_TRUE(BlackAreaChange(coloring, outside));
    EXPECT_NEAR(*BlackAreaChange(coloring, outside), sign * 0.125, 1e-12);
  }
}

TEST(BlackAreaChange, IsUnknownForATriangleAroundAnIsland) {
  const Coloring coloring = Island(Colour::kWhite);
  // Around the island (and the anchor): its inside is of two colours.
  const Edit around = TriangleBirth(Vec2(0.2, 0.2), Vec2(3.8, 0.2), Vec2(2.0, 2.8));
  EditEffect effect;
  ASSERT_TRUE(coloring.Evaluate(around, &effect));
  EXPECT_FALSE(BlackAreaChange(coloring, around));
}

TEST(BlackAreaChange, OfABowTieIsWhatOneLobeGainsLessWhatTheOtherLoses) {
  const Coloring coloring = Island(Colour::kWhite);
  // The island's corner (2.1, 1.2) moved out to (2.3, 0.9), past the line of the edge it
  // leaves: the region between the old and new edges is a bow tie.
  const Vec2 u = kIsland[1], p = kIsland[2], w = kIsland[3], moved(2.3, 0.9);
  const VertexId v = VertexAt(coloring, p);
  Edit move;
  move.removed_edges.push_back(coloring.vertex(v).edges[0]);
  move.removed_edges.push_back(coloring.vertex(v).edges[1]);
  move.removed_vertices.push_back(v);
  move.new_vertices.push_back({moved, kInterior});
  move.added_edges.push_back({VertexRef::Existing(VertexAt(coloring, u)), VertexRef::New(0)});
  move.added_edges.push_back({VertexRef::New(0), VertexRef::Existing(VertexAt(coloring, w))});
  for (const Vec2& x : {u, p, w, moved}) move.flipped_region.push_back(x);
  EditEffect effect;
  ASSERT_TRUE(coloring.Evaluate(move, &effect));
  // One lobe (beyond the old edge from u) turns black, the other (inside the old corner)
  // white: the change is the difference, which the coloring after the move confirms.
  const auto bow_tie = BlackAreaChange(coloring, move);
  ASSERT_TRUE(bow_tie);
  Coloring moved_coloring = coloring;
  moved_coloring.Apply(move, effect);
  EXPECT_NEAR(*bow_tie, BlackArea(moved_coloring) - BlackArea(coloring), 1e-12);
  EXPECT_GT(std::abs(*bow_tie), 1e-3);
  // The same move to a point on the other side does not cross: a simple quadrilateral.
  move.new_vertices[0].position = Vec2(2.3, 1.4);
  move.flipped_region[3] = Vec2(2.3, 1.4);
  ASSERT_TRUE(coloring.Evaluate(move, &effect));
  const auto change = BlackAreaChange(coloring, move);
  ASSERT_TRUE(change);
  // The island grows by the quadrilateral u, p, w, moved.
  const std::array<Vec2, 4> quad = {u, p, w, Vec2(2.3, 1.4)};
  EXPECT_NEAR(*change, std::abs(RingSignedArea(quad)), 1e-12);
}

TEST(BlackArea, TheSamplersRunningAreaMatchesTheColoringAfterEveryStep) {
  const Window window{Vec2::Zero(), Vec2(2, 2)};
  SamplerOptions options;
  options.p = 1.0;
  options.birth_scale = 0.5;
  options.free_space = 0.5;
  options.weights[MoveKind::kEdgeShift] = 1.0;
  PrfSampler sampler(Coloring(window, 0.25), options, 51);
  int changed = 0;
  double last = sampler.black_area();
  for (int step = 0; step < 6000; ++step) {
    sampler.Step();
    const double recomputed = BlackArea(sampler.coloring());
    // Relative to the window's area: the running sum gathers rounding from every change.
    ASSERT_NEAR(sampler.black_area(), recomputed, 1e-9 * window.Area()) << "step " << step;
    changed += sampler.black_area() != last ? 1 : 0;
    last = sampler.black_area();
  }
  // Many accepted moves changed the area, and structure built up.
  EXPECT_GT(changed, 300);
  EXPECT_GT(sampler.coloring().stats().edges, 5);
}

}  // namespace
}  // namespace priormap::prf
