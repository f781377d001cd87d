#include <random>

#include <gtest/gtest.h>

#include <priormap/core/check.hpp>
#include <priormap/core/circle.hpp>
#include <priormap/core/polygon.hpp>
#include <priormap/core/polyline.hpp>
#include <priormap/core/segment.hpp>

#include "testing/numeric_diff.hpp"

namespace priormap {
namespace {

using testing::NumericJacobian;

TEST(Segment, ClosestPointClampsToTheEnds) {
  const Segment s{{0, 0}, {2, 0}};
  double t = -1;
  EXPECT_TRUE(ClosestPointOnSegment(s, {1, 1}, &t).isApprox(Vec2(1, 0)));
  EXPECT_DOUBLE_EQ(t, 0.5);
  EXPECT_TRUE(ClosestPointOnSegment(s, {-1, 1}, &t).isApprox(Vec2(0, 0)));
  EXPECT_DOUBLE_EQ(t, 0.0);
  EXPECT_TRUE(ClosestPointOnSegment(s, {5, -1}, &t).isApprox(Vec2(2, 0)));
  EXPECT_DOUBLE_EQ(t, 1.0);
  EXPECT_DOUBLE_EQ(PointSegmentDistance({1, 1}, s), 1.0);
  EXPECT_DOUBLE_EQ(PointSegmentDistance({3, 0}, s), 1.0);
  EXPECT_DOUBLE_EQ(PointSegmentDistance({1, 0}, s), 0.0);
}

TEST(Segment, DegenerateSegmentActsAsAPoint) {
  const Segment s{{1, 1}, {1, 1}};
  EXPECT_DOUBLE_EQ(PointSegmentDistance({4, 5}, s), 5.0);
  EXPECT_TRUE(s.Direction().isZero());
}

TEST(Segment, DistanceJacobianMatchesNumeric) {
  const Segment s{{-1, 0.5}, {2, 1.5}};
  for (const Vec2& p : {Vec2(0.3, 2.0), Vec2(-3.0, 0.0), Vec2(5.0, 4.0), Vec2(1.0, -1.0)}) {
    Row2 J;
    (void)PointSegmentDistance(p, s, &J);
    const Eigen::MatrixXd numeric = NumericJacobian(
        [&](const Eigen::VectorXd& v) -> Eigen::VectorXd {
          return Eigen::VectorXd::Constant(1, PointSegmentDistance(v, s));
        },
        p);
    EXPECT_TRUE(testing::JacobiansMatch(J, numeric));
  }
}

TEST(Segment, SignedLineDistanceIsPositiveOnTheLeft) {
  EXPECT_DOUBLE_EQ(SignedLineDistance({0, 1}, {0, 0}, {1, 0}), 1.0);
  EXPECT_DOUBLE_EQ(SignedLineDistance({5, -2}, {0, 0}, {1, 0}), -2.0);
  EXPECT_THROW((void)SignedLineDistance({0, 1}, {1, 1}, {1, 1}), ContractError);
}

TEST(Segment, SignedLineDistanceJacobiansMatchNumeric) {
  std::mt19937_64 engine(3);
  std::uniform_real_distribution<double> u(-5, 5);
  for (int trial = 0; trial < 50; ++trial) {
    const Vec2 p(u(engine), u(engine)), a(u(engine), u(engine)), b(u(engine), u(engine));
    if ((b - a).norm() < 0.5) continue;
    Row2 J_p, J_a, J_b;
    (void)SignedLineDistance(p, a, b, &J_p, &J_a, &J_b);
    Eigen::VectorXd x(6);
    x << p, a, b;
    const Eigen::MatrixXd numeric = NumericJacobian(
        [](const Eigen::VectorXd& v) -> Eigen::VectorXd {
          return Eigen::VectorXd::Constant(
              1, SignedLineDistance(v.segment<2>(0), v.segment<2>(2), v.segment<2>(4)));
        },
        x);
    EXPECT_TRUE(testing::JacobiansMatch(J_p, numeric.block<1, 2>(0, 0)));
    EXPECT_TRUE(testing::JacobiansMatch(J_a, numeric.block<1, 2>(0, 2)));
    EXPECT_TRUE(testing::JacobiansMatch(J_b, numeric.block<1, 2>(0, 4)));
  }
}

TEST(Segment, IntersectionOfCrossingSegments) {
  const auto hit = IntersectSegments({{0, 0}, {2, 2}}, {{0, 2}, {2, 0}});
  ASSERT_TRUE(hit);
  EXPECT_TRUE(hit->isApprox(Vec2(1, 1)));
  EXPECT_FALSE(IntersectSegments({{0, 0}, {1, 0}}, {{0, 1}, {1, 1}}));  // parallel
  EXPECT_FALSE(
      IntersectSegments({{0, 0}, {1, 0}}, {{2, -1}, {2, 1}}));         // would meet beyond the end
  EXPECT_TRUE(IntersectSegments({{0, 0}, {1, 0}}, {{1, 0}, {1, 1}}));  // shared endpoint
}

TEST(Segment, ClippedToABoxKeepsThePartInside) {
  const Box2 box(Vec2(0, 0), Vec2(4, 2));
  const auto across = ClipSegmentToBox({{-2, 1}, {6, 1}}, box);  // through both sides
  ASSERT_TRUE(across);
  EXPECT_TRUE(across->a.isApprox(Vec2(0, 1)));
  EXPECT_TRUE(across->b.isApprox(Vec2(4, 1)));
  const auto half = ClipSegmentToBox({{1, 1}, {1, 5}}, box);  // from inside out through the top
  ASSERT_TRUE(half);
  EXPECT_EQ(half->a, Vec2(1, 1));
  EXPECT_TRUE(half->b.isApprox(Vec2(1, 2)));
  const Segment inside{{1, 0.5}, {3, 1.5}};
  const auto whole = ClipSegmentToBox(inside, box);
  ASSERT_TRUE(whole);
  EXPECT_EQ(whole->a, inside.a);
  EXPECT_EQ(whole->b, inside.b);
  EXPECT_FALSE(ClipSegmentToBox({{5, 0}, {6, 2}}, box));          // beside it
  EXPECT_FALSE(ClipSegmentToBox({{-1, 3}, {5, 3}}, box));         // parallel, above
  EXPECT_FALSE(ClipSegmentToBox({{3, 4}, {6, 1}}, box));          // past the corner
  const auto touching = ClipSegmentToBox({{3, 3}, {5, 1}}, box);  // through the corner (4, 2)
  ASSERT_TRUE(touching);
  EXPECT_TRUE(touching->a.isApprox(touching->b));
}

TEST(Polyline, SegmentsLengthAndDistance) {
  const Polyline open{{{0, 0}, {3, 0}, {3, 4}}, false};
  EXPECT_EQ(open.NumSegments(), 2u);
  EXPECT_DOUBLE_EQ(open.Length(), 7.0);
  Polyline closed = open;
  closed.closed = true;
  EXPECT_EQ(closed.NumSegments(), 3u);
  EXPECT_DOUBLE_EQ(closed.Length(), 12.0);
  std::size_t index = 99;
  EXPECT_DOUBLE_EQ(open.Distance({4, 2}, &index), 1.0);
  EXPECT_EQ(index, 1u);
  EXPECT_THROW((void)open.segment(2), ContractError);
  EXPECT_EQ((Polyline{{{1, 1}}, false}.NumSegments()), 0u);
}

TEST(Polygon, AreaPerimeterCentroidOfARectangle) {
  const Polygon ccw{{{0, 0}, {4, 0}, {4, 2}, {0, 2}}};
  EXPECT_DOUBLE_EQ(ccw.SignedArea(), 8.0);
  EXPECT_DOUBLE_EQ(ccw.Perimeter(), 12.0);
  EXPECT_TRUE(ccw.Centroid().isApprox(Vec2(2, 1)));
  const Polygon cw{{{0, 0}, {0, 2}, {4, 2}, {4, 0}}};
  EXPECT_DOUBLE_EQ(cw.SignedArea(), -8.0);
  EXPECT_DOUBLE_EQ(cw.Area(), 8.0);
}

TEST(Polygon, ContainsFollowsTheEvenOddRuleOnAnLShape) {
  const Polygon l{{{-3, -3}, {3, -3}, {3, 0}, {0, 0}, {0, 3}, {-3, 3}}};
  EXPECT_TRUE(l.Contains({-1, -1}));
  EXPECT_TRUE(l.Contains({2, -1}));
  EXPECT_TRUE(l.Contains({-1, 2}));
  EXPECT_FALSE(l.Contains({1, 1}));  // the missing quadrant
  EXPECT_FALSE(l.Contains({5, 5}));
  EXPECT_DOUBLE_EQ(l.Area(), 27.0);
  EXPECT_TRUE(l.IsSimple());
}

TEST(Polygon, BowTieIsNotSimple) {
  EXPECT_FALSE((Polygon{{{0, 0}, {2, 2}, {2, 0}, {0, 2}}}).IsSimple());
  EXPECT_FALSE((Polygon{{{0, 0}, {1, 0}}}).IsSimple());
}

TEST(Circle, ClosestPointAndDistance) {
  const Circle c{{1, 1}, 2};
  EXPECT_TRUE(c.ClosestPoint({5, 1}).isApprox(Vec2(3, 1)));
  EXPECT_DOUBLE_EQ(c.DistanceToBoundary({5, 1}), 2.0);
  EXPECT_DOUBLE_EQ(c.DistanceToBoundary({1, 1}), 2.0);
  EXPECT_TRUE(c.Contains({2, 2}));
  EXPECT_FALSE(c.Contains({4, 4}));
  EXPECT_TRUE(c.Bounds().min().isApprox(Vec2(-1, -1)));
}

}  // namespace
}  // namespace priormap
