// The world's bound (kMaxWorldCoordinate, 1e9 m) on what the odometry does, not only on each of
// its rows: increments of 9e8 m pass the reader one by one, but two of them leave the world. The
// bicycle's controls are bounded as every other value read, the dead-reckoned trajectory is
// refused at the row that first leaves the world (the library, and `priormap slam run` before it
// filters anything), and the filter stops if its pose estimate leaves it all the same.
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <priormap/slam/prior_map_slam.hpp>
#include <priormap/slam/slam_io.hpp>

#include "testing/diagnostic_matchers.hpp"
#include "testing/process.hpp"
#include "testing/temp_dir.hpp"

namespace priormap::slam {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::Matcher;

Matcher<const Diagnostic&> At(const std::string& file, int line, int col,
                              const std::string& message_part) {
  return testing::DiagnosticAt(file, line, col, message_part);
}

std::vector<Diagnostic> OdometryErrors(const std::string& text) {
  const auto result = ParseOdometryCsv(text, "odom.csv");
  EXPECT_FALSE(result.ok()) << "parsed without error:\n" << text;
  return result.diagnostics();
}

Odometry Read(const std::string& text) {
  auto result = ParseOdometryCsv(text, "odom.csv");
  EXPECT_TRUE(result.ok()) << result.error();
  return std::move(result).value();
}

TEST(OdometryWorldBound, ABicycleSpeedIsBoundedAsEveryValueRead) {
  EXPECT_THAT(OdometryErrors("time,speed,steer\n0,1,0\n1,2e9,0\n2,1,0\n"),
              ElementsAre(At("odom.csv", 3, 3,
                             "speed must be at most 1e+09 m/s in magnitude (the bound of world "
                             "coordinates, per second), found '2e9'")));
  // The last row's controls are not used, but they are read and bounded as the others.
  EXPECT_THAT(OdometryErrors("time,speed,steer\n0,1,0\n1,-1e300,0\n"),
              ElementsAre(At("odom.csv", 3, 3, "speed must be at most 1e+09 m/s")));
}

TEST(OdometryWorldBound, ASteeringAngleIsWithinPlusMinusPiAsDtheta) {
  EXPECT_THAT(OdometryErrors("time,speed,steer\n0,1,30\n1,1,0\n"),
              ElementsAre(At("odom.csv", 2, 5,
                             "steer must be in [-pi, pi] rad, found '30' "
                             "(degrees?)")));
  const Odometry edge = Read("time,speed,steer\n0,1,-3.141592653589793\n1,1,0\n");
  EXPECT_EQ(std::get<BicycleControl>(edge.steps[0].motion).steer, -std::numbers::pi);
}

TEST(OdometryWorldBound, ASpeedHeldLongerThanTheWorldIsWideIsRefusedAtItsRow) {
  // 1e9 m/s is allowed, but held for 2 s it covers 2e9 m in one step (as a dx of 2e9 m would);
  // held for 1e300 s the distance is not even finite.
  EXPECT_THAT(OdometryErrors("time,speed,steer\n0,1,0\n1,1e9,0\n3,0,0\n"),
              ElementsAre(At("odom.csv", 3, 3,
                             "speed 1000000000 m/s held from t = 1 to t = 3 (line 4) covers "
                             "2000000000 m in one step, more than 1e+09 m")));
  EXPECT_THAT(OdometryErrors("time,speed,steer\n0,1e9,0\n1e300,0,0\n"),
              ElementsAre(At("odom.csv", 2, 3, "covers inf m in one step")));
  // Exactly the bound is within it.
  EXPECT_EQ(Read("time,speed,steer\n0,1e9,0\n1,0,0\n").steps.size(), 1u);
}

TEST(OdometryWorldBound, StepsKeepTheCellTheirMotionWasReadFrom) {
  const Odometry bicycle = Read("time,steer,speed\n# start\n0,0,5\n1,0.1,6\n2,0,0\n");
  ASSERT_EQ(bicycle.steps.size(), 2u);
  EXPECT_EQ(bicycle.steps[0].line, 3);  // the controls of line 3, held until line 4's time
  EXPECT_EQ(bicycle.steps[0].col, 5);
  EXPECT_EQ(bicycle.steps[1].line, 4);
  const Odometry increments = Read("time,dx,dy,dtheta\n0,0,0,0\n1,1,0,0\n2,1,0,0\n");
  ASSERT_EQ(increments.steps.size(), 2u);
  EXPECT_EQ(increments.steps[0].line, 3);
  EXPECT_EQ(increments.steps[0].col, 3);
  EXPECT_EQ(increments.steps[1].line, 4);
}

// The brief's case: rows of 9e8 m each, 1.8e9 m together.
constexpr const char* kTwoLongIncrements =
    "time,dx,dy,dtheta\n0,0,0,0\n1,9e8,0,0\n2,9e8,0,0\n3,1,0,0\n";

TEST(OdometryWorldBound, TheRowThatFirstTakesThePoseBeyondTheWorldIsReported) {
  const Odometry odometry = Read(kTwoLongIncrements);  // each row is within the bound
  const std::optional<Diagnostic> beyond =
      FirstPoseBeyondWorld(Se2(0.0, 0.0, 0.0), odometry, 4.0, "odom.csv");
  ASSERT_TRUE(beyond.has_value());
  EXPECT_THAT(*beyond, At("odom.csv", 4, 3,
                          "this row's motion takes the pose from (900000000, 0) to (1800000000, "
                          "0) m at t = 2 s, beyond 1e+09 m in x or y (the bound of world "
                          "coordinates): the odometry dead-reckoned from the initial pose (0, 0) "
                          "leaves the world"));
}

TEST(OdometryWorldBound, WhetherTheOdometryLeavesTheWorldDependsOnTheStartPose) {
  const Odometry odometry = Read(kTwoLongIncrements);
  // From x = -9e8 the same rows end at 9e8 + 1 m: within the world.
  EXPECT_FALSE(FirstPoseBeyondWorld(Se2(-9e8, 0.0, 0.0), odometry, 4.0, "o").has_value());
  // Heading north, they leave it in y.
  const auto north = FirstPoseBeyondWorld(Se2(0.0, 5e8, std::numbers::pi / 2), odometry, 4.0, "o");
  ASSERT_TRUE(north.has_value());
  EXPECT_EQ(north->line, 3);
}

TEST(OdometryWorldBound, BicycleOdometryIsDeadReckonedWithTheWheelbase) {
  // 5e8 m per row: 5e8, then 1e9 (on the bound, within), then 1.5e9 m with line 4's controls.
  const Odometry fast = Read("time,speed,steer\n0,5e8,0\n1,5e8,0\n2,5e8,0\n3,0,0\n");
  const auto beyond = FirstPoseBeyondWorld(Se2(), fast, 4.0, "bike.csv");
  ASSERT_TRUE(beyond.has_value());
  EXPECT_THAT(*beyond, At("bike.csv", 4, 3, "to (1500000000, 0) m at t = 3 s"));
  // Forwards, backwards, forwards: never beyond 5e8 m, though 1.5e9 m are driven.
  const Odometry back = Read("time,speed,steer\n0,5e8,0\n1,-5e8,0\n2,5e8,0\n3,0,0\n");
  EXPECT_FALSE(FirstPoseBeyondWorld(Se2(), back, 4.0, "bike.csv").has_value());
}

TEST(OdometryWorldBound, TheFilterStopsWhenItsPoseLeavesTheWorld) {
  SlamInput input;
  input.motion = Read(kTwoLongIncrements).steps;
  input.frames.push_back({3.0, {{0, 5.0, 0.0}}});
  SlamOptions options;
  options.use_prior_map = false;
  try {
    (void)RunSlam(input, nullptr, options);
    ADD_FAILURE() << "no SlamDiverged";
  } catch (const SlamDiverged& e) {
    EXPECT_THAT(e.what(), HasSubstr("the filter's pose left the world after the motion step read "
                                    "at line 4 at t = 2 s: (1800000000, 0) m, beyond 1e+09 m"));
  }
  // Within the world it runs.
  input.initial_pose = Se2(-9e8, 0.0, 0.0);
  EXPECT_EQ(RunSlam(input, nullptr, options).frames.size(), 1u);
}

// `priormap slam run` refuses such odometry before filtering, at file:line:col, and writes nothing.
TEST(OdometryWorldBound, SlamRunRefusesOdometryThatLeavesTheWorldAtItsRow) {
  const priormap::testing::TempDir work, io;
  priormap::testing::WriteAll(work / "odo.csv", kTwoLongIncrements);
  priormap::testing::WriteAll(work / "obs.csv", "time,id,range,bearing\n2,0,5,0.5\n3,0,5,0.6\n");
  const auto run = [&](const std::string& initial_pose) {
    return priormap::testing::RunProgram(
        PRIORMAP_BINARY, work.path(), io.path(),
        {"slam", "run", "--observations", "obs.csv", "--odometry", "odo.csv", "--no-prior",
         "--no-figures", "--initial-pose=" + initial_pose, "-o", "out"});
  };
  const priormap::testing::ProcessResult refused = run("0,0,0");
  EXPECT_EQ(refused.status, 1);
  EXPECT_THAT(refused.err, HasSubstr("odo.csv:4:3: this row's motion takes the pose from "
                                     "(900000000, 0) to (1800000000, 0) m at t = 2 s, beyond "
                                     "1e+09 m in x or y"));
  EXPECT_FALSE(std::filesystem::exists(work / "out"));
  const priormap::testing::ProcessResult within = run("-9e8,0,0");
  EXPECT_EQ(within.status, 0) << within.err;
}

}  // namespace
}  // namespace priormap::slam
