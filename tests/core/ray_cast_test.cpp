#include <priormap/core/angles.hpp>
#include <priormap/core/ray_cast.hpp>
#include <priormap/core/scene_ray_caster.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace priormap {
namespace {

TEST(RayCast, SegmentHitHasRangeAndNormalFacingTheRay) {
  const Segment wall{{2, -1}, {2, 1}};
  const auto hit = CastRay(Ray{{0, 0}, 0.0}, wall);
  ASSERT_TRUE(hit);
  EXPECT_DOUBLE_EQ(hit->range, 2.0);
  EXPECT_NEAR(hit->normal_angle, kPi, 1e-12);  // points back at the origin
  // The same wall seen from the other side has the opposite normal.
  const auto back = CastRay(Ray{{4, 0}, kPi}, wall);
  ASSERT_TRUE(back);
  EXPECT_NEAR(back->normal_angle, 0.0, 1e-12);
}

TEST(RayCast, SegmentObliqueHit) {
  const Segment wall{{0, 2}, {4, 2}};
  const auto hit = CastRay(Ray{{0, 0}, kPi / 4}, wall);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->range, 2 * std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(hit->normal_angle, -kPi / 2, 1e-12);
}

TEST(RayCast, SegmentMisses) {
  const Segment wall{{2, -1}, {2, 1}};
  EXPECT_FALSE(CastRay(Ray{{0, 0}, kPi}, wall));        // behind
  EXPECT_FALSE(CastRay(Ray{{0, 0}, kPi / 2}, wall));    // parallel
  EXPECT_FALSE(CastRay(Ray{{0, 0}, 0.6}, wall));        // passes above the end (tan 0.6 * 2 > 1)
  EXPECT_FALSE(CastRay(Ray{{2, 0}, 0.0}, wall));        // starts on it and leaves
  EXPECT_TRUE(CastRay(Ray{{0, 0}, std::atan(0.499)}, wall));  // just inside the end point
}

TEST(RayCast, CircleFromOutsideAndInside) {
  const Circle pillar{{5, 0}, 1};
  const auto outside = CastRay(Ray{{0, 0}, 0.0}, pillar);
  ASSERT_TRUE(outside);
  EXPECT_DOUBLE_EQ(outside->range, 4.0);
  EXPECT_NEAR(outside->normal_angle, kPi, 1e-12);
  const auto inside = CastRay(Ray{{5, 0}, kPi / 2}, pillar);
  ASSERT_TRUE(inside);
  EXPECT_DOUBLE_EQ(inside->range, 1.0);
  EXPECT_NEAR(inside->normal_angle, -kPi / 2, 1e-12);  // towards the centre, i.e. the sensor side
  EXPECT_FALSE(CastRay(Ray{{0, 0}, kPi}, pillar));
  EXPECT_FALSE(CastRay(Ray{{0, 0}, 0.3}, pillar));  // sin(0.3) * 5 > 1: misses
}

TEST(RayCast, CircleNormalIsRadial) {
  const Circle room{{0, 0}, 2};
  std::mt19937_64 engine(11);
  std::uniform_real_distribution<double> angle(-kPi, kPi), offset(-1.0, 1.0);
  for (int i = 0; i < 200; ++i) {
    const Ray ray{{offset(engine), offset(engine)}, angle(engine)};
    const auto hit = CastRay(ray, room);
    ASSERT_TRUE(hit);
    const Vec2 point = ray.origin + hit->range * UnitVector(ray.angle);
    EXPECT_NEAR(point.norm(), 2.0, 1e-12);
    EXPECT_NEAR(AngleDifference(hit->normal_angle, std::atan2(-point.y(), -point.x())), 0.0, 1e-9);
    EXPECT_LT(UnitVector(hit->normal_angle).dot(UnitVector(ray.angle)), 0.0);
  }
}

// The scene caster must return exactly what a brute-force loop over the primitives returns.
TEST(SceneRayCaster, AgreesWithBruteForceOverPrimitives) {
  for (const std::string& name : BuiltinSceneNames()) {
    const Scene scene = *BuiltinScene(name);
    const SceneRayCaster caster(scene);
    std::mt19937_64 engine(5);
    std::uniform_real_distribution<double> angle(-kPi, kPi);
    const Vec2 origin = scene.default_pose->translation();
    for (int i = 0; i < 500; ++i) {
      const Ray ray{origin, angle(engine)};
      std::optional<RayHit> best;
      int best_region = -1;
      for (const ScenePrimitive& p : caster.primitives()) {
        const auto hit = std::visit([&](const auto& shape) { return CastRay(ray, shape); }, p.shape);
        if (hit && (!best || hit->range < best->range)) {
          best = hit;
          best_region = p.region;
        }
      }
      const auto hit = caster.Cast(ray, 1e9);
      ASSERT_EQ(hit.has_value(), best.has_value()) << name;
      if (!hit) continue;
      EXPECT_DOUBLE_EQ(hit->range, best->range) << name;
      EXPECT_DOUBLE_EQ(hit->normal_angle, best->normal_angle) << name;
      EXPECT_EQ(hit->region, best_region) << name;
    }
  }
}

TEST(SceneRayCaster, RespectsMaxRangeAndReportsIds) {
  const Scene scene = *BuiltinScene("square");
  const SceneRayCaster caster(scene);
  const auto hit = caster.Cast(Ray{{0, 0}, 0.0}, 10.0);
  ASSERT_TRUE(hit);
  EXPECT_DOUBLE_EQ(hit->range, 2.0);
  EXPECT_EQ(hit->surface, 0);
  EXPECT_EQ(hit->region, 1);  // the wall from (2,-2) to (2,2)
  EXPECT_FALSE(caster.Cast(Ray{{0, 0}, 0.0}, 1.5));
}

}  // namespace
}  // namespace priormap
