#include <gtest/gtest.h>

#include <priormap/core/scene.hpp>

namespace priormap {
namespace {

TEST(Scene, BuiltinsExistAndAreWellFormed) {
  const std::vector<std::string> names = BuiltinSceneNames();
  EXPECT_EQ(names, (std::vector<std::string>{"square", "rectangle", "circle", "two-circles",
                                             "l-room", "corridor", "office", "l-office"}));
  for (const std::string& name : names) {
    const std::optional<Scene> scene = BuiltinScene(name);
    ASSERT_TRUE(scene) << name;
    EXPECT_EQ(scene->name, name);
    EXPECT_TRUE(scene->Problems().empty()) << name;
    EXPECT_TRUE(scene->default_pose.has_value()) << name;
    EXPECT_GE(scene->waypoints.size(), 2u) << name;
    // Centred on the origin.
    EXPECT_TRUE(scene->Bounds().center().isZero(1e-9)) << name;
  }
  EXPECT_FALSE(BuiltinScene("no-such-scene"));
}

TEST(Scene, BuiltinSizesAreAsDocumented) {
  EXPECT_TRUE(BuiltinScene("square")->Bounds().sizes().isApprox(Vec2(4, 4)));
  EXPECT_TRUE(BuiltinScene("rectangle")->Bounds().sizes().isApprox(Vec2(6, 4)));
  EXPECT_TRUE(BuiltinScene("circle")->Bounds().sizes().isApprox(Vec2(4, 4)));
  const Scene two = *BuiltinScene("two-circles");
  ASSERT_EQ(two.surfaces.size(), 2u);
  EXPECT_NE(std::get<Circle>(two.surfaces[0].shape).radius,
            std::get<Circle>(two.surfaces[1].shape).radius);
  const Scene l_room = *BuiltinScene("l-room");
  EXPECT_TRUE(std::any_of(l_room.surfaces.begin(), l_room.surfaces.end(),
                          [](const SceneSurface& s) { return s.clutter; }));
}

TEST(Scene, PrimitivesNumberRegionsAndKeepSurfaceIds) {
  const Scene scene = *BuiltinScene("l-room");
  const std::vector<ScenePrimitive> primitives = scene.Primitives();
  ASSERT_EQ(primitives.size(), 6u + 4u + 1u);  // six walls, a four-sided box, a bin
  for (std::size_t i = 0; i < primitives.size(); ++i)
    EXPECT_EQ(primitives[i].region, static_cast<int>(i));
  EXPECT_EQ(primitives[0].surface, 0);
  EXPECT_EQ(primitives[6].surface, 1);
  EXPECT_TRUE(primitives[6].clutter);
  EXPECT_EQ(primitives[10].surface, 2);
  EXPECT_TRUE(std::holds_alternative<Circle>(primitives[10].shape));
}

TEST(Scene, ProblemsNameTheBrokenSurface) {
  Scene scene;
  scene.surfaces.push_back({Polyline{{{0, 0}, {0, 0}}, false}, false, ""});
  scene.surfaces.push_back({Circle{{0, 0}, -1.0}, false, ""});
  scene.surfaces.push_back({Polyline{{{0, 0}}, false}, false, ""});
  const std::vector<std::string> problems = scene.Problems();
  ASSERT_EQ(problems.size(), 3u);
  EXPECT_EQ(problems[0], "surface 0: segment 0 has zero length");
  EXPECT_EQ(problems[1], "surface 1: circle radius must be positive and finite");
  EXPECT_EQ(problems[2], "surface 2: a polyline needs at least 2 points");
}

}  // namespace
}  // namespace priormap
