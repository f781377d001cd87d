// The true map of a simulated scene as a coloring (SceneColoring): its colours agree with the
// scene's ground truth (reachable free space white, the rest black) wherever a point is clear
// of the walls, whether the window holds the whole scene or cuts its walls; scenes whose
// surfaces do not bound regions are refused with a message.
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <priormap/core/rng.hpp>
#include <priormap/core/scene.hpp>
#include <priormap/core/scene_truth.hpp>
#include <priormap/prf/scene_coloring.hpp>

namespace priormap::prf {
namespace {

using ::testing::HasSubstr;

constexpr double kCell = 0.5;
// Closer to a wall the truth's 1 cm raster may give either colour.
constexpr double kWallClearance = 0.02;

SceneTruth TruthOf(const Scene& scene) {
  return SceneTruth(scene, scene.waypoints);
}

const Coloring& Accepted(const std::variant<Coloring, std::string>& built) {
  if (const auto* message = std::get_if<std::string>(&built))
    ADD_FAILURE() << "refused: " << *message;
  return std::get<Coloring>(built);
}

// Colours at random points of the window (away from the walls) against the truth; returns the
// numbers of black and white points compared, so that a caller can check both were exercised.
std::pair<int, int> ExpectAgreesWithTruth(const Coloring& coloring, const SceneTruth& truth,
                                          int points, std::uint64_t seed) {
  const Window& w = coloring.window();
  Rng rng(seed);
  int black = 0, white = 0;
  for (int i = 0; i < points; ++i) {
    const Vec2 q(rng.Uniform(w.min.x(), w.max.x()), rng.Uniform(w.min.y(), w.max.y()));
    if (truth.DistanceToWall(q) <= kWallClearance) continue;
    const bool occupied = truth.Occupied(q);
    EXPECT_EQ(coloring.ColourAt(q), occupied ? Colour::kBlack : Colour::kWhite)
        << "at (" << q.transpose() << ")";
    if (::testing::Test::HasFailure()) break;
    (occupied ? black : white) += 1;
  }
  return {black, white};
}

TEST(SceneColoring, TheRectangleIsWhiteInsideAndBlackOutside) {
  const Scene scene = *BuiltinScene("rectangle");  // walls at x = ±3, y = ±2
  const SceneTruth truth = TruthOf(scene);
  const Window window{Vec2(-4, -3), Vec2(4, 3)};
  const auto built = SceneColoring(scene, truth, window, kCell);
  const Coloring& coloring = Accepted(built);
  if (HasFailure()) return;
  EXPECT_FALSE(coloring.FindInvariantViolation());
  EXPECT_EQ(coloring.stats().edges, 4);
  EXPECT_TRUE(coloring.boundary_vertices().empty());
  EXPECT_NEAR(coloring.stats().total_length, 20.0, 1e-12);
  EXPECT_EQ(coloring.ColourAt(Vec2(0.5, 0.5)), Colour::kWhite);
  EXPECT_EQ(coloring.ColourAt(Vec2(3.5, 0.5)), Colour::kBlack);
  const auto [black, white] = ExpectAgreesWithTruth(coloring, truth, 3000, 1);
  EXPECT_GT(black, 300);
  EXPECT_GT(white, 300);
}

TEST(SceneColoring, AWindowThatCutsTheWallsEndsThemOnItsSides) {
  const Scene scene = *BuiltinScene("rectangle");
  const SceneTruth truth = TruthOf(scene);
  // Only the corner (3, 2) is inside: the right wall leaves through the bottom side at
  // (3, -1), the top wall through the left side at (-2, 2).
  const Window window{Vec2(-2, -1), Vec2(4, 3)};
  const auto built = SceneColoring(scene, truth, window, kCell);
  const Coloring& coloring = Accepted(built);
  if (HasFailure()) return;
  EXPECT_FALSE(coloring.FindInvariantViolation());
  EXPECT_EQ(coloring.stats().edges, 2);
  EXPECT_EQ(coloring.interior_vertices().size(), 1u);
  ASSERT_EQ(coloring.boundary_vertices().size(), 2u);
  std::vector<std::pair<int, Vec2>> ends;
  for (const VertexId v : coloring.boundary_vertices())
    ends.emplace_back(coloring.vertex(v).side, coloring.vertex(v).position);
  std::sort(ends.begin(), ends.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  EXPECT_EQ(ends[0].first, 0);
  EXPECT_EQ(ends[0].second, Vec2(3, -1));
  EXPECT_EQ(ends[1].first, 3);
  EXPECT_EQ(ends[1].second, Vec2(-2, 2));
  EXPECT_NEAR(coloring.stats().total_length, 3.0 + 5.0, 1e-12);
  const auto [black, white] = ExpectAgreesWithTruth(coloring, truth, 3000, 2);
  EXPECT_GT(black, 300);
  EXPECT_GT(white, 300);
}

TEST(SceneColoring, TheOfficeAgreesWithItsTruthWholeAndCut) {
  const Scene scene = *BuiltinScene("office");
  const SceneTruth truth = TruthOf(scene);
  // The whole scene (about 20 m by 10 m, centred), then a window that cuts the corridor and
  // several rooms (its sides pass through no point of the wall polyline).
  const Window whole{Vec2(-11, -6), Vec2(11, 6)};
  const Window cut{Vec2(-4.7, -2.9), Vec2(4.3, 2.6)};
  for (const Window& window : {whole, cut}) {
    SCOPED_TRACE(::testing::Message() << "window (" << window.min.transpose() << ") to ("
                                      << window.max.transpose() << ")");
    const auto built = SceneColoring(scene, truth, window, kCell);
    const Coloring& coloring = Accepted(built);
    if (HasFailure()) return;
    EXPECT_FALSE(coloring.FindInvariantViolation());
    const auto [black, white] = ExpectAgreesWithTruth(coloring, truth, 4000, 3);
    EXPECT_GT(black, 200);
    EXPECT_GT(white, 200);
  }
  const auto built = SceneColoring(scene, truth, cut, kCell);
  EXPECT_GE(std::get<Coloring>(built).boundary_vertices().size(), 8u);
}

// The colour of every point is the anchor's flipped once per wall crossed on the way: with the
// anchor on a wall, points on both sides cross nothing and take its colour. Such a window must
// be refused, or the anchor's colour must come out right on each side somehow.
TEST(SceneColoring, AWindowWhoseAnchorLiesOnAWallIsRefusedOrColouredRight) {
  const Scene scene = *BuiltinScene("rectangle");
  const SceneTruth truth = TruthOf(scene);
  // A window 8 m by 6 m whose anchor (at a fixed fraction of its size) is on the wall x = 3.
  const double fraction = Coloring(Window{Vec2::Zero(), Vec2(1, 1)}, kCell).anchor().x();
  double left = 3.0 - fraction * 8.0;
  Window window{Vec2(left, -3), Vec2(left + 8.0, 3)};
  for (int k = 0; k < 100 && Coloring(window, kCell).anchor().x() != 3.0; ++k) {
    left = std::nextafter(left, Coloring(window, kCell).anchor().x() > 3.0 ? -10.0 : 10.0);
    window = Window{Vec2(left, -3), Vec2(left + 8.0, 3)};
  }
  const Vec2 anchor = Coloring(window, kCell).anchor();
  ASSERT_EQ(anchor.x(), 3.0);
  ASSERT_LT(std::abs(anchor.y()), 2.0);  // on the wall, not on its line beyond it
  const auto built = SceneColoring(scene, truth, window, kCell);
  if (std::holds_alternative<std::string>(built)) return;  // refused: fine
  const auto [black, white] = ExpectAgreesWithTruth(std::get<Coloring>(built), truth, 2000, 4);
  EXPECT_GT(black + white, 1000);
}

TEST(SceneColoring, RefusesOpenPolylinesAndCircles) {
  const Scene corridor = *BuiltinScene("corridor");  // one open wall polyline
  const auto open =
      SceneColoring(corridor, TruthOf(corridor), Window{Vec2(-11, -2), Vec2(11, 2)}, kCell);
  ASSERT_TRUE(std::holds_alternative<std::string>(open));
  EXPECT_THAT(std::get<std::string>(open), HasSubstr("surface 0 is not a closed polyline"));

  const Scene circle = *BuiltinScene("circle");
  const auto round =
      SceneColoring(circle, TruthOf(circle), Window{Vec2(-3, -3), Vec2(3, 3)}, kCell);
  ASSERT_TRUE(std::holds_alternative<std::string>(round));
  EXPECT_THAT(std::get<std::string>(round), HasSubstr("surface 0 is not a closed polyline"));

  // Closed walls, then a bin (a circle) as the third surface.
  const Scene l_room = *BuiltinScene("l-room");
  const auto with_bin =
      SceneColoring(l_room, TruthOf(l_room), Window{Vec2(-4, -4), Vec2(4, 4)}, kCell);
  ASSERT_TRUE(std::holds_alternative<std::string>(with_bin));
  EXPECT_THAT(std::get<std::string>(with_bin), HasSubstr("surface 2"));
}

TEST(SceneColoring, RefusesCrossingWallsAndWallPointsOnTheWindowsBoundary) {
  Scene scene;
  scene.name = "crossing";
  const auto room = [](double x0, double y0, double x1, double y1) {
    return SceneSurface{Polyline{{{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}, true}, false, "room"};
  };
  scene.surfaces = {room(-2, -2, 1, 1), room(-1, -1, 2, 2)};
  scene.waypoints = {{-1.5, -1.5}, {0, 0}};
  const auto crossing =
      SceneColoring(scene, TruthOf(scene), Window{Vec2(-3, -3), Vec2(3, 3)}, kCell);
  ASSERT_TRUE(std::holds_alternative<std::string>(crossing));
  EXPECT_THAT(std::get<std::string>(crossing), HasSubstr("cross"));

  scene.surfaces = {room(-2, -2, 1, 1)};
  const auto on_boundary =
      SceneColoring(scene, TruthOf(scene), Window{Vec2(-3, -3), Vec2(1, 3)}, kCell);
  ASSERT_TRUE(std::holds_alternative<std::string>(on_boundary));
  EXPECT_THAT(std::get<std::string>(on_boundary), HasSubstr("window's boundary"));
}

}  // namespace
}  // namespace priormap::prf
