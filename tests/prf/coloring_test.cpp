// Polygonal colorings: colours by crossing parity, edits and their validity, the Arak measure's
// statistics, and the grid index's answers against brute force.
#include <array>
#include <cmath>
#include <limits>
#include <numbers>

#include <gtest/gtest.h>

#include <priormap/core/rng.hpp>
#include <priormap/prf/coloring.hpp>
#include <priormap/prf/sampler.hpp>

#include "prf/brute_force.hpp"

namespace priormap::prf {
namespace {

const Window kUnit{Vec2::Zero(), Vec2::Ones()};

// An edit adding the closed polygon `corners` (interior vertices), reversing its inside.
Edit AddPolygon(std::initializer_list<Vec2> corners) {
  Edit edit;
  int k = 0;
  for (const Vec2& c : corners) {
    edit.new_vertices.push_back({c, kInterior});
    edit.flipped_region.push_back(c);
    ++k;
  }
  for (int i = 0; i < k; ++i)
    edit.added_edges.push_back({VertexRef::New(i), VertexRef::New((i + 1) % k)});
  return edit;
}

bool Try(Coloring& coloring, const Edit& edit) {
  EditEffect effect;
  if (!coloring.Evaluate(edit, &effect)) return false;
  coloring.Apply(edit, effect);
  return true;
}

TEST(Coloring, EmptyColoringHasTheAnchorColourEverywhere) {
  const Coloring coloring(kUnit, 0.25, Colour::kBlack);
  EXPECT_EQ(coloring.ColourAt(Vec2(0.1, 0.9)), Colour::kBlack);
  EXPECT_EQ(coloring.stats().edges, 0);
  EXPECT_DOUBLE_EQ(coloring.LogArakDensity(2.0), 0.0);
  EXPECT_TRUE(coloring.window().ContainsInterior(coloring.anchor()));
}

TEST(Coloring, ATriangleReversesItsInsideOnly) {
  Coloring coloring(kUnit, 0.25);
  // Away from the anchor: the anchor keeps its colour, the inside turns black.
  ASSERT_TRUE(Try(coloring, AddPolygon({{0.1, 0.1}, {0.3, 0.1}, {0.2, 0.3}})));
  EXPECT_EQ(coloring.anchor_colour(), Colour::kWhite);
  EXPECT_EQ(coloring.ColourAt(Vec2(0.2, 0.15)), Colour::kBlack);
  EXPECT_EQ(coloring.ColourAt(Vec2(0.8, 0.8)), Colour::kWhite);
  // Around the anchor: the anchor turns black, so that the outside keeps its colour.
  ASSERT_TRUE(Try(coloring, AddPolygon({{0.4, 0.4}, {0.7, 0.4}, {0.55, 0.7}})));
  EXPECT_EQ(coloring.anchor_colour(), Colour::kBlack);
  EXPECT_EQ(coloring.ColourAt(Vec2(0.55, 0.45)), Colour::kBlack);
  EXPECT_EQ(coloring.ColourAt(Vec2(0.8, 0.8)), Colour::kWhite);
  EXPECT_EQ(coloring.ColourAt(Vec2(0.2, 0.15)), Colour::kBlack);
  EXPECT_EQ(coloring.CountCrossings(Vec2(0.05, 0.2), Vec2(0.95, 0.5)), 4);
  EXPECT_FALSE(coloring.FindInvariantViolation());
}

TEST(Coloring, ArakDensityOfATriangleByHand) {
  Coloring coloring(kUnit, 0.25);
  const Vec2 a(0.2, 0.2), b(0.6, 0.2), c(0.2, 0.5);  // right angle at a, sides 0.4, 0.3, 0.5
  ASSERT_TRUE(Try(coloring, AddPolygon({a, b, c})));
  const double p = 1.5;
  const double sin_b = 0.3 / 0.5, sin_c = 0.4 / 0.5;  // sin of the acute angles; sin 90° = 1
  const double expected = 3.0 * std::log(p) - std::log(0.4 * 0.3 * 0.5) + std::log(sin_b) +
                          std::log(sin_c) - 2.0 * p * 1.2;
  EXPECT_NEAR(coloring.LogArakDensity(p), expected, 1e-12);
  EXPECT_EQ(coloring.stats().edges, 3);
  EXPECT_NEAR(coloring.stats().total_length, 1.2, 1e-15);
}

TEST(Coloring, BoundaryVertexAngleIsToTheSide) {
  Coloring coloring(kUnit, 0.25);
  // A corner edge from (0.3, 0) to (1, 0.7): 45° to both sides.
  Edit edit;
  edit.new_vertices.push_back({{0.3, 0.0}, 0});
  edit.new_vertices.push_back({{1.0, 0.7}, 1});
  edit.added_edges.push_back({VertexRef::New(0), VertexRef::New(1)});
  for (const Vec2& x : {Vec2(0.3, 0.0), Vec2(1.0, 0.0), Vec2(1.0, 0.7)})
    edit.flipped_region.push_back(x);
  ASSERT_TRUE(Try(coloring, edit));
  const double length = 0.7 * std::numbers::sqrt2;
  EXPECT_NEAR(coloring.LogArakDensity(1.0),
              -std::log(length) + 2.0 * std::log(std::sqrt(0.5)) - 2.0 * length, 1e-12);
  EXPECT_EQ(coloring.ColourAt(Vec2(0.95, 0.05)), Colour::kBlack);
  EXPECT_EQ(coloring.ColourAt(Vec2(0.1, 0.9)), Colour::kWhite);
}

TEST(Coloring, InvalidEditsAreRefusedAndChangeNothing) {
  Coloring coloring(kUnit, 0.25);
  ASSERT_TRUE(Try(coloring, AddPolygon({{0.1, 0.1}, {0.5, 0.1}, {0.3, 0.5}})));
  const double before = coloring.LogArakDensity(1.0);
  EditEffect effect;
  // Crossing the triangle.
  EXPECT_FALSE(coloring.Evaluate(AddPolygon({{0.3, 0.3}, {0.8, 0.3}, {0.6, 0.8}}), &effect));
  // A vertex outside the window, or on its boundary as an interior vertex.
  EXPECT_FALSE(coloring.Evaluate(AddPolygon({{0.6, 0.6}, {1.2, 0.6}, {0.7, 0.9}}), &effect));
  EXPECT_FALSE(coloring.Evaluate(AddPolygon({{0.6, 0.6}, {1.0, 0.6}, {0.7, 0.9}}), &effect));
  // Collinear: a zero angle has zero measure.
  EXPECT_FALSE(coloring.Evaluate(AddPolygon({{0.6, 0.6}, {0.7, 0.7}, {0.8, 0.8}}), &effect));
  // Two boundary vertices on one side joined by an edge would run along the boundary.
  Edit along_side;
  along_side.new_vertices.push_back({{0.6, 0.0}, 0});
  along_side.new_vertices.push_back({{0.9, 0.0}, 0});
  along_side.added_edges.push_back({VertexRef::New(0), VertexRef::New(1)});
  EXPECT_FALSE(coloring.Evaluate(along_side, &effect));
  // A boundary vertex that is not on its side.
  Edit off_side;
  off_side.new_vertices.push_back({{0.6, 0.01}, 0});
  off_side.new_vertices.push_back({{1.0, 0.5}, 1});
  off_side.added_edges.push_back({VertexRef::New(0), VertexRef::New(1)});
  EXPECT_FALSE(coloring.Evaluate(off_side, &effect));
  EXPECT_EQ(coloring.LogArakDensity(1.0), before);
  EXPECT_FALSE(coloring.FindInvariantViolation());
}

// Long random chains with every move: the invariants hold after each accepted move, and the
// index answers crossing counts, colours and first hits as brute force does.
TEST(Coloring, IndexAnswersAsBruteForceAlongAChain) {
  SamplerOptions options;
  options.p = 3.0;
  options.birth_scale = 0.3;
  options.step_scales = {0.01, 0.05, 0.2};
  options.check_invariants = true;
  PrfSampler sampler(Coloring(kUnit, 1.0 / 12.0), options, 17);
  Rng rng(4);
  int checked = 0;
  for (int round = 0; round < 40; ++round) {
    sampler.Run(500);
    const Coloring& coloring = sampler.coloring();
    const Colour anchor = coloring.anchor_colour();
    for (int i = 0; i < 25; ++i) {
      const Vec2 a(rng.Uniform(), rng.Uniform()), b(rng.Uniform(), rng.Uniform());
      ASSERT_EQ(coloring.CountCrossings(a, b), CrossingsByBruteForce(coloring, a, b));
      const int parity = CrossingsByBruteForce(coloring, coloring.anchor(), b) % 2;
      ASSERT_EQ(coloring.ColourAt(b), parity == 0 ? anchor : Flip(anchor));
      // First hit along a ray against every edge.
      const Vec2 direction = UnitVector(rng.Uniform(0.0, 2.0 * std::numbers::pi));
      double nearest = std::numeric_limits<double>::infinity();
      // (The same intersection formula: this checks the walk, which edges it considers.)
      for (const Segment& s : AllEdges(coloring)) {
        const auto t = RaySegmentHit(a, direction, s.a, s.b, 2.0);
        if (t) nearest = std::min(nearest, *t);
      }
      const auto hit = coloring.FirstHit(a, direction, 2.0);
      if (std::isinf(nearest)) {
        ASSERT_FALSE(hit);
      } else {
        ASSERT_TRUE(hit);
        ASSERT_DOUBLE_EQ(hit->t, nearest);
      }
      ++checked;
    }
  }
  EXPECT_EQ(checked, 1000);
  EXPECT_GT(sampler.coloring().stats().edges, 20);  // p = 3: about 125 edges expected
}

TEST(RaySegmentHit, FindsTheCrossingWhicheverWayTheSegmentRuns) {
  Rng rng(5);
  int hits = 0;
  for (int i = 0; i < 1000; ++i) {
    const Vec2 origin(rng.Uniform(), rng.Uniform());
    const Vec2 direction = UnitVector(rng.Uniform(0.0, 2.0 * std::numbers::pi));
    const Vec2 a(rng.Uniform(), rng.Uniform()), b(rng.Uniform(), rng.Uniform());
    const auto forward = RaySegmentHit(origin, direction, a, b, 1.5);
    const auto backward = RaySegmentHit(origin, direction, b, a, 1.5);
    ASSERT_EQ(forward.has_value(), backward.has_value());
    if (!forward) continue;
    ++hits;
    ASSERT_EQ(*forward, *backward);  // bit for bit
    const Vec2 q = origin + *forward * direction;
    ASSERT_NEAR(Cross(b - a, q - a), 0.0, 1e-12);  // on ab's line
    ASSERT_LE(*forward, 1.5);
  }
  EXPECT_GT(hits, 100);
  EXPECT_FALSE(RaySegmentHit(Vec2::Zero(), Vec2::UnitX(), Vec2(-1, -1), Vec2(-1, 1), 5.0));
  EXPECT_EQ(*RaySegmentHit(Vec2::Zero(), Vec2::UnitX(), Vec2(2, -1), Vec2(2, 1), 5.0), 2.0);
}

// Every move reverses exactly its region: after each applied edit, a point's colour (by crossing
// parity from the anchor) has changed if and only if the point lies in the edit's region. A
// wrong region, or a wrong anchor flip, changes the colour of points outside it.
TEST(Coloring, EveryMoveReversesExactlyItsRegion) {
  SamplerOptions options;
  options.p = 3.0;
  options.birth_scale = 0.4;
  options.step_scales = {0.05, 0.3, 0.9};  // boundary moves that pass corners
  options.vertex_jump_reach = 0.4;         // far jumps that mostly stay in the unit window
  std::vector<Vec2> guide_points;
  Rng guide_rng(5);
  for (int i = 0; i < 100; ++i) guide_points.emplace_back(guide_rng.Uniform(), guide_rng.Uniform());
  options.guide = std::make_shared<const BirthGuide>(guide_points, options.birth_scale, 0.05);
  PrfSampler sampler(Coloring(kUnit, 0.125), options, 21);
  sampler.Run(3000);
  const Coloring warmed = sampler.coloring();
  Coloring coloring = warmed;
  PrfSampler proposer(coloring, options, 22);
  Rng rng(6);
  std::array<int, kNumMoveTypes> applied{};
  for (int round = 0; round < 400 * kNumMoveTypes; ++round) {
    // Every edit that is valid is applied, with no acceptance test, so births that are valid more
    // often than their deaths (vertex pairs) would crowd the state: start again from time to time.
    if (round % (20 * kNumMoveTypes) == 0) {
      coloring = warmed;
      proposer = PrfSampler(coloring, options, 22 + static_cast<std::uint64_t>(round));
    }
    const auto type = static_cast<MoveType>(round % kNumMoveTypes);
    Edit edit;
    EditEffect effect;
    double log_q = 0.0;
    if (!proposer.Propose(type, &edit, &log_q) || !coloring.Evaluate(edit, &effect)) continue;
    // Points anywhere, and points in the box of the vertices the edit touches, where its region
    // is (for a boundary move past a corner, the box of the old and new positions holds it).
    Box2 touched;
    for (EdgeId e : edit.removed_edges) {
      touched.extend(coloring.EdgeSegment(e).a);
      touched.extend(coloring.EdgeSegment(e).b);
    }
    for (const NewVertex& v : edit.new_vertices) touched.extend(v.position);
    std::vector<Vec2> points;
    std::vector<Colour> before;
    for (int i = 0; i < 60; ++i) {
      const Vec2 u(rng.Uniform(), rng.Uniform());
      points.push_back(i < 30 ? u : Vec2(touched.min() + u.cwiseProduct(touched.sizes())));
      before.push_back(coloring.ColourAt(points.back()));
    }
    coloring.Apply(edit, effect);
    const std::span<const Vec2> region(edit.flipped_region.begin(), edit.flipped_region.size());
    for (std::size_t i = 0; i < points.size(); ++i)
      ASSERT_EQ(coloring.ColourAt(points[i]) != before[i], RingContains(region, points[i]))
          << MoveTypeName(type) << " at (" << points[i].transpose() << ")";
    ++applied[static_cast<std::size_t>(type)];
    // Keep proposing from the new state.
    proposer = PrfSampler(coloring, options, 100 + static_cast<std::uint64_t>(round));
  }
  for (int t = 0; t < kNumMoveTypes; ++t)
    EXPECT_GT(applied[static_cast<std::size_t>(t)], 5) << MoveTypeName(static_cast<MoveType>(t));
  EXPECT_FALSE(coloring.FindInvariantViolation(1e-9));
}

}  // namespace
}  // namespace priormap::prf
