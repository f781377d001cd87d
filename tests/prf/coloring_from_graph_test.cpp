// Colorings given their discontinuity graph outright (Coloring::FromGraph): a valid graph gives
// a coloring whose statistics are the sums over its edges and vertices and whose colours follow
// the polygon it draws; every way a graph can fail to be a coloring of the window is refused
// with a message saying which.
#include <array>
#include <cmath>
#include <string>
#include <variant>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <priormap/core/polygon.hpp>
#include <priormap/core/rng.hpp>
#include <priormap/prf/coloring.hpp>

#include "prf/brute_force.hpp"

namespace priormap::prf {
namespace {

using ::testing::AnyOf;
using ::testing::HasSubstr;

// The anchor of a coloring of this window is at about (2.06, 1.59).
const Window kWindow{Vec2::Zero(), Vec2(4, 3)};
constexpr double kCell = 0.5;

using Edges = std::vector<std::array<int, 2>>;

// The edges of the closed ring through vertices first..first + count - 1.
Edges Ring(int first, int count) {
  Edges edges;
  for (int i = 0; i < count; ++i) edges.push_back({first + i, first + (i + 1) % count});
  return edges;
}

std::variant<Coloring, std::string> Build(const std::vector<NewVertex>& vertices,
                                          const Edges& edges, Colour anchor = Colour::kWhite) {
  return Coloring::FromGraph(kWindow, kCell, vertices, edges, anchor);
}

// The message of a refused graph ("" and a test failure when it was accepted).
std::string Refusal(const std::vector<NewVertex>& vertices, const Edges& edges) {
  auto built = Build(vertices, edges);
  if (const auto* message = std::get_if<std::string>(&built)) return *message;
  ADD_FAILURE() << "the graph was accepted";
  return "";
}

// log sin of the angle between directions u and w, from their cross product: independent of
// the coloring's own formula (which works from the vertices).
double LogSinBetween(const Vec2& u, const Vec2& w) {
  return std::log(std::abs(Cross(u, w)) / (u.norm() * w.norm()));
}

// Colours at many random points of the window against the even-odd rule on `ring`, which is
// black inside; points within `margin` of an edge are skipped (either colour is right there).
void ExpectBlackExactlyInside(const Coloring& coloring, const std::vector<Vec2>& ring,
                              double margin = 1e-6) {
  Rng rng(9);
  int inside = 0, outside = 0;
  for (int i = 0; i < 2000; ++i) {
    const Vec2 q(rng.Uniform(0.0, kWindow.Width()), rng.Uniform(0.0, kWindow.Height()));
    bool near_edge = false;
    for (const Segment& s : AllEdges(coloring))
      near_edge = near_edge || PointSegmentDistance(q, s) < margin;
    if (near_edge) continue;
    const bool in = RingContains(ring, q);
    ASSERT_EQ(coloring.ColourAt(q), in ? Colour::kBlack : Colour::kWhite)
        << "at (" << q.transpose() << ")";
    (in ? inside : outside) += 1;
  }
  EXPECT_GT(inside, 50);
  EXPECT_GT(outside, 50);
}

TEST(ColoringFromGraph, ASquareAroundTheAnchorHasItsStatisticsAndColours) {
  const std::vector<Vec2> square = {{1, 0.5}, {2.5, 0.5}, {2.5, 2}, {1, 2}};
  std::vector<NewVertex> vertices;
  for (const Vec2& p : square) vertices.push_back({p, kInterior});
  auto built = Build(vertices, Ring(0, 4), Colour::kBlack);
  ASSERT_TRUE(std::holds_alternative<Coloring>(built)) << std::get<std::string>(built);
  const Coloring& coloring = std::get<Coloring>(built);
  ASSERT_TRUE(RingContains(square, coloring.anchor()));  // so that the inside is black
  EXPECT_FALSE(coloring.FindInvariantViolation());
  EXPECT_EQ(coloring.stats().edges, 4);
  EXPECT_EQ(coloring.interior_vertices().size(), 4u);
  EXPECT_TRUE(coloring.boundary_vertices().empty());
  EXPECT_NEAR(coloring.stats().total_length, 6.0, 1e-12);
  EXPECT_NEAR(coloring.stats().sum_log_length, 4.0 * std::log(1.5), 1e-12);
  EXPECT_NEAR(coloring.stats().sum_log_sin, 0.0, 1e-12);  // four right angles
  // Axis-aligned edges: cos 4θ = 1, sin 4θ = 0.
  EXPECT_NEAR(coloring.stats().sum_cos4, 6.0, 1e-12);
  EXPECT_NEAR(coloring.stats().sum_sin4, 0.0, 1e-12);
  EXPECT_EQ(coloring.ColourAt(Vec2(1.2, 1.9)), Colour::kBlack);
  EXPECT_EQ(coloring.ColourAt(Vec2(0.5, 0.2)), Colour::kWhite);
  EXPECT_EQ(coloring.ColourAt(Vec2(3.5, 2.8)), Colour::kWhite);
  ExpectBlackExactlyInside(coloring, square);
}

TEST(ColoringFromGraph, ATriangleAwayFromTheAnchorHasItsStatisticsAndColours) {
  // Sides 1.2 (along x), 0.9 (along y) and 1.5: a right angle at the first vertex.
  const std::vector<Vec2> triangle = {{0.3, 0.3}, {1.5, 0.3}, {0.3, 1.2}};
  std::vector<NewVertex> vertices;
  for (const Vec2& p : triangle) vertices.push_back({p, kInterior});
  auto built = Build(vertices, Ring(0, 3), Colour::kWhite);
  ASSERT_TRUE(std::holds_alternative<Coloring>(built)) << std::get<std::string>(built);
  const Coloring& coloring = std::get<Coloring>(built);
  ASSERT_FALSE(RingContains(triangle, coloring.anchor()));
  EXPECT_FALSE(coloring.FindInvariantViolation());
  const ColoringStats& stats = coloring.stats();
  EXPECT_EQ(stats.edges, 3);
  EXPECT_NEAR(stats.total_length, 3.6, 1e-12);
  EXPECT_NEAR(stats.sum_log_length, std::log(1.2) + std::log(0.9) + std::log(1.5), 1e-12);
  EXPECT_NEAR(stats.sum_log_sin, std::log(0.9 / 1.5) + std::log(1.2 / 1.5), 1e-12);
  // The hypotenuse runs at θ = atan2(0.9, -1.2); the legs at 0 and 90°, where cos 4θ = 1.
  const double theta = std::atan2(0.9, -1.2);
  EXPECT_NEAR(stats.sum_cos4, 1.2 + 0.9 + 1.5 * std::cos(4.0 * theta), 1e-12);
  EXPECT_NEAR(stats.sum_sin4, 1.5 * std::sin(4.0 * theta), 1e-12);
  EXPECT_NEAR(coloring.LogArakDensity(2.0),
              3.0 * std::log(2.0) - stats.sum_log_length + stats.sum_log_sin - 2.0 * 2.0 * 3.6,
              1e-12);
  ExpectBlackExactlyInside(coloring, triangle);
}

TEST(ColoringFromGraph, APolygonClippedByTheWindowEndsOnItsSide) {
  // The right side (1) cuts the polygon: two boundary vertices on x = 4, two interior ones.
  const Vec2 b0(4, 0.5), v1(3, 1), v2(3, 2), b3(4, 2.5);
  const std::vector<NewVertex> vertices = {{b0, 1}, {v1, kInterior}, {v2, kInterior}, {b3, 1}};
  const Edges edges = {{0, 1}, {1, 2}, {2, 3}};
  auto built = Build(vertices, edges);
  ASSERT_TRUE(std::holds_alternative<Coloring>(built)) << std::get<std::string>(built);
  const Coloring& coloring = std::get<Coloring>(built);
  EXPECT_FALSE(coloring.FindInvariantViolation());
  EXPECT_EQ(coloring.boundary_vertices().size(), 2u);
  EXPECT_EQ(coloring.interior_vertices().size(), 2u);
  const ColoringStats& stats = coloring.stats();
  EXPECT_EQ(stats.edges, 3);
  const double slanted = std::sqrt(1.25);
  EXPECT_NEAR(stats.total_length, 2.0 * slanted + 1.0, 1e-12);
  EXPECT_NEAR(stats.sum_log_length, 2.0 * std::log(slanted), 1e-12);
  // Boundary vertices: the angle to the side (direction (0, 1)); interior: between the edges.
  const Vec2 up = Vec2::UnitY();
  const double expected_log_sin = LogSinBetween(v1 - b0, up) + LogSinBetween(v2 - b3, up) +
                                  LogSinBetween(b0 - v1, v2 - v1) + LogSinBetween(v1 - v2, b3 - v2);
  EXPECT_LT(expected_log_sin, -0.1);  // far from the right angles that would give 0
  EXPECT_NEAR(stats.sum_log_sin, expected_log_sin, 1e-12);
  // The pocket between the polyline and the side is black, the rest white (the anchor's).
  const std::vector<Vec2> pocket = {b0, v1, v2, b3};
  EXPECT_EQ(coloring.ColourAt(Vec2(3.8, 1.5)), Colour::kBlack);
  EXPECT_EQ(coloring.ColourAt(Vec2(3.8, 0.2)), Colour::kWhite);
  ExpectBlackExactlyInside(coloring, pocket);
}

TEST(ColoringFromGraph, AnEmptyGraphIsTheAnchorsColourEverywhere) {
  auto built = Build({}, {}, Colour::kBlack);
  ASSERT_TRUE(std::holds_alternative<Coloring>(built));
  const Coloring& coloring = std::get<Coloring>(built);
  EXPECT_EQ(coloring.stats().edges, 0);
  EXPECT_EQ(coloring.ColourAt(Vec2(0.1, 0.1)), Colour::kBlack);
  EXPECT_EQ(coloring.ColourAt(Vec2(3.9, 2.9)), Colour::kBlack);
}

std::vector<NewVertex> Interior(const std::vector<Vec2>& points) {
  std::vector<NewVertex> vertices;
  for (const Vec2& p : points) vertices.push_back({p, kInterior});
  return vertices;
}

TEST(ColoringFromGraph, RefusesCrossingEdges) {
  // Two triangles, each valid alone, overlapping.
  const std::vector<NewVertex> vertices =
      Interior({{0.5, 0.5}, {2, 0.5}, {1, 2}, {1.5, 1}, {3, 1}, {2, 2.5}});
  Edges edges = Ring(0, 3);
  for (const auto& e : Ring(3, 3)) edges.push_back(e);
  ASSERT_TRUE(std::holds_alternative<Coloring>(
      Build(Interior({{0.5, 0.5}, {2, 0.5}, {1, 2}}), Ring(0, 3))));
  EXPECT_THAT(Refusal(vertices, edges), HasSubstr("cross"));
}

TEST(ColoringFromGraph, RefusesAnInteriorVertexOfDegreeOne) {
  // An open path: its two ends have one edge each.
  EXPECT_THAT(Refusal(Interior({{0.5, 0.5}, {2, 0.5}, {1, 2}}), {{0, 1}, {1, 2}}),
              HasSubstr("fewer than two edges"));
  // A vertex of degree three (a triangle with a tail).
  EXPECT_THAT(
      Refusal(Interior({{0.5, 0.5}, {2, 0.5}, {1, 2}, {3, 0.5}}), {{0, 1}, {1, 2}, {2, 0}, {1, 3}}),
      HasSubstr("more than 2 edges"));
}

TEST(ColoringFromGraph, RefusesAnInteriorVertexOutsideTheWindowOrOnItsBoundary) {
  EXPECT_THAT(Refusal(Interior({{0.5, 0.5}, {5, 0.5}, {1, 2}}), Ring(0, 3)),
              HasSubstr("interior vertex 1"));
  EXPECT_THAT(Refusal(Interior({{0.5, 0.5}, {4, 0.5}, {1, 2}}), Ring(0, 3)),
              HasSubstr("not inside the window"));
  EXPECT_THAT(Refusal(Interior({{0.5, 0.5}, {2, 0.5}, {1, std::nan("")}}), Ring(0, 3)),
              HasSubstr("interior vertex 2"));
}

TEST(ColoringFromGraph, RefusesEdgesThatDoNotJoinTwoOfTheVertices) {
  const std::vector<NewVertex> vertices = Interior({{0.5, 0.5}, {2, 0.5}, {1, 2}});
  EXPECT_THAT(Refusal(vertices, {{0, 1}, {1, 1}, {2, 0}}), HasSubstr("does not join"));
  EXPECT_THAT(Refusal(vertices, {{0, 1}, {1, 3}, {3, 0}}), HasSubstr("(1, 3)"));
  EXPECT_THAT(Refusal(vertices, {{0, 1}, {1, 2}, {2, -1}}), HasSubstr("does not join"));
  // Two edges between the same two vertices (a zero angle at both).
  EXPECT_THAT(Refusal(Interior({{0.5, 0.5}, {2, 0.5}}), {{0, 1}, {1, 0}}),
              AnyOf(HasSubstr("join the same vertices"), HasSubstr("zero angle")));
}

TEST(ColoringFromGraph, RefusesABoundaryVertexOffItsSide) {
  const Edges edges = {{0, 1}, {1, 2}, {2, 3}};
  // As in the clipped polygon above, but the first boundary vertex 0.1 m inside the window.
  EXPECT_THAT(
      Refusal({{{3.9, 0.5}, 1}, {{3, 1}, kInterior}, {{3, 2}, kInterior}, {{4, 2.5}, 1}}, edges),
      HasSubstr("boundary vertex 0 off its side"));
  // On the window's boundary, but on another side than the one given.
  EXPECT_THAT(
      Refusal({{{4, 0.5}, 0}, {{3, 1}, kInterior}, {{3, 2}, kInterior}, {{4, 2.5}, 1}}, edges),
      HasSubstr("off its side"));
  EXPECT_THAT(
      Refusal({{{4, 0.5}, 4}, {{3, 1}, kInterior}, {{3, 2}, kInterior}, {{4, 2.5}, 1}}, edges),
      HasSubstr("has side 4"));
  // A boundary vertex without an edge.
  EXPECT_THAT(Refusal({{{4, 0.5}, 1}}, {}), HasSubstr("boundary vertex 0 has no edge"));
}

}  // namespace
}  // namespace priormap::prf
