// What the sonar model's outlier mixture and corner reflectors need of a view: whether each
// corner is seen from inside (SonarFeature::concave) and the share of the cone that sees a
// face within R (SonarView::seen_fraction), on hand cases and, for corners, against an
// independent angle computation on Arak samples; both independent of the segments' order.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include <priormap/prf/coloring.hpp>
#include <priormap/prf/sampler.hpp>
#include <priormap/prf/sonar_visibility.hpp>

#include "cone_testing.hpp"

namespace priormap::prf {
namespace {

constexpr double kPi = std::numbers::pi;
const Window& kWindow = kConeTestWindow;

std::vector<SonarFeature> Corners(const SonarView& view) {
  std::vector<SonarFeature> corners;
  for (const SonarFeature& f : view.features)
    if (f.kind == SonarFeature::Kind::kCorner) corners.push_back(f);
  return corners;
}

// The apex on the axis at the origin, looking along +x; corners at (3, 0).
const SonarCone kCone = Cone(Vec2::Zero(), 0.0, 0.3, 5.0);

TEST(SonarCorners, AnInsideCornerFacingTheApexIsConcave) {
  // A V opening towards the apex: its arms leave the cone before their far ends.
  const std::vector<Segment> v_shape = {{Vec2(3, 0), Vec2(1.5, 1.5)},
                                        {Vec2(3, 0), Vec2(1.5, -1.5)}};
  const SonarView view = ViewOf(kCone, v_shape);
  const auto corners = Corners(view);
  ASSERT_EQ(corners.size(), 1u);
  EXPECT_NEAR(corners[0].distance, 3.0, 1e-12);
  EXPECT_TRUE(corners[0].concave);
}

TEST(SonarCorners, TheTipOfAWedgePointingAtTheApexIsNotConcave) {
  const std::vector<Segment> wedge = {{Vec2(3, 0), Vec2(4.5, 1.5)}, {Vec2(3, 0), Vec2(4.5, -1.5)}};
  const auto corners = Corners(ViewOf(kCone, wedge));
  ASSERT_EQ(corners.size(), 1u);
  EXPECT_NEAR(corners[0].distance, 3.0, 1e-12);
  EXPECT_FALSE(corners[0].concave);
  // Seen from the side, along one arm's outside: the apex outside the sector, still not
  // concave. Seen from behind the tip, inside the sector: concave.
  const auto from_side = Corners(ViewOf(Cone(Vec2(3, -3), kPi / 2, 0.3, 5.0), wedge));
  ASSERT_EQ(from_side.size(), 1u);
  EXPECT_NEAR(from_side[0].distance, 3.0, 1e-12);
  EXPECT_FALSE(from_side[0].concave);
  const SonarCone behind = Cone(Vec2(6, 0), kPi, 0.3, 5.0);
  const auto from_behind = Corners(ViewOf(behind, wedge));
  ASSERT_EQ(from_behind.size(), 1u);
  EXPECT_TRUE(from_behind[0].concave);
}

TEST(SonarCorners, ACornerWithoutItsSecondEdgeAmongTheSegmentsIsNotConcave) {
  // The V above with one arm left out: the vertex is a free end of the other.
  const std::vector<Segment> one_arm = {{Vec2(3, 0), Vec2(1.5, 1.5)}};
  const auto corners = Corners(ViewOf(kCone, one_arm));
  ASSERT_EQ(corners.size(), 1u);
  EXPECT_FALSE(corners[0].concave);
  // A straight vertex (two collinear edges) spans no sector either.
  const std::vector<Segment> straight = {{Vec2(3, -1), Vec2(3, 0.1)}, {Vec2(3, 0.1), Vec2(3, 1)}};
  const auto flat = Corners(ViewOf(kCone, straight));
  ASSERT_EQ(flat.size(), 1u);
  EXPECT_FALSE(flat[0].concave);
}

// The angle between directions u1 and u2, in [0, pi] (atan2: accurate near 0 and pi too).
double AngleBetween(const Vec2& u1, const Vec2& u2) {
  return std::atan2(std::abs(Cross(u1, u2)), u1.dot(u2));
}

struct ExpectedCorner {
  double distance = 0.0;
  bool concave = false;
  bool either = false;  // the apex (nearly) on an edge's line, or a straight vertex
};

TEST(SonarCorners, ConcaveMatchesTheAnglesAtEachVertexOfArakSamples) {
  // Each interior vertex of a coloring has exactly two edges, so every visible corner is
  // concave or not; the apex is inside the sector of the two edges exactly when the angles
  // from each edge to the apex add up to the angle between them.
  const Window& window = kArakSampleWindow;
  const Coloring coloring = DenseArakSample(31);
  std::vector<TaggedSegment> segments;
  for (EdgeId e : coloring.edge_ids()) segments.push_back({coloring.EdgeSegment(e), e});
  std::mt19937_64 random(7);
  ConeSweep sweep;
  SonarView view;
  int concave = 0, convex = 0;
  for (int trial = 0; trial < 150; ++trial) {
    const SonarCone cone = RandomCone(random, 0.05, 0.4);
    sweep.Compute(cone, segments, window, &view);
    std::vector<ExpectedCorner> expected;
    for (const Vec2& corner : view.corners) {
      VertexId vertex = kNoVertex;
      for (VertexId v : coloring.interior_vertices())
        if (coloring.vertex(v).position == corner) vertex = v;
      ASSERT_NE(vertex, kNoVertex) << "a corner that is no interior vertex";
      const ColoringVertex& cv = coloring.vertex(vertex);
      const Vec2 u1 = coloring.vertex(coloring.Other(cv.edges[0], vertex)).position - corner;
      const Vec2 u2 = coloring.vertex(coloring.Other(cv.edges[1], vertex)).position - corner;
      const Vec2 w = cone.origin - corner;
      const double a1 = AngleBetween(u1, w), a2 = AngleBetween(w, u2), span = AngleBetween(u1, u2);
      expected.push_back({.distance = w.norm(),
                          .concave = a1 + a2 - span < 1e-9,
                          .either = std::min({a1, a2, kPi - span}) < 1e-7});
    }
    std::vector<SonarFeature> actual = Corners(view);
    ASSERT_EQ(actual.size(), expected.size()) << "trial " << trial;
    std::sort(expected.begin(), expected.end(),
              [](const auto& a, const auto& b) { return a.distance < b.distance; });
    // Features come in depth order already.
    for (std::size_t k = 0; k < expected.size(); ++k) {
      ASSERT_NEAR(actual[k].distance, expected[k].distance, 1e-9) << "trial " << trial;
      if (expected[k].either) continue;
      ASSERT_EQ(actual[k].concave, expected[k].concave)
          << "trial " << trial << ", corner at distance " << expected[k].distance;
      (expected[k].concave ? concave : convex) += 1;
    }
  }
  // Both kinds were seen often.
  EXPECT_GT(concave, 20);
  EXPECT_GT(convex, 20);
}

TEST(SonarSeenFraction, IsOneForAWallAcrossTheConeAndZeroForNothing) {
  EXPECT_EQ(ViewOf(kCone, {{Vec2(2, -3), Vec2(2, 3)}}).seen_fraction, 1.0);
  const SonarView empty = ViewOf(kCone, {});
  EXPECT_EQ(empty.seen_fraction, 0.0);
  EXPECT_EQ(empty.extent, kCone.max_range);
  // A wall wholly beyond R is not seen either.
  EXPECT_EQ(ViewOf(kCone, {{Vec2(6, -3), Vec2(6, 3)}}).seen_fraction, 0.0);
}

TEST(SonarSeenFraction, IsTheShareOfTheConesAngleThatMeetsAFaceWithinR) {
  const double h = kCone.half_spread;
  // A wall at x = 2 from y = -0.2 upwards: seen from angle atan(-0.1) to h.
  EXPECT_NEAR(ViewOf(kCone, {{Vec2(2, -0.2), Vec2(2, 3)}}).seen_fraction,
              (h + std::atan(0.1)) / (2.0 * h), 1e-12);
  // Two pieces with a gap between them: the gap, atan(0.1) - atan(-0.05), is not seen.
  EXPECT_NEAR(
      ViewOf(kCone, {{Vec2(2, -3), Vec2(2, -0.1)}, {Vec2(2, 0.2), Vec2(2, 3)}}).seen_fraction,
      1.0 - (std::atan(0.1) + std::atan(0.05)) / (2.0 * h), 1e-12);
  // A wall across the cone but partly beyond R: seen where 4.5 / cos(psi) <= R.
  const SonarCone short_cone = Cone(Vec2::Zero(), 0.0, h, 4.6);
  EXPECT_NEAR(ViewOf(short_cone, {{Vec2(4.5, -3), Vec2(4.5, 3)}}).seen_fraction,
              std::acos(4.5 / 4.6) / h, 1e-9);
  // Turned and moved, the same geometry gives the same share.
  const double turn = 2.1;
  const Vec2 shift(1.3, -0.7);
  const auto moved = [&](const Vec2& p) {
    return Vec2(shift + p.x() * UnitVector(turn) + p.y() * Perp(UnitVector(turn)));
  };
  EXPECT_NEAR(
      ViewOf(Cone(shift, turn, h, 5.0), {{moved(Vec2(2, -0.2)), moved(Vec2(2, 3))}}).seen_fraction,
      (h + std::atan(0.1)) / (2.0 * h), 1e-9);
}

TEST(SonarView, DoesNotDependOnTheOrderOfSegmentsConcaveCornersIncluded) {
  const Window& window = kArakSampleWindow;
  const Coloring coloring = DenseArakSample(32);
  std::vector<TaggedSegment> segments;
  for (EdgeId e : coloring.edge_ids()) segments.push_back({coloring.EdgeSegment(e), e});
  std::mt19937_64 random(8);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  ConeSweep sweep;
  SonarView first, second;
  int concave = 0, partial = 0;
  for (int trial = 0; trial < 100; ++trial) {
    const SonarCone cone = RandomCone(random, 0.05, 0.4);
    sweep.Compute(cone, segments, window, &first);
    std::vector<TaggedSegment> shuffled = segments;
    std::shuffle(shuffled.begin(), shuffled.end(), random);
    for (TaggedSegment& t : shuffled)
      if (unit(random) < 0.5) std::swap(t.segment.a, t.segment.b);
    sweep.Compute(cone, shuffled, window, &second);
    SCOPED_TRACE(::testing::Message() << "trial " << trial);
    ASSERT_EQ(first.features.size(), second.features.size());
    for (std::size_t f = 0; f < first.features.size(); ++f) {
      EXPECT_EQ(first.features[f].kind, second.features[f].kind);
      EXPECT_EQ(first.features[f].distance, second.features[f].distance);
      EXPECT_EQ(first.features[f].projection, second.features[f].projection);
      EXPECT_EQ(first.features[f].subtended, second.features[f].subtended);
      EXPECT_EQ(first.features[f].concave, second.features[f].concave);
      concave += first.features[f].concave ? 1 : 0;
    }
    EXPECT_EQ(first.seen_fraction, second.seen_fraction);
    EXPECT_EQ(first.extent, second.extent);
    EXPECT_EQ(first.corners, second.corners);
    EXPECT_EQ(first.contact_tags, second.contact_tags);
    partial += (first.seen_fraction > 0.0 && first.seen_fraction < 1.0) ? 1 : 0;
    if (HasFailure()) return;
  }
  EXPECT_GT(concave, 10);
  EXPECT_GT(partial, 5);
}

}  // namespace
}  // namespace priormap::prf
