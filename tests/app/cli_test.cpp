// End-to-end tests of the priormap executable: each test runs it in a fresh directory and checks
// the exit status, what it printed and the files it wrote.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <sys/wait.h>
#include <vector>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <priormap/core/angles.hpp>
#include <priormap/core/carmen_io.hpp>
#include <priormap/core/json_io.hpp>
#include <priormap/core/log_io.hpp>
#include <priormap/core/scene.hpp>
#include <priormap/core/scene_ray_caster.hpp>
#include <priormap/core/simulate.hpp>

#include "cli_fixture.hpp"
#include "testing/temp_dir.hpp"

namespace priormap {
namespace {

namespace fs = std::filesystem;
using priormap::testing::ReadAll;
using priormap::testing::TempDir;
using priormap::testing::WriteAll;
using ::testing::ContainsRegex;
using ::testing::HasSubstr;
using ::testing::MatchesRegex;
using ::testing::Not;
using ::testing::StartsWith;

using RunResult = priormap::testing::ProcessResult;

class Cli : public priormap::testing::CliFixture {
 protected:
  /// Runs and expects success with nothing on stderr.
  RunResult Ok(const std::vector<std::string>& args) const {
    RunResult r = Run(args);
    EXPECT_EQ(r.status, 0) << "stdout:\n" << r.out << "stderr:\n" << r.err;
    EXPECT_EQ(r.err, "");
    return r;
  }

  /// Runs and expects success with nothing on stderr but the warning that a CARMEN output cannot
  /// hold `losses` (a substring: "the ground truth of 1 scan", ...).
  RunResult OkLosingToCarmen(const std::vector<std::string>& args,
                             const std::string& losses) const {
    RunResult r = Run(args);
    EXPECT_EQ(r.status, 0) << "stdout:\n" << r.out << "stderr:\n" << r.err;
    EXPECT_THAT(r.err, StartsWith("priormap: warning: "));
    EXPECT_THAT(r.err, HasSubstr(": CARMEN cannot hold "));
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_THAT(r.err, HasSubstr(losses));
    return r;
  }

  /// Runs, expects a failure reported on stderr, and that the working directory is unchanged
  /// (no output file, no temporary file).
  RunResult Fails(const std::vector<std::string>& args) const {
    RunResult r = RunFailing(args);
    EXPECT_NE(r.status, 0) << "stdout:\n" << r.out;
    EXPECT_NE(r.status, -1);
    return r;
  }

  [[nodiscard]] Log ReadLogFile(const std::string& name) const {
    Result<Log> log = ReadLog(Work(name));
    EXPECT_TRUE(log.ok()) << log.error();
    return log.ok() ? std::move(log).value() : Log{};
  }
};

using priormap::testing::IsPng;

// Width and height from the PNG's IHDR chunk (big-endian, right after the signature).
std::pair<int, int> PngSize(const std::string& bytes) {
  const auto be32 = [&](std::size_t at) {
    int v = 0;
    for (std::size_t i = 0; i < 4; ++i) v = (v << 8) | static_cast<unsigned char>(bytes.at(at + i));
    return v;
  };
  return {be32(16), be32(20)};
}

// --- simulate ----------------------------------------------------------------------------------

// The README's example: a square room seen from its default pose, whose nearest wall (1 m away,
// where the utm30's beams are 4 mm apart) is the first the scan sees. The first beams' normals
// must come from a window of the wall, not from a few beams of noise, or the wall breaks into
// regions and surfaces of their own (seed 2 gave 9 regions and 3 surfaces).
TEST_F(Cli, TheSquareUnderTheRectangularPriorIsFourWallsOfOneSurface) {
  for (const char* seed : {"1", "2", "3", "4", "5", "6", "7", "8"}) {
    Ok({"simulate", "--scene", "square", "--outliers", "0.02", "--seed", seed, "-o", "sq.json"});
    Ok({"scan", "--prior", "rectangular", "-i", "sq.json", "-o", "m.json"});
    const nlohmann::json map = nlohmann::json::parse(ReadAll(Work("m.json")));
    EXPECT_EQ(map["surfaces"].size(), 1u) << "seed " << seed;
    if (std::string(seed) == "2") {
      EXPECT_EQ(map["regions"].size(), 4u);
    }
  }
}

// A full turn whose seam (the sensor's back, beams 0 and 359) falls mid-wall: the wall is one
// region across it, listed last; --open-full-turn cuts it at the seam into two.
TEST_F(Cli, AFullTurnClosesUnlessOpenFullTurnIsGiven) {
  Ok({"simulate", "--scene", "square", "--fov", "360", "--beams", "360", "--pose", "0.5,0.3,0",
      "--seed", "2", "-o", "ring.json"});
  Ok({"scan", "--prior", "rectangular", "-i", "ring.json", "-o", "closed.json"});
  Ok({"scan", "--prior", "rectangular", "-i", "ring.json", "-o", "open.json", "--open-full-turn"});
  const nlohmann::json closed = nlohmann::json::parse(ReadAll(Work("closed.json")));
  const nlohmann::json open = nlohmann::json::parse(ReadAll(Work("open.json")));
  EXPECT_TRUE(closed["closed"].get<bool>());
  EXPECT_EQ(closed["closing_link"], "same_region");
  ASSERT_EQ(closed["regions"].size(), 4u);
  EXPECT_GT(closed["regions"][3][0].get<int>(), closed["regions"][3][1].get<int>());
  EXPECT_FALSE(open["closed"].get<bool>());
  EXPECT_FALSE(open.contains("closing_link"));
  EXPECT_EQ(open["regions"].size(), 5u);
}

TEST_F(Cli, SimulateAcceptanceCommandWritesTheScanAndItsFigure) {
  const RunResult r = Ok({"simulate", "--scene", "l-room", "--sensor", "utm30", "--seed", "1", "-o",
                          "s.json", "--png", "s.png"});
  EXPECT_THAT(r.out, HasSubstr("wrote s.json"));
  EXPECT_THAT(r.out, HasSubstr("wrote s.png"));
  EXPECT_EQ(WorkFiles(), (std::set<std::string>{"s.json", "s.png"}));

  const std::string png = ReadAll(Work("s.png"));
  EXPECT_TRUE(IsPng(png));
  EXPECT_EQ(PngSize(png).first, 800);  // FigureOptions' default width
  EXPECT_LE(PngSize(png).second, 800);

  Result<Log> read = ReadJsonLog(Work("s.json"));
  ASSERT_TRUE(read.ok()) << read.error();
  const Log& log = read.value();
  ASSERT_EQ(log.scans.size(), 1u);
  const Scan& scan = log.scans.front();
  EXPECT_THAT(scan.Problems(), ::testing::IsEmpty());
  ASSERT_EQ(scan.size(), 1081u);
  EXPECT_NEAR(scan.angles.front(), -DegToRad(135.0), 1e-12);
  EXPECT_NEAR(scan.angles.back(), DegToRad(135.0), 1e-12);
  EXPECT_NEAR(scan.angles[1] - scan.angles[0], DegToRad(0.25), 1e-12);
  EXPECT_EQ(scan.min_range, 0.1);
  EXPECT_EQ(scan.max_range, 30.0);

  // The scene's default pose.
  const Scene scene = *BuiltinScene("l-room");
  EXPECT_NEAR(scan.pose.x(), scene.default_pose->x(), 1e-12);
  EXPECT_NEAR(scan.pose.y(), scene.default_pose->y(), 1e-12);
  EXPECT_NEAR(scan.pose.theta(), scene.default_pose->theta(), 1e-12);

  // The ground truth is what an independent ray cast from the scan pose finds.
  ASSERT_TRUE(scan.truth.has_value());
  const SceneRayCaster caster(scene);
  int hits = 0;
  for (std::size_t i = 0; i < scan.size(); ++i) {
    const Ray ray{scan.pose.translation(), scan.pose.theta() + scan.angles[i]};
    const std::optional<SceneHit> hit = caster.Cast(ray, std::numeric_limits<double>::infinity());
    if (!hit) {
      EXPECT_TRUE(std::isnan(scan.truth->range[i])) << "beam " << i;
      continue;
    }
    ++hits;
    EXPECT_NEAR(scan.truth->range[i], hit->range, 1e-9) << "beam " << i;
    EXPECT_NEAR(AngleDifference(scan.truth->alpha[i], hit->normal_angle - scan.pose.theta()), 0.0,
                1e-9)
        << "beam " << i;
    EXPECT_EQ(scan.truth->surface[i], hit->surface) << "beam " << i;
    EXPECT_EQ(scan.truth->region[i], hit->region) << "beam " << i;
  }
  EXPECT_EQ(hits, 1081);  // a closed room: every beam hits a wall
}

// The range noise of valid, non-outlier readings is N(0, sigma^2), pooled over several seeds.
// With n readings, the mean must be within 4 standard errors (sigma / sqrt(n)) of 0 and
// (n - 1) s^2 / sigma^2 inside the central 99.9% interval of chi-square(n - 1).
void ExpectNoiseHasSigma(const std::vector<Scan>& scans, double sigma) {
  std::vector<double> noise;
  for (const Scan& scan : scans) {
    ASSERT_TRUE(scan.truth.has_value());
    for (std::size_t i = 0; i < scan.size(); ++i) {
      EXPECT_DOUBLE_EQ(scan.sigma[i], sigma);
      if (scan.IsValid(i) && scan.truth->outlier[i] == 0)
        noise.push_back(scan.ranges[i] - scan.truth->range[i]);
    }
  }
  const auto n = static_cast<double>(noise.size());
  ASSERT_GT(n, 3000);
  double mean = 0.0;
  for (double e : noise) mean += e;
  mean /= n;
  double ss = 0.0;
  for (double e : noise) ss += (e - mean) * (e - mean);
  const double statistic = ss / (sigma * sigma);  // (n - 1) s^2 / sigma^2
  EXPECT_LT(std::abs(mean), 4.0 * sigma / std::sqrt(n)) << "mean " << mean;
  // Wilson-Hilferty: chi2_p(k) ~ k (1 - 2/(9k) + z_p sqrt(2/(9k)))^3; z = 3.2905 for 0.05%
  // / 99.95%.
  const double k = n - 1.0, z = 3.2905;
  const auto quantile = [&](double zp) {
    return k * std::pow(1.0 - 2.0 / (9.0 * k) + zp * std::sqrt(2.0 / (9.0 * k)), 3);
  };
  EXPECT_GT(statistic, quantile(-z)) << "sample sigma " << std::sqrt(ss / k);
  EXPECT_LT(statistic, quantile(z)) << "sample sigma " << std::sqrt(ss / k);
}

TEST_F(Cli, SimulatedNoiseHasThePresetSigma) {
  std::vector<Scan> scans;
  for (int seed = 1; seed <= 4; ++seed) {
    const std::string out = std::to_string(seed) + ".json";
    Ok({"simulate", "--scene", "l-room", "--sensor", "utm30", "--seed", std::to_string(seed), "-o",
        out});
    Log log = ReadLogFile(out);
    ASSERT_EQ(log.scans.size(), 1u);
    scans.push_back(log.scans.front());
  }
  ExpectNoiseHasSigma(scans, 0.01);
}

TEST_F(Cli, SigmaOptionSetsTheNoise) {
  std::vector<Scan> scans;
  for (int seed = 11; seed <= 14; ++seed) {
    const std::string out = std::to_string(seed) + ".json";
    Ok({"simulate", "--scene", "l-room", "--sigma", "0.05", "--seed", std::to_string(seed), "-o",
        out});
    scans.push_back(ReadLogFile(out).scans.at(0));
  }
  ExpectNoiseHasSigma(scans, 0.05);
}

TEST_F(Cli, SameSeedGivesIdenticalFilesAndAnotherSeedDiffers) {
  Ok({"simulate", "--seed", "5", "-o", "a.json", "--png", "a.png"});
  Ok({"simulate", "--seed", "5", "-o", "b.json", "--png", "b.png"});
  Ok({"simulate", "--seed", "6", "-o", "c.json", "--png", "c.png"});
  EXPECT_EQ(ReadAll(Work("a.json")), ReadAll(Work("b.json")));
  EXPECT_EQ(ReadAll(Work("a.png")), ReadAll(Work("b.png")));
  EXPECT_NE(ReadAll(Work("a.json")), ReadAll(Work("c.json")));
  // Only the noise differs: same beams, same truth, different ranges.
  const Scan a = ReadLogFile("a.json").scans.at(0), c = ReadLogFile("c.json").scans.at(0);
  EXPECT_EQ(a.angles, c.angles);
  EXPECT_EQ(a.truth->range, c.truth->range);
  EXPECT_NE(a.ranges, c.ranges);
}

// Priorlets relate the beams of a laser scan; a sonar ring is refused, not fitted from the wrong
// origins.
TEST_F(Cli, ScanRefusesSonarRings) {
  Ok({"simulate", "--scene", "square", "--sensor", "pioneer16", "-o", "ring.json"});
  EXPECT_THAT(Fails({"scan", "--prior", "polygonal", "-i", "ring.json", "-o", "m.json"}).err,
              HasSubstr("a sonar ring: priorlets take laser scans"));
  EXPECT_FALSE(fs::exists(Work("m.json")));
}

// Unsigned options refuse a sign (CLI11 alone would wrap -5 round to 2^64 - 5) and read a
// leading zero as decimal (CLI11 alone: octal).
TEST_F(Cli, UnsignedOptionsRefuseSignsAndReadLeadingZerosAsDecimal) {
  EXPECT_THAT(Fails({"simulate", "--seed", "-5", "-o", "a.json"}).err,
              HasSubstr("--seed: '-5' is not a seed"));
  EXPECT_FALSE(fs::exists(Work("a.json")));
  Ok({"simulate", "--seed", "010", "-o", "a.json"});
  Ok({"simulate", "--seed", "10", "-o", "b.json"});
  EXPECT_EQ(ReadAll(Work("a.json")), ReadAll(Work("b.json")));
  EXPECT_THAT(
      Fails({"scan", "--prior", "rectangular", "-i", "a.json", "-o", "m.json", "--index", "-1"})
          .err,
      HasSubstr("'-1' is not an index"));
  EXPECT_THAT(Fails({"scan", "--prior", "rectangular", "-i", "a.json", "-o", "m.json",
                     "--max-free-dimension", "-5"})
                  .err,
              HasSubstr("'-5' is not a dimension"));
  EXPECT_THAT(Fails({"plot", "a.json", "-o", "p.png", "--scan", "-2"}).err,
              HasSubstr("'-2' is not an index"));
}

// Exit statuses tell a script what went wrong: 2 for every usage error (CLI11's own codes, 105,
// 106, 109, ... said no more and looked like crashes), 1 for bad input, 0 for help.
TEST_F(Cli, UsageErrorsExitWithTwoAndInputErrorsWithOne) {
  const std::vector<std::vector<std::string>> usage = {
      {"frobnicate"},                                      // unknown command
      {"simulate", "--scene"},                             // an option without its value
      {"scan", "--prior", "rectangular", "-i", "a.json"},  // -o is required
      {"simulate", "--beams", "0", "-o", "a.json"},        // out of its range
      {"simulate", "--no-such-option", "-o", "a.json"},    // unknown option
      {"grid", "--log", "a.json", "-o", "g", "--resolution", "-1"}};
  for (const std::vector<std::string>& args : usage) {
    const RunResult r = Fails(args);
    EXPECT_EQ(r.status, 2) << fmt::format("{}", fmt::join(args, " ")) << "\n" << r.err;
    EXPECT_THAT(r.err, StartsWith("priormap: error: "));
  }
  EXPECT_EQ(Fails({"scan", "--prior", "rectangular", "-i", "missing.json", "-o", "m.json"}).status,
            1);
  EXPECT_EQ(Run({"simulate", "--help"}).status, 0);
}

TEST_F(Cli, SameSeedGivesIdenticalLogs) {
  Ok({"simulate", "--log", "--sensor", "lms200", "--seed", "3", "-o", "a.json"});
  Ok({"simulate", "--log", "--sensor", "lms200", "--seed", "3", "-o", "b.json"});
  Ok({"simulate", "--log", "--sensor", "lms200", "--seed", "4", "-o", "c.json"});
  EXPECT_EQ(ReadAll(Work("a.json")), ReadAll(Work("b.json")));
  EXPECT_NE(ReadAll(Work("a.json")), ReadAll(Work("c.json")));
}

TEST_F(Cli, PoseOptionSetsThePose) {
  Ok({"simulate", "--scene", "square", "--pose", "0.5,-1.25,1.2", "-o", "s.json"});
  const Scan scan = ReadLogFile("s.json").scans.at(0);
  EXPECT_DOUBLE_EQ(scan.pose.x(), 0.5);
  EXPECT_DOUBLE_EQ(scan.pose.y(), -1.25);
  EXPECT_DOUBLE_EQ(scan.pose.theta(), 1.2);
  // ...and the scan is taken from there.
  const SceneRayCaster caster(*BuiltinScene("square"));
  for (std::size_t i = 0; i < scan.size(); i += 10) {
    const auto hit = caster.Cast({Vec2(0.5, -1.25), 1.2 + scan.angles[i]}, 1e9);
    ASSERT_TRUE(hit.has_value());
    EXPECT_NEAR(scan.truth->range[i], hit->range, 1e-9);
  }
}

TEST_F(Cli, PoseOptionAcceptsNegativeCoordinates) {
  // Both as --pose=VALUE and as a separate argument that starts with '-'.
  Ok({"simulate", "--scene", "square", "--pose=-1,-0.5,-3", "-o", "a.json"});
  Ok({"simulate", "--scene", "square", "--pose", "-1,-0.5,-3", "-o", "b.json"});
  for (const char* name : {"a.json", "b.json"}) {
    const Scan scan = ReadLogFile(name).scans.at(0);
    EXPECT_DOUBLE_EQ(scan.pose.x(), -1.0) << name;
    EXPECT_DOUBLE_EQ(scan.pose.y(), -0.5) << name;
    EXPECT_DOUBLE_EQ(scan.pose.theta(), -3.0) << name;
  }
}

TEST_F(Cli, LogOptionWritesALocalizedLogAlongTheWaypoints) {
  const RunResult r =
      Ok({"simulate", "--scene", "l-room", "--sensor", "lms200", "--log", "--seed", "2", "--speed",
          "1", "--rate", "2", "-o", "log.json", "--png", "log.svg"});
  EXPECT_THAT(r.out, HasSubstr("wrote log.json"));
  EXPECT_THAT(ReadAll(Work("log.svg")), HasSubstr("<svg"));
  const Log log = ReadLogFile("log.json");
  const Scene scene = *BuiltinScene("l-room");
  const std::vector<TimedPose> trajectory = TrajectoryFromWaypoints(scene.waypoints, 1.0, 2.0);
  ASSERT_EQ(log.scans.size(), trajectory.size());
  EXPECT_EQ(log.odometry.size(), trajectory.size());
  EXPECT_EQ(log.true_poses.size(), trajectory.size());
  EXPECT_EQ(log.pose_source, PoseSource::kGroundTruth);
  EXPECT_THAT(log.Problems(), ::testing::IsEmpty());
  for (std::size_t k = 0; k < log.scans.size(); ++k) {
    EXPECT_EQ(log.scans[k].size(), 181u);
    EXPECT_NEAR(log.scans[k].timestamp, trajectory[k].time, 1e-12);
    EXPECT_NEAR((log.scans[k].pose.translation() - trajectory[k].pose.translation()).norm(), 0.0,
                1e-12);
    EXPECT_NEAR(AngleDifference(log.scans[k].pose.theta(), trajectory[k].pose.theta()), 0.0, 1e-12);
  }
}

TEST_F(Cli, CarmenOutputHoldsTheSameScanAsJson) {
  Ok({"simulate", "--seed", "9", "-o", "s.json"});
  // The utm30's noise is the CARMEN reader's default; its minimum range and truth are not.
  OkLosingToCarmen(
      {"simulate", "--seed", "9", "-o", "s.log"},
      "CARMEN cannot hold the ground truth of 1 scan, the minimum range of 1 scan, the pose "
      "source \"ground_truth\" (read back as \"unknown\");");
  EXPECT_THAT(ReadAll(Work("s.log")), Not(StartsWith("{")));
  const Scan json = ReadLogFile("s.json").scans.at(0);
  Result<Log> carmen = ReadCarmenLog(Work("s.log"));
  ASSERT_TRUE(carmen.ok()) << carmen.error();
  ASSERT_EQ(carmen.value().scans.size(), 1u);
  const Scan& scan = carmen.value().scans[0];
  ASSERT_EQ(scan.size(), json.size());
  for (std::size_t i = 0; i < scan.size(); ++i) {
    EXPECT_DOUBLE_EQ(scan.ranges[i], json.ranges[i]) << i;
    EXPECT_NEAR(scan.angles[i], json.angles[i], 1e-12) << i;
  }
  EXPECT_DOUBLE_EQ(scan.pose.x(), json.pose.x());
  EXPECT_DOUBLE_EQ(scan.pose.theta(), json.pose.theta());
}

TEST_F(Cli, SimulatedLogCanBeWrittenAsCompressedCarmen) {
  OkLosingToCarmen({"simulate", "--log", "--sensor", "lms200", "--speed", "2", "-o", "log.log.gz"},
                   "CARMEN cannot hold the ground truth of 38 scans, the pose source");
  EXPECT_THAT(ReadAll(Work("log.log.gz")), StartsWith("\x1f\x8b"));
  const Log log = ReadLogFile("log.log.gz");
  EXPECT_GT(log.scans.size(), 5u);
  EXPECT_EQ(log.odometry.size(), log.scans.size());
}

// --- convert -----------------------------------------------------------------------------------

constexpr const char* kCarmenLog =
    "# a hand-written log\n"
    "PARAM robot_front_laser_max 81.9\n"
    "ODOM 0.0 0.0 0.0 0.1 0.0 0.0 1.0 host 1.0\n"
    "FLASER 5 1.5 2.25 3.0 81.9 0.75 0.0 0.0 0.0 0.0 0.0 0.0 1.05 host 1.05\n"
    "ODOM 0.5 0.1 0.05 0.1 0.0 0.0 2.0 host 2.0\n"
    "FLASER 5 1.25 2.0 2.5 3.5 0.5 0.5 0.1 0.05 0.5 0.1 0.05 2.05 host 2.05\n";

TEST_F(Cli, ConvertCarmenToJsonAndBackKeepsTheLog) {
  WriteAll(Work("in.log"), kCarmenLog);
  const RunResult to_json = Ok({"convert", "in.log", "-o", "mid.json"});
  EXPECT_THAT(to_json.out, HasSubstr("2 scans, 2 odometry"));
  EXPECT_THAT(to_json.out, HasSubstr("wrote mid.json (json)"));
  EXPECT_THAT(ReadAll(Work("mid.json")), StartsWith("{"));
  Ok({"convert", "mid.json", "-o", "out.log"});
  Ok({"convert", "in.log", "-o", "direct.log"});
  // Through JSON or directly, CARMEN comes out the same.
  EXPECT_EQ(ReadAll(Work("out.log")), ReadAll(Work("direct.log")));

  const Log original = ReadLogFile("in.log");
  const Log round_trip = ReadLogFile("out.log");
  ASSERT_EQ(round_trip.scans.size(), 2u);
  ASSERT_EQ(original.scans.size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(round_trip.scans[k].ranges, original.scans[k].ranges);
    EXPECT_EQ(round_trip.scans[k].status, original.scans[k].status);
    EXPECT_EQ(round_trip.scans[k].angles, original.scans[k].angles);
    EXPECT_EQ(round_trip.scans[k].timestamp, original.scans[k].timestamp);
    EXPECT_EQ(round_trip.scans[k].pose.translation(), original.scans[k].pose.translation());
  }
  EXPECT_EQ(round_trip.odometry.size(), 2u);
  EXPECT_EQ(round_trip.params, original.params);
  // The FLASER records stay FLASER records with their fields.
  const std::string text = ReadAll(Work("out.log"));
  EXPECT_THAT(text, HasSubstr("FLASER 5 1.5 2.25 3 81.9 0.75"));
  EXPECT_THAT(text, HasSubstr("PARAM robot_front_laser_max 81.9"));
}

TEST_F(Cli, ConvertSimulatedCarmenLogThroughJson) {
  OkLosingToCarmen(
      {"simulate", "--log", "--sensor", "lms200", "--speed", "2", "--seed", "4", "-o", "sim.log"},
      "the ground truth of 38 scans");
  Ok({"convert", "sim.log", "-o", "sim.json"});
  Ok({"convert", "sim.json", "-o", "back.log"});
  EXPECT_EQ(ReadAll(Work("back.log")), ReadAll(Work("sim.log")));
}

// --- plot --------------------------------------------------------------------------------------

TEST_F(Cli, PlotsAScanAsMapRangesAndResiduals) {
  Ok({"simulate", "--seed", "1", "-o", "s.json"});
  EXPECT_THAT(Ok({"plot", "s.json", "-o", "map.png"}).out, HasSubstr("wrote map.png"));
  Ok({"plot", "s.json", "--kind", "ranges", "-o", "ranges.svg"});
  Ok({"plot", "s.json", "--kind", "residuals", "--width", "640", "-o", "residuals.png"});
  Ok({"plot", "s.json", "--scene", "l-room", "-o", "map.pdf"});
  const std::string map = ReadAll(Work("map.png"));
  EXPECT_TRUE(IsPng(map));
  EXPECT_EQ(PngSize(map).first, 900);  // --width's default
  EXPECT_THAT(ReadAll(Work("ranges.svg")), HasSubstr("<svg"));
  const std::string residuals = ReadAll(Work("residuals.png"));
  EXPECT_TRUE(IsPng(residuals));
  EXPECT_EQ(PngSize(residuals), std::pair(640, 450));
  EXPECT_THAT(ReadAll(Work("map.pdf")), StartsWith("%PDF"));
}

TEST_F(Cli, PlotsALogAsAMapAndOneOfItsScans) {
  Ok({"simulate", "--log", "--sensor", "lms200", "--speed", "2", "-o", "log.json"});
  Ok({"plot", "log.json", "-o", "log.png", "--stride", "2"});
  Ok({"plot", "log.json", "--scan", "3", "-o", "scan3.png"});
  Ok({"plot", "log.json", "--scan", "3", "--kind", "residuals", "-o", "residuals3.png"});
  for (const char* name : {"log.png", "scan3.png", "residuals3.png"})
    EXPECT_TRUE(IsPng(ReadAll(Work(name))));
}

TEST_F(Cli, PlotsACarmenLog) {
  WriteAll(Work("in.log"), kCarmenLog);
  Ok({"plot", "in.log", "-o", "carmen.png"});
  Ok({"plot", "in.log", "--kind", "ranges", "--scan", "1", "-o", "ranges.png"});
  EXPECT_TRUE(IsPng(ReadAll(Work("carmen.png"))));
  EXPECT_TRUE(IsPng(ReadAll(Work("ranges.png"))));
}

// --- demo, version, help -----------------------------------------------------------------------

TEST_F(Cli, DemoRunsEveryEngineIntoAGalleryAndSaysWhereItIs) {
  const RunResult r = Ok({"demo", "--quick", "--no-real", "--out", "gallery"});
  EXPECT_THAT(r.out, HasSubstr("gallery/index.html"));
  const std::string index = ReadAll(Work("gallery/index.html"));
  EXPECT_THAT(index, StartsWith("<!doctype html>"));
  // One figure per engine at least, each made by the command shown beside it.
  for (const std::string file :
       {"priorlets/l-room-rectangular.png", "priorlets/two-circles-circular.png",
        "slam/figures/pose_error.png", "prf-laser/grid/grid.png", "prf-laser/prf/posterior.png",
        "prf-laser/prf/map.png", "prf-sonar/grid/grid.png", "prf-sonar/prf/posterior.png"}) {
    EXPECT_THAT(index, HasSubstr("src=\"" + file + "\"")) << file;
    EXPECT_TRUE(IsPng(ReadAll(Work("gallery/" + file)))) << file;
  }
  for (const std::string command :
       {"priormap scan --prior rectangular", "priormap slam simulate --runs 5 --seed 1",
        "priormap prf --log gallery/data/l-room-lms200.json --beam-step 8",
        "priormap grid --log gallery/data/office-pioneer16.json"})
    EXPECT_THAT(index, HasSubstr(command)) << command;
  EXPECT_THAT(index, HasSubstr("RMS position error"));
  EXPECT_THAT(index, HasSubstr("proposals/s"));
  // Every image the page shows exists.
  int images = 0;
  for (std::size_t at = index.find("src=\""); at != std::string::npos;
       at = index.find("src=\"", at)) {
    at += 5;
    const std::string file = index.substr(at, index.find('"', at) - at);
    EXPECT_TRUE(fs::exists(Work("gallery/" + file))) << file;
    ++images;
  }
  EXPECT_EQ(images, 11);  // 2 priorlet scans, 4 SLAM plots, 3 laser and 2 sonar maps
  // The commands' own output went to the log, not to the terminal.
  const std::string log = ReadAll(Work("gallery/demo.log"));
  EXPECT_THAT(log, HasSubstr("$ priormap prf --log"));
  // A command's stderr (the prf's count of beams) comes after its own heading, not the last one's.
  EXPECT_LT(log.find("$ priormap prf --log gallery/data/l-room-lms200.json"),
            log.find("sensor positions, R ="));
  EXPECT_THAT(r.out, Not(HasSubstr("R-hat")));
  // The footer names what made the gallery, and why it has no real log.
  EXPECT_THAT(index, HasSubstr("Made by priormap demo --seed 1 --quick --no-real"));
  EXPECT_THAT(index, HasSubstr("no real logs (--no-real)"));
  EXPECT_FALSE(fs::exists(Work("gallery/real")));
  for (const std::string& file : WorkFiles()) EXPECT_THAT(file, Not(HasSubstr(".tmp-")));
}

TEST_F(Cli, DemoRefusesAMissingDataDirectory) {
  const RunResult r = Fails({"demo", "--quick", "--data", "no-such-dir", "--out", "gallery"});
  EXPECT_THAT(r.err, HasSubstr("--data no-such-dir: no such directory"));
  EXPECT_THAT(Fails({"demo", "--quick", "--out", ""}).err, HasSubstr("empty directory name"));
}

TEST_F(Cli, VersionPrintsTheVersionAndLibraries) {
  const RunResult r = Ok({"version"});
  EXPECT_THAT(r.out, MatchesRegex("priormap [0-9]+\\.[0-9]+\\.[0-9]+\n.*"));
  EXPECT_THAT(r.out, HasSubstr("Eigen"));
  EXPECT_THAT(r.out, HasSubstr("cairo"));
  EXPECT_TRUE(WorkFiles().empty());
}

TEST_F(Cli, HelpOnEverySubcommandExitsZero) {
  for (const char* command : {"simulate", "convert", "plot", "demo", "version"}) {
    const RunResult r = Ok({command, "--help"});
    EXPECT_THAT(r.out, HasSubstr(command)) << command;
    EXPECT_THAT(r.out, HasSubstr("--help")) << command;
  }
  const RunResult root = Ok({"--help"});
  for (const char* command : {"simulate", "convert", "plot", "demo", "version"}) {
    EXPECT_THAT(root.out, HasSubstr(command));
  }
  EXPECT_THAT(Ok({"simulate", "--help"}).out, HasSubstr("--pose"));
  EXPECT_THAT(Ok({"plot", "-h"}).out, HasSubstr("--kind"));
  EXPECT_TRUE(WorkFiles().empty());
}

// --- errors ------------------------------------------------------------------------------------

TEST_F(Cli, UnknownSceneIsAnError) {
  const RunResult r = Fails({"simulate", "--scene", "atlantis", "-o", "s.json", "--png", "s.png"});
  EXPECT_THAT(r.err, HasSubstr("unknown scene 'atlantis'"));
  EXPECT_EQ(r.status, 1);
}

TEST_F(Cli, BadPoseTextIsAnError) {
  for (const char* pose : {"1,2", "1,2,x", "1,2,3,4", "1;2;3", "", "nan,0,0", "1,,3", " 1,2,3"}) {
    const RunResult r = Fails({"simulate", "--scene", "square", "--pose", pose, "-o", "s.json"});
    EXPECT_THAT(r.err, HasSubstr("--pose")) << "'" << pose << "'";
  }
}

TEST_F(Cli, UnknownSensorIsAnError) {
  EXPECT_THAT(Fails({"simulate", "--sensor", "kinect", "-o", "s.json"}).err, HasSubstr("kinect"));
}

TEST_F(Cli, InvalidSensorParametersAreAnError) {
  EXPECT_THAT(Fails({"simulate", "--correlation", "1.5", "-o", "s.json"}).err,
              HasSubstr("correlation"));
  EXPECT_THAT(Fails({"simulate", "--max-range", "-1", "-o", "s.json"}).err, HasSubstr("range"));
}

TEST_F(Cli, MissingOutputOptionIsAnError) {
  EXPECT_THAT(Fails({"simulate", "--scene", "l-room"}).err, HasSubstr("--out"));
  WriteAll(Work("in.log"), kCarmenLog);
  EXPECT_THAT(Fails({"convert", "in.log"}).err, HasSubstr("--out"));
  EXPECT_THAT(Fails({"plot", "in.log"}).err, HasSubstr("--out"));
}

TEST_F(Cli, UnknownSubcommandIsAnError) {
  Fails({"frobnicate"});
  Fails({"simulate", "--no-such-option", "-o", "s.json"});
  Fails({});  // a subcommand is required
}

TEST_F(Cli, UnsupportedFigureExtensionIsAnError) {
  EXPECT_THAT(Fails({"simulate", "-o", "s.json", "--png", "s.bmp"}).err, HasSubstr("s.bmp"));
  Ok({"simulate", "-o", "s.json"});
  EXPECT_THAT(Fails({"plot", "s.json", "-o", "s.gif"}).err, HasSubstr(".png, .svg or .pdf"));
  EXPECT_THAT(Fails({"plot", "s.json", "-o", "noextension"}).err, HasSubstr(".png, .svg or .pdf"));
}

TEST_F(Cli, UnreadableInputFileIsAnError) {
  EXPECT_THAT(Fails({"plot", "missing.json", "-o", "p.png"}).err, HasSubstr("missing.json"));
  EXPECT_THAT(Fails({"convert", "missing.log", "-o", "out.json"}).err, HasSubstr("missing.log"));
  fs::create_directory(Work("adir"));
  EXPECT_THAT(Fails({"convert", "adir", "-o", "out.json"}).err, HasSubstr("adir"));
  EXPECT_THAT(Fails({"simulate", "--scene", "missing-scene.json", "-o", "s.json"}).err,
              HasSubstr("missing-scene.json"));
}

TEST_F(Cli, MalformedCarmenInputIsLocated) {
  WriteAll(Work("bad.log"),
           "ODOM 0.0 0.0 0.0 0.1 0.0 0.0 1.0 host 1.0\n"
           "FLASER 3 1.0 2.0 oops 0.0 0.0 0.0 0.0 0.0 0.0 1.05 host 1.05\n");
  const auto located = ContainsRegex("priormap: error: bad\\.log:2:[0-9]+: ");
  const RunResult convert = Fails({"convert", "bad.log", "-o", "out.json"});
  EXPECT_THAT(convert.err, located);
  EXPECT_THAT(convert.err, HasSubstr("oops"));
  const RunResult plot = Fails({"plot", "bad.log", "-o", "out.png"});
  EXPECT_THAT(plot.err, located);
}

TEST_F(Cli, MalformedJsonInputIsLocated) {
  WriteAll(Work("bad.json"), "{\"format\": \"priormap.scan\",\n \"version\": oops}\n");
  const RunResult r = Fails({"convert", "bad.json", "-o", "out.log"});
  EXPECT_THAT(r.err, ContainsRegex("priormap: error: bad\\.json:2:[0-9]+"));
}

TEST_F(Cli, OutputIntoAMissingDirectoryIsAnError) {
  EXPECT_THAT(Fails({"simulate", "-o", "nowhere/s.json"}).err, HasSubstr("nowhere"));
  Ok({"simulate", "-o", "s.json"});
  EXPECT_THAT(Fails({"plot", "s.json", "-o", "nowhere/p.png"}).err, HasSubstr("nowhere"));
  EXPECT_THAT(Fails({"convert", "s.json", "-o", "nowhere/s.log"}).err, HasSubstr("nowhere"));
}

TEST_F(Cli, PlotRefusesToOverwriteItsInput) {
  Ok({"simulate", "-o", "s.json"});
  const std::string scan = ReadAll(Work("s.json"));
  fs::copy_file(Work("s.json"), Work("s.svg"));
  EXPECT_THAT(Fails({"plot", "s.svg", "-o", "s.svg"}).err,
              HasSubstr("one would overwrite the other"));
  EXPECT_EQ(ReadAll(Work("s.json")), scan);
}

// An output that is the input through a link: both paths named as given, and said to be one file.
TEST_F(Cli, AnOutputLinkedToTheInputIsNamedWithTheInputAsTheSameFile) {
  const std::string log = "FLASER 3 1 2 3 0 0 0 0 0 0\n";
  WriteAll(Work("s.log"), log);
  fs::create_symlink("s.log", Work("link.log"));
  EXPECT_THAT(Fails({"convert", "s.log", "-o", "link.log"}).err,
              HasSubstr("priormap: error: the input s.log and --out link.log are the same file: "
                        "one would overwrite the other\n"));
  fs::create_symlink("s.log", Work("link.svg"));
  EXPECT_THAT(Fails({"plot", "./s.log", "-o", "link.svg"}).err,
              HasSubstr("priormap: error: the input ./s.log and --out link.svg are the same file: "
                        "one would overwrite the other\n"));
  EXPECT_EQ(ReadAll(Work("s.log")), log);
}

// A reading of 1e300 in a log without a max range was accepted, and `plot` alone refused the log,
// "too far to draw", naming no line: every command now gets the reader's error at the reading.
// A no-return (at or above the max range) is kept as read and drawn by its status, as a ray to
// the max range.
TEST_F(Cli, AReturnBeyondTheWorldIsReportedAtItsReadingAndANoReturnIsDrawn) {
  WriteAll(Work("far.log"), "FLASER 3 1 1e300 2 0 0 0 0 0 0\n");
  WriteAll(Work("far.json"), R"({"format":"priormap.scan","version":1,"pose":[0,0,0],)"
                             R"("angles":[-0.5,0,0.5],"ranges":[1,1e300,2]})");
  const std::map<std::string, std::string> located = {
      {"far.log",
       "priormap: error: far.log:1:12: expected a range reading in metres, at most 1e+09 for a "
       "return or at or above the max range (inf m) for no return, got '1e300'"},
      {"far.json",
       "priormap: error: far.json:1:88: expected an element of \"ranges\" in metres, at most "
       "1e+09 for a return or at or above the max range (inf m) for no return, got 1e+300 (at "
       "/ranges/1)"}};
  for (const auto& [log, message] : located) {
    for (const std::vector<std::string>& args :
         {std::vector<std::string>{"plot", log, "-o", "far.png"},
          {"plot", log, "--kind", "ranges", "-o", "far.png"},
          {"grid", "--log", log, "-o", "grid"},
          {"convert", log, "-o", "out.json"}}) {
      const RunResult r = Fails(args);
      EXPECT_THAT(r.err, HasSubstr(message)) << args[0];
      EXPECT_THAT(r.err, Not(HasSubstr("too far to draw"))) << args[0];
    }
  }
  EXPECT_FALSE(fs::exists(Work("far.png")));
  // The same readings as no-returns: the caller's max range, the scan's own, and one so long
  // (a stand-in for none) that its rays cannot size the figure.
  Ok({"plot", "far.log", "--max-range", "80", "-o", "carmen.png"});
  WriteAll(Work("own.json"), R"({"format":"priormap.scan","version":1,"pose":[0,0,0],)"
                             R"("max_range":30,"angles":[-0.5,0,0.5],"ranges":[1,1e300,2]})");
  WriteAll(Work("none.json"), R"({"format":"priormap.scan","version":1,"pose":[0,0,0],)"
                              R"("max_range":1e20,"angles":[-0.5,0.5],"ranges":[2e20,3e20]})");
  for (const std::string name : {"own", "none"}) {
    Ok({"plot", name + ".json", "-o", name + ".png"});
    Ok({"plot", name + ".json", "--kind", "ranges", "-o", name + "-ranges.png"});
    EXPECT_GT(fs::file_size(Work(name + ".png")), 0U) << name;
  }
}

// A finite but absurd pose made each command fail later, with a grid or a window too large to
// make and no line to look at: every command that reads the log now names the record's field.
TEST_F(Cli, APoseBeyondTheWorldIsReportedAtItsFieldByEveryCommandThatReadsTheLog) {
  WriteAll(Work("far.log"),
           "ODOM 0 0 0 0 0 0\n"
           "FLASER 5 1 1 1 1 1 1e300 0 0 1e300 0 0\n");
  WriteAll(Work("far.json"),
           "{\"format\": \"priormap.log\", \"version\": 1, \"records\": [\n"
           "{\"type\": \"scan\", \"pose\": [0, 1e300, 0], \"angles\": [0], "
           "\"ranges\": [1]}]}\n");
  const std::map<std::string, std::string> located = {
      {"far.log",
       "priormap: error: far.log:2:20: expected laser pose x in metres of a local frame, at "
       "most 1e+09 in magnitude, got '1e300'"},
      {"far.json",
       "priormap: error: far.json:2:30: expected y in metres of a local frame, at most 1e+09 in "
       "magnitude, got 1e+300 (at /records/0/pose/1)"}};
  for (const auto& [log, message] : located) {
    for (const std::vector<std::string>& args :
         {std::vector<std::string>{"grid", "--log", log, "-o", "grid"},
          {"prf", "--log", log, "-o", "prf", "--samples", "10", "--burn-in", "0"},
          {"plot", log, "-o", "far.png"},
          {"convert", log, "-o", "out.log"}}) {
      const RunResult r = Fails(args);
      EXPECT_THAT(r.err, HasSubstr(message)) << args[0];
      EXPECT_THAT(r.err, Not(HasSubstr("cells"))) << args[0];
    }
  }
}

// A scene far away made plot blame the log ("far.log: poses or readings lie beyond ..."): the
// scene is named, at the coordinate that leaves the world.
TEST_F(Cli, PlotNamesASceneBeyondTheWorldNotTheLog) {
  Ok({"simulate", "--scene", "l-room", "--log", "-o", "room.json"});
  WriteAll(Work("far-scene.json"),
           "{\"format\": \"priormap.scene\", \"version\": 1, \"surfaces\": [\n"
           "  {\"type\": \"polyline\", \"points\": [[2e9, 0], [2e9, 4]]}]}\n");
  WriteAll(Work("absurd-scene.json"),
           "{\"format\": \"priormap.scene\", \"version\": 1, \"surfaces\": [\n"
           "  {\"type\": \"circle\", \"center\": [0, 1e300], \"radius\": 1}]}\n");
  const RunResult far = Fails({"plot", "room.json", "--scene", "far-scene.json", "-o", "p.png"});
  EXPECT_THAT(far.err, HasSubstr("priormap: error: far-scene.json:2:36: expected x in metres of a "
                                 "local frame, at most 1e+09 in magnitude, got 2000000000"));
  EXPECT_THAT(far.err, Not(HasSubstr("room.json")));
  const RunResult absurd =
      Fails({"plot", "room.json", "--scene", "absurd-scene.json", "-o", "p.png"});
  EXPECT_THAT(absurd.err, HasSubstr("priormap: error: absurd-scene.json:2:36: expected y in "
                                    "metres of a local frame"));
  EXPECT_THAT(absurd.err, Not(HasSubstr("room.json")));
  // Far from the log but within the world: drawn.
  WriteAll(Work("distant-scene.json"),
           "{\"format\": \"priormap.scene\", \"version\": 1, \"surfaces\": [\n"
           "  {\"type\": \"polyline\", \"points\": [[9e8, 0], [9e8, 4]]}]}\n");
  Ok({"plot", "room.json", "--scene", "distant-scene.json", "-o", "p.png"});
}

// A simulated scan at a pose the readers refuse could not be read back.
TEST_F(Cli, SimulateRefusesAPoseBeyondTheWorld) {
  EXPECT_THAT(Fails({"simulate", "--pose", "2e9,0,0", "-o", "s.json"}).err,
              HasSubstr("priormap: error: --pose: expected x in metres of a local frame, at most "
                        "1e+09 in magnitude, got 2000000000"));
  EXPECT_THAT(Fails({"simulate", "--pose", "0,-1e300,0", "-o", "s.json"}).err,
              HasSubstr("--pose: expected y in metres of a local frame"));
}

// Bytes after the last gzip member were ignored: a log with a second file appended lost it
// without a word. Members written one after the other are one log.
TEST_F(Cli, GzipLogsAreReadAsTheirMembersConcatenatedAndTrailingDataIsAnError) {
  OkLosingToCarmen({"simulate", "--scene", "l-room", "--log", "-o", "room.log.gz"},
                   "the ground truth");
  const std::string member = ReadAll(Work("room.log.gz"));
  WriteAll(Work("twice.log.gz"), member + member);
  EXPECT_EQ(ReadLogFile("twice.log.gz").scans.size(), 2 * ReadLogFile("room.log.gz").scans.size());
  WriteAll(Work("tail.log.gz"), member + "FLASER 0 0 0 0 0 0 0\n");
  EXPECT_THAT(Fails({"convert", "tail.log.gz", "-o", "out.json"}).err,
              HasSubstr(fmt::format("priormap: error: tail.log.gz: trailing data after the last "
                                    "gzip member, at byte offset {} (of a {}-byte file): expected "
                                    "another gzip member (magic bytes 1f 8b) or the end of the "
                                    "file",
                                    member.size(), member.size() + 21)));
}

// A run that fails writes none of its outputs, even when the first one could have been written.
TEST_F(Cli, FailedSimulateWritesNoOutputAtAll) {
  EXPECT_THAT(Fails({"simulate", "-o", "s.json", "--png", "nowhere/s.png"}).err,
              HasSubstr("nowhere"));
  EXPECT_THAT(Fails({"simulate", "-o", "s.json", "--write-scene", "nowhere/scene.json"}).err,
              HasSubstr("nowhere"));
  EXPECT_THAT(Fails({"simulate", "--write-scene", "scene.json", "-o", "nowhere/s.json"}).err,
              HasSubstr("nowhere"));
  EXPECT_THAT(
      Fails({"simulate", "--write-scene", "scene.json", "-o", "s.json", "--pose", "1,2"}).err,
      HasSubstr("--pose"));
}

TEST_F(Cli, WrittenSceneCanBeSimulatedAgain) {
  EXPECT_THAT(Ok({"simulate", "--scene", "l-room", "--write-scene", "room.json"}).out,
              HasSubstr("wrote room.json"));
  EXPECT_EQ(WorkFiles(), (std::set<std::string>{"room.json"}));
  Result<Scene> scene = ReadJsonScene(Work("room.json"));
  ASSERT_TRUE(scene.ok()) << scene.error();
  EXPECT_EQ(scene.value().surfaces.size(), BuiltinScene("l-room")->surfaces.size());
  // The file gives the same scan as the built-in scene.
  Ok({"simulate", "--scene", "l-room", "--seed", "3", "-o", "builtin.json"});
  Ok({"simulate", "--scene", "room.json", "--seed", "3", "-o", "file.json"});
  const Scan builtin = ReadLogFile("builtin.json").scans.at(0);
  const Scan file = ReadLogFile("file.json").scans.at(0);
  EXPECT_EQ(builtin.ranges, file.ranges);
  EXPECT_EQ(builtin.truth->range, file.truth->range);
}

TEST_F(Cli, PlotErrorsNameTheProblem) {
  Ok({"simulate", "-o", "s.json"});
  WriteAll(Work("in.log"), kCarmenLog);
  EXPECT_THAT(Fails({"plot", "s.json", "--scan", "1", "-o", "p.png"}).err, HasSubstr("--scan 1"));
  EXPECT_THAT(Fails({"plot", "in.log", "--kind", "residuals", "-o", "p.png"}).err,
              HasSubstr("no ground truth"));
  Fails({"plot", "s.json", "--kind", "histogram", "-o", "p.png"});
  WriteAll(Work("odometry.log"), "ODOM 0.0 0.0 0.0 0.1 0.0 0.0 1.0 host 1.0\n");
  EXPECT_THAT(Fails({"plot", "odometry.log", "-o", "p.png"}).err, HasSubstr("no scans"));
}

TEST_F(Cli, FailedWriteKeepsThePreviousOutput) {
  Ok({"simulate", "--seed", "1", "-o", "s.json"});
  const std::string before = ReadAll(Work("s.json"));
  Fails({"simulate", "--scene", "atlantis", "--seed", "2", "-o", "s.json"});
  EXPECT_EQ(ReadAll(Work("s.json")), before);
}

// --- prior -------------------------------------------------------------------------------------

constexpr const char* kPoseDependentPrior =
    "# Walls facing the sensor.\n"
    "name: Facing\n"
    "order: 2\n"
    "priorlet same_region:\n"
    "  alpha_1 == alpha_2\n"
    "  alpha_1 == 0\n";

// `priormap prior eval polygonal --at ...` at p_1 = (1, 0), p_2 = 2 (cos 0.5, sin 0.5).
const std::vector<std::string> kPolygonalEval = {
    "prior", "eval", "polygonal", "--at",
    "rho_1=1,rho_2=2,alpha_1=0.3,alpha_2=-0.1,phi_1=0,phi_2=0.5"};

TEST_F(Cli, PriorListShowsTheBuiltinLibrary) {
  const RunResult r = Ok({"prior", "list"});
  for (const char* name : {"Polygonal prior", "Rectangular prior (relaxed - alternative)",
                           "Circular prior", "Splines prior", "Straight or circular prior"}) {
    EXPECT_THAT(r.out, HasSubstr(name));
  }
  EXPECT_THAT(r.out, HasSubstr("<builtin>/polygonal.prior"));
  EXPECT_THAT(r.out, HasSubstr("Fig. 2a: the environment is made of straight walls."));
  std::size_t builtins = 0;
  for (std::size_t at = r.out.find("<builtin>/"); at != std::string::npos;
       at = r.out.find("<builtin>/", at + 1)) {
    ++builtins;
  }
  EXPECT_EQ(builtins, 10u);
  EXPECT_TRUE(WorkFiles().empty());
}

TEST_F(Cli, PriorListIncludesThePriorPathBeforeOrAfterTheSubcommand) {
  fs::create_directory(Work("lib"));
  WriteAll(Work("lib/facing.prior"), kPoseDependentPrior);
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"prior", "--prior-path", "lib", "list"},
        std::vector<std::string>{"prior", "list", "--prior-path", "lib"}}) {
    const RunResult r = Ok(args);
    EXPECT_THAT(r.out, StartsWith("Facing "));
    EXPECT_THAT(r.out, HasSubstr("Walls facing the sensor."));
    EXPECT_THAT(r.out, HasSubstr("lib/facing.prior"));
  }
}

// CLI11's ranges let NaN through (every comparison with it is false); priormap refuses NaN and
// infinities in every floating-point option.
TEST_F(Cli, NonFiniteNumbersAreRefusedInEveryFloatingPointOption) {
  for (const char* value : {"nan", "inf", "-inf"}) {
    EXPECT_THAT(Fails({"simulate", "--scene", "square", "--fov", value, "-o", "s.json"}).err,
                HasSubstr(fmt::format("--fov: {} is not a finite number", value)));
  }
  EXPECT_THAT(Fails({"slam", "simulate", "--runs", "1", "--p-accept", "nan", "-o", "x"}).err,
              HasSubstr("--p-accept: nan is not a finite number"));
  EXPECT_THAT(Fails({"scan", "--prior", "polygonal", "-i", "s.json", "--beta", "nan"}).err,
              HasSubstr("--beta: nan is not a finite number"));
  EXPECT_THAT(Fails({"prior", "eval", "rectangular", "--at",
                     "rho_1=nan,alpha_1=0,phi_1=0,rho_2=1,alpha_2=0,phi_2=0.1"})
                  .err,
              HasSubstr("--at: rho_1=nan is not a finite number"));
  // Finite, but beyond the range of normal doubles: told which way (they said "not a finite
  // number", and 1e-310 was evaluated with digits lost).
  EXPECT_THAT(Fails({"prior", "eval", "rectangular", "--at",
                     "rho_1=1,alpha_1=1e-330,phi_1=0,rho_2=1,alpha_2=0,phi_2=0.1"})
                  .err,
              HasSubstr("--at: alpha_1=1e-330 underflows: below the smallest normal magnitude"));
  EXPECT_THAT(Fails({"prior", "eval", "rectangular", "--at",
                     "rho_1=1,alpha_1=1e-310,phi_1=0,rho_2=1,alpha_2=0,phi_2=0.1"})
                  .err,
              HasSubstr("--at: alpha_1=1e-310 underflows"));
  EXPECT_THAT(Fails({"prior", "eval", "rectangular", "--at",
                     "rho_1=1e999,alpha_1=0,phi_1=0,rho_2=1,alpha_2=0,phi_2=0.1"})
                  .err,
              HasSubstr("--at: rho_1=1e999 overflows: above the largest number"));
}

TEST_F(Cli, PriorListWarnsOfAPriorThatParsesButDoesNotCompile) {
  fs::create_directory(Work("lib"));
  WriteAll(Work("lib/typo.prior"), "name: Typo\norder: 1\npriorlet same_region:\n  rho_1 == rh\n");
  const RunResult r = Run({"prior", "list", "--prior-path", "lib"});
  EXPECT_EQ(r.status, 0);
  EXPECT_THAT(r.out, StartsWith("Typo "));
  EXPECT_THAT(r.err, HasSubstr("priormap: warning: 'Typo' does not compile, lib/typo.prior:4:12: "
                               "unknown name 'rh'"));
  EXPECT_THAT(Ok({"prior", "list"}).err, Not(HasSubstr("warning")));
}

// A constraint on constants is a mistake: one that never holds refuses the prior, one that
// always holds is a warning from every command that loads the prior, which then goes on.
TEST_F(Cli, ConstraintsOnConstantsAreReportedByEveryCommandThatLoadsThePrior) {
  WriteAll(Work("never.prior"),
           "name: Never\nspecializes: Polygonal prior\npriorlet same_region:\n  1 == 2\n");
  WriteAll(Work("always.prior"),
           "name: Always\nspecializes: Polygonal prior\npriorlet different_region:\n  1 <= 2\n");
  Ok({"simulate", "--scene", "square", "-o", "sq.json"});
  const std::string warning =
      "priormap: warning: always.prior:4:3: this constraint uses no variable "
      "and always holds";
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"prior", "check", "always.prior"},
        std::vector<std::string>{"scan", "--prior", "always.prior", "-i", "sq.json", "-o",
                                 "m.json"}}) {
    const RunResult r = Run(args);
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_THAT(r.err, HasSubstr(warning)) << args[0];
  }
  EXPECT_THAT(Fails({"prior", "check", "never.prior"}).err,
              HasSubstr("never.prior:4:3: this constraint uses no variable and never holds"));
  EXPECT_THAT(Fails({"scan", "--prior", "never.prior", "-i", "sq.json", "-o", "n.json"}).err,
              HasSubstr("never.prior:4:3: this constraint uses no variable and never holds"));
  EXPECT_FALSE(fs::exists(Work("n.json")));
}

TEST_F(Cli, PriorCheckSummarisesTheResolvedPrior) {
  const RunResult r = Ok({"prior", "check", "rectangular"});
  EXPECT_THAT(r.out, StartsWith("Rectangular prior (<builtin>/rectangular.prior)\n"));
  EXPECT_THAT(r.out, HasSubstr("  specializes: Polygonal prior (<builtin>/polygonal.prior)\n"));
  EXPECT_THAT(r.out, HasSubstr("  order: 2   max_curvature: 0 1/m\n"));
  EXPECT_THAT(
      r.out,
      HasSubstr("  same_region:       2 equalities, 0 inequalities, 0 disjunctions, 0 energies (2 "
                "scalar terms); uses rho_1 rho_2 alpha_1 alpha_2 phi_1 phi_2\n"));
  EXPECT_THAT(
      r.out,
      HasSubstr("  different_region:  0 equalities, 0 inequalities, 1 disjunction, 0 energies (2 "
                "scalar terms); uses alpha_1 alpha_2\n"));
  EXPECT_THAT(r.out, HasSubstr("  different_surface: none (no constraint)\n"));
  EXPECT_THAT(r.out, Not(HasSubstr("pose independence")));
}

// A prior without max_curvature has none, not "none 1/m".
TEST_F(Cli, PriorCheckOfAPriorWithoutACurvatureBoundSaysNone) {
  WriteAll(Work("flat.prior"),
           "name: Flat\norder: 2\npriorlet same_region:\n  alpha_1 == alpha_2\n");
  EXPECT_THAT(Ok({"prior", "check", "flat.prior"}).out,
              HasSubstr("  order: 2   max_curvature: none\n"));
}

TEST_F(Cli, PriorCheckOfAFileFindsItsParentNextToIt) {
  WriteAll(Work("facing.prior"), kPoseDependentPrior);
  WriteAll(Work("child.prior"),
           "name: Child\nspecializes: Facing\npriorlet different_surface:\n  rho_1 >= 0.5\n");
  const RunResult r = Ok({"prior", "check", "child.prior"});
  EXPECT_THAT(r.out, StartsWith("Child (child.prior)\n"));
  EXPECT_THAT(r.out, HasSubstr("specializes: Facing ("));
  EXPECT_THAT(r.out, HasSubstr("facing.prior)"));
  EXPECT_THAT(r.out, HasSubstr("different_surface: 0 equalities, 1 inequality"));
}

TEST_F(Cli, PriorCheckPoseIndependenceWarnsAboutAPoseDependentTerm) {
  WriteAll(Work("facing.prior"), kPoseDependentPrior);
  const RunResult r = Run({"prior", "check", "facing.prior", "--pose-independence", "--seed", "4"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.err,
              StartsWith("priormap: warning: facing.prior:6: 'alpha_1 == 0' (same_region) is not "
                         "pose-independent"));
  EXPECT_THAT(r.err, Not(HasSubstr("alpha_1 == alpha_2")));
  EXPECT_THAT(r.out, HasSubstr("pose independence: 1 term(s) changed under rigid motions"));
  // The same seed gives the same warning.
  EXPECT_EQ(Run({"prior", "check", "facing.prior", "--pose-independence", "--seed", "4"}).err,
            r.err);
}

TEST_F(Cli, PriorCheckPoseIndependenceOfABuiltinIsOk) {
  const RunResult r = Ok({"prior", "check", "circular-radius", "--pose-independence"});
  EXPECT_THAT(r.out, HasSubstr("pose independence: ok"));
}

TEST_F(Cli, PriorShowPrintsTermsAndOptionallyTheirDerivatives) {
  const RunResult plain = Ok({"prior", "show", "polygonal"});
  EXPECT_THAT(plain.out, StartsWith("Polygonal prior, priorlet same_region:\n"));
  EXPECT_THAT(plain.out,
              HasSubstr("  term 1 (equality; <builtin>/polygonal.prior:9: alpha_1 == alpha_2)\n"
                        "    f = alpha_1 - alpha_2\n"));
  EXPECT_THAT(plain.out, Not(HasSubstr("df/")));
  EXPECT_THAT(plain.out, HasSubstr("  tape: "));

  const RunResult derivatives = Ok({"prior", "show", "polygonal", "--derivatives"});
  EXPECT_THAT(derivatives.out, HasSubstr("    f = alpha_1 - alpha_2\n"
                                         "    df/dalpha_1 = 1\n"
                                         "    df/dalpha_2 = -1\n"));
  EXPECT_THAT(derivatives.out,
              HasSubstr("    df/drho_1 = -cos(phi_1)*cos(alpha_1) - sin(phi_1)*sin(alpha_1)\n"));
  EXPECT_THAT(derivatives.out, Not(HasSubstr("df/drho_1 = 0")));  // zero derivatives are left out

  const RunResult disjunction = Ok({"prior", "show", "rectangular"});
  EXPECT_THAT(disjunction.out,
              HasSubstr("(equality, disjunction 1 branch 2; <builtin>/rectangular.prior:5:"));
}

TEST_F(Cli, PriorEvalPrintsValuesGradientsAndHessians) {
  const RunResult r = Ok(kPolygonalEval);
  EXPECT_THAT(r.out, StartsWith("term 1 (equality: alpha_1 == alpha_2)\n"
                                "  value: 0.4\n"
                                "  gradient [rho_1, rho_2, alpha_1, alpha_2]:\n"
                                "    0 0 1 -1\n"
                                "  Hessian:\n"
                                "    0 0 0 0\n"));
  EXPECT_THAT(r.out,
              HasSubstr("term 2 (equality: (p_2 - p_1)' * [cos(alpha_1); sin(alpha_1)] == 0)\n"));
  // (p_2 - p_1)' (cos 0.3, sin 0.3)
  const double value = (2 * std::cos(0.5) - 1) * std::cos(0.3) + 2 * std::sin(0.5) * std::sin(0.3);
  const std::size_t term2 = r.out.find("term 2 ");
  ASSERT_NE(term2, std::string::npos) << r.out;
  const std::size_t value_at = r.out.find("\n  value: ", term2);
  ASSERT_NE(value_at, std::string::npos) << r.out;
  EXPECT_NEAR(std::stod(r.out.substr(value_at + 10)), value, 1e-12);
  EXPECT_TRUE(WorkFiles().empty());
}

TEST_F(Cli, PriorEvalOfAnotherBlock) {
  const RunResult r = Ok({"prior", "eval", "rectangular", "--block", "different_region", "--at",
                          "rho_1=1,rho_2=2,alpha_1=0,alpha_2=0,phi_1=0,phi_2=0.5"});
  EXPECT_THAT(
      r.out,
      HasSubstr("term 1 (equality: alpha_2 == alpha_1 - pi / 2 || alpha_2 == alpha_1 + pi / 2)\n"));
  EXPECT_THAT(r.out, HasSubstr("term 2 "));
  EXPECT_THAT(r.out, Not(HasSubstr("term 3 ")));
}

TEST_F(Cli, PriorErrorsNameTheProblem) {
  EXPECT_THAT(Fails({"prior", "check", "no-such-prior"}).err,
              HasSubstr("no prior file or prior named 'no-such-prior'"));
  EXPECT_EQ(Fails({"prior", "show", "no-such-prior"}).status, 1);

  std::vector<std::string> args = kPolygonalEval;
  args.back() = "rho_1=1,rho_2";
  EXPECT_THAT(Fails(args).err,
              HasSubstr("--at: expected name=value pairs separated by commas, got 'rho_2'"));
  args.back() = "rho_1=1,rho_2=x,alpha_1=0.3,alpha_2=-0.1,phi_1=0,phi_2=0.5";
  EXPECT_THAT(Fails(args).err, HasSubstr("got 'rho_2=x'"));
  args.back() = "rho_1=1,rho_2=2,alpha_1=0.3,phi_1=0,phi_2=0.5";
  EXPECT_THAT(Fails(args).err, HasSubstr("--at: missing a value for alpha_2"));
  args.back() = "rho_1=1,rho_2=2,rho_1=3,alpha_1=0.3,alpha_2=-0.1,phi_1=0,phi_2=0.5";
  EXPECT_THAT(Fails(args).err, HasSubstr("--at: rho_1 is given twice"));
  args.back() = "rho_1=1,rho_2=2,alpha_1=0.3,alpha_2=-0.1,phi_1=0,phi_2=0.5,rho_3=1";
  EXPECT_THAT(Fails(args).err,
              HasSubstr("--at: 'rho_3' is not a variable of this prior (order 2)"));

  args = kPolygonalEval;
  args.insert(args.end(), {"--block", "corner"});
  EXPECT_THAT(Fails(args).err,
              HasSubstr("--block: expected same_region, different_region or different_surface, "
                        "got 'corner'"));
  args.back() = "different_surface";
  EXPECT_THAT(Fails(args).err, HasSubstr("the prior 'Polygonal prior' has no such block"));

  EXPECT_THAT(Fails({"prior", "eval", "polygonal"}).err, HasSubstr("--at"));
  // A --prior-path that does not exist is a typo, not an empty library.
  EXPECT_THAT(Fails({"prior", "list", "--prior-path", "no-such-dir"}).err,
              HasSubstr("--prior-path: Directory does not exist: no-such-dir"));
  Fails({"prior"});  // a subcommand is required
  Fails({"prior", "check"});
}

TEST_F(Cli, PriorFileErrorsAreLocated) {
  WriteAll(Work("bad.prior"), "name: Bad\norder: 2\npriorlet same_region:\n  rho_3 == 1\n");
  const RunResult r = Fails({"prior", "check", "bad.prior"});
  EXPECT_THAT(
      r.err,
      HasSubstr("priormap: error: bad.prior:4:3: 'rho_3': index 3 is above the prior's order 2"));
  EXPECT_EQ(r.status, 1);
  WriteAll(Work("orphan.prior"), "name: Orphan\nspecializes: Nobody\n");
  EXPECT_THAT(Fails({"prior", "show", "orphan.prior"}).err,
              HasSubstr("priormap: error: orphan.prior:2:14: unknown prior 'Nobody'"));
}

}  // namespace
}  // namespace priormap

namespace priormap {
namespace {

TEST_F(Cli, ScanWritesTheMapScanOfOneScan) {
  Ok({"simulate", "--scene", "square", "--sensor", "lms200", "--seed", "2", "--pose",
      "0.3,-0.2,0.4", "-o", "s.json"});
  const RunResult r = Ok({"scan", "--prior", "rectangular", "-i", "s.json", "-o", "map.json"});
  EXPECT_THAT(r.out, HasSubstr("wrote map.json"));
  const nlohmann::json map = nlohmann::json::parse(ReadAll(Work("map.json")));
  EXPECT_EQ(map["format"], "priormap.map_scan");
  EXPECT_EQ(map["prior"], "Rectangular prior");
  EXPECT_TRUE(map["feasible"].get<bool>());
  for (const char* key : {"rho", "alpha", "inmodel"}) EXPECT_EQ(map[key].size(), 181u) << key;
  EXPECT_EQ(map["topology"].size() + 1, map["inmodel_beams"].size());
  EXPECT_GT(map["stats"]["newton_steps"].get<int>(), 0);
  EXPECT_EQ(WorkFiles(), (std::set<std::string>{"s.json", "map.json"}));
  // Sec. IV: one orientation and an offset per wall in view (the lms200's 180 degrees see three
  // of the four), 3 of them a sensor motion.
  const std::size_t walls = map["regions"].size();
  EXPECT_EQ(walls, 3u);
  EXPECT_EQ(map["dof"]["free"], walls + 1);
  EXPECT_EQ(map["dof"]["extrinsic"], 3);
  EXPECT_EQ(map["dof"]["intrinsic"], walls - 2);
  EXPECT_TRUE(map["posterior"]["computed"].get<bool>());
  EXPECT_EQ(map["posterior"]["covariance"], "conditional");
  for (const char* key : {"posterior_std", "prior_std", "posterior_std_alpha"}) {
    EXPECT_EQ(map[key].size(), 181u) << key;
  }
  ASSERT_EQ(map["eigenvariations"].size(), walls + 1);
  EXPECT_EQ(map["eigenvariations"][0]["rho"].size(), 181u);
  EXPECT_EQ(map["intrinsic_eigenvariations"].size(), walls - 2);
  const std::size_t beam = map["inmodel_beams"][90].get<std::size_t>();
  EXPECT_LT(map["posterior_std"][beam].get<double>(), map["prior_std"][beam].get<double>());

  Ok({"scan", "--prior", "rectangular", "-i", "s.json", "-o", "projected.json", "--covariance",
      "projected", "--eigenvariations", "2"});
  const nlohmann::json projected = nlohmann::json::parse(ReadAll(Work("projected.json")));
  EXPECT_EQ(projected["posterior"]["covariance"], "projected");
  EXPECT_EQ(projected["eigenvariations"].size(), 2u);
}

TEST_F(Cli, ScanWritesTheWallsAsLineSegmentsOfOneScan) {
  Ok({"simulate", "--scene", "square", "--sensor", "lms200", "--seed", "2", "--pose",
      "0.3,-0.2,0.4", "-o", "s.json"});
  const RunResult r = Ok({"scan", "--prior", "rectangular", "-i", "s.json", "-o", "map.json",
                          "--lines", "lines.json"});
  EXPECT_THAT(r.out, HasSubstr("wrote lines.json (3 line segments)"));
  const nlohmann::json lines = nlohmann::json::parse(ReadAll(Work("lines.json")));
  EXPECT_EQ(lines["format"], "priormap.line_segments");
  EXPECT_EQ(lines["covariance_source"], "posterior");
  // The square's walls are 2 m from its centre: from (0.3, -0.2) they lie 1.7, 2.2, 2.3 or 1.8 m
  // away; seen in the sensor frame their normals are 90 degrees apart.
  ASSERT_EQ(lines["line_segments"].size(), 3u);
  std::vector<double> radii;
  for (const auto& segment : lines["line_segments"]) {
    radii.push_back(segment["radius"].get<double>());
    EXPECT_EQ(segment["covariance"].size(), 4u);
    EXPECT_GT(segment["covariance"][0].get<double>(), 0.0);
    EXPECT_LT(segment["covariance"][0].get<double>(), 1e-4);  // sigma_r < 1 cm
  }
  std::sort(radii.begin(), radii.end());
  for (const double radius : radii) {
    const bool near_a_wall = std::abs(radius - 1.7) < 0.02 || std::abs(radius - 2.2) < 0.02 ||
                             std::abs(radius - 2.3) < 0.02 || std::abs(radius - 1.8) < 0.02;
    EXPECT_TRUE(near_a_wall) << radius;
  }
  const RunResult all = Fails({"scan", "--prior", "rectangular", "-i", "s.json", "-o", "m.jsonl",
                               "--all", "--lines", "l.json"});
  EXPECT_THAT(all.err, HasSubstr("--lines writes one scan's segments"));
}

TEST_F(Cli, ScanAllWritesJsonLinesForEveryScanOfALog) {
  Ok({"simulate", "--scene", "square", "--sensor", "lms200", "--log", "--seed", "3", "-o",
      "run.json"});
  const std::size_t scans = ReadLogFile("run.json").scans.size();
  ASSERT_GT(scans, 2u);
  const RunResult r =
      Run({"scan", "--prior", "polygonal", "--log", "run.json", "--all", "-o", "maps.jsonl"});
  ASSERT_EQ(r.status, 0) << r.err;
  // Progress goes to stderr, a line every 10 % when stderr is not a terminal.
  EXPECT_THAT(r.err, HasSubstr(std::to_string(scans) + "/" + std::to_string(scans) + " scans"));
  const std::string text = ReadAll(Work("maps.jsonl"));
  std::size_t lines = 0, start = 0;
  for (std::size_t end = text.find('\n'); end != std::string::npos;
       start = end + 1, end = text.find('\n', start)) {
    const nlohmann::json line = nlohmann::json::parse(text.substr(start, end - start));
    EXPECT_EQ(line["scan_index"].get<std::size_t>(), lines);
    EXPECT_FALSE(line.contains("error")) << line["error"];
    ++lines;
  }
  EXPECT_EQ(lines, scans);
}

TEST_F(Cli, ScanDrawsTheFigureOfOneScanAsPngAndSvg) {
  Ok({"simulate", "--scene", "square", "--sensor", "lms200", "--seed", "2", "-o", "s.json"});
  const RunResult r = Ok({"scan", "--prior", "rectangular", "--input", "s.json", "-o", "out.json",
                          "--png", "fig.png", "--svg", "fig.svg"});
  EXPECT_THAT(r.out, HasSubstr("wrote fig.png"));
  EXPECT_THAT(r.out, HasSubstr("wrote fig.svg"));
  EXPECT_EQ(WorkFiles(), (std::set<std::string>{"s.json", "out.json", "fig.png", "fig.svg"}));
  const std::string png = ReadAll(Work("fig.png"));
  EXPECT_TRUE(IsPng(png));
  EXPECT_EQ(PngSize(png).first, 1400);
  const std::string svg = ReadAll(Work("fig.svg"));
  EXPECT_THAT(svg, StartsWith("<?xml"));
  EXPECT_THAT(svg, ContainsRegex("<svg[ >]"));
  EXPECT_THAT(svg, HasSubstr("</svg>"));
  // The JSON is the same as without a figure.
  EXPECT_EQ(nlohmann::json::parse(ReadAll(Work("out.json")))["format"], "priormap.map_scan");
}

TEST_F(Cli, ScanFigureErrorsNameTheProblem) {
  Ok({"simulate", "--scene", "square", "--sensor", "lms200", "--log", "--seed", "3", "-o",
      "run.json"});
  EXPECT_THAT(Fails({"scan", "--prior", "rectangular", "-i", "run.json", "--all", "-o", "m.jsonl",
                     "--png", "fig.png"})
                  .err,
              HasSubstr("--png draws one scan, not --all"));
  EXPECT_THAT(
      Fails({"scan", "--prior", "rectangular", "-i", "run.json", "-o", "m.json", "--svg", "f.png"})
          .err,
      HasSubstr("--svg: 'f.png' must end in .svg"));
  EXPECT_THAT(Fails({"scan", "--prior", "rectangular", "-i", "run.json", "-o", "m.json", "--png",
                     "missing/f.png"})
                  .err,
              HasSubstr("directory missing does not exist"));
}

// A prior whose term leaves its domain at the data (the square root of a negative number) gives
// an infeasible MAP scan, infinitely violated, without degrees of freedom: not an internal error.
TEST_F(Cli, AScanUnderAPriorOutsideItsDomainIsInfeasible) {
  Ok({"simulate", "--scene", "l-room", "--seed", "1", "-o", "s.json"});
  WriteAll(Work("sqrt.prior"),
           "name: Square-root walls\nspecializes: Polygonal prior\npriorlet same_region:\n"
           "  sqrt(rho_1 - 100) == rho_2\n");
  Ok({"scan", "--prior", "sqrt.prior", "-i", "s.json", "-o", "m.json"});
  const nlohmann::json map = nlohmann::json::parse(ReadAll(Work("m.json")));
  EXPECT_FALSE(map["feasible"].get<bool>());
  EXPECT_EQ(map["max_violation"], "inf");
  EXPECT_FALSE(map["posterior"]["computed"].get<bool>());
  EXPECT_THAT(map["posterior"]["note"].get<std::string>(), HasSubstr("violates the prior by inf"));
}

// Infinite readings keep their value in the MAP scan, written as our JSON writes infinities.
TEST_F(Cli, AScanKeepsInfiniteReadingsAsInf) {
  Ok({"simulate", "--scene", "square", "--sensor", "lms200", "-o", "s.json"});
  nlohmann::json log = nlohmann::json::parse(ReadAll(Work("s.json")));
  ASSERT_TRUE(log.contains("ranges"));
  log["ranges"][0] = "inf";
  log["ranges"][1] = "-inf";
  WriteAll(Work("inf.json"), log.dump());
  Ok({"scan", "--prior", "rectangular", "-i", "inf.json", "-o", "m.json"});
  const nlohmann::json map = nlohmann::json::parse(ReadAll(Work("m.json")));
  EXPECT_FALSE(map["inmodel"][0].get<bool>());
  EXPECT_EQ(map["rho"][0], "inf");
  EXPECT_EQ(map["rho"][1], "-inf");
}

// --all writes every scan's record, a failed scan's error too, and exits 1 when any failed.
TEST_F(Cli, ScanAllExitsWithAnErrorWhenSomeScansFailedAfterWritingEveryRecord) {
  Ok({"simulate", "--scene", "square", "--sensor", "lms200", "--log", "--seed", "3", "-o",
      "run.json"});
  // sqrt(abs(x)) has no derivative at x = 0, where the MAP puts the same region's normals.
  WriteAll(Work("kink.prior"),
           "name: Kinked walls\nspecializes: Polygonal prior\npriorlet same_region:\n"
           "  sqrt(abs(alpha_1 - alpha_2)) == 0\n");
  // Run, not Fails: a failing command here writes its output, by design.
  const RunResult r =
      Run({"scan", "--prior", "kink.prior", "--log", "run.json", "--all", "-o", "all.jsonl"});
  EXPECT_EQ(r.status, 1);
  EXPECT_THAT(r.err, ContainsRegex("[0-9]+ of [0-9]+ scans failed; their records in all.jsonl"));
  const std::string text = ReadAll(Work("all.jsonl"));
  std::size_t records = 0, errors = 0;
  for (std::size_t start = 0, end = text.find('\n'); end != std::string::npos;
       start = end + 1, end = text.find('\n', start)) {
    const nlohmann::json line = nlohmann::json::parse(text.substr(start, end - start));
    ++records;
    if (line.contains("error")) {
      ++errors;
      EXPECT_THAT(line["error"].get<std::string>(), HasSubstr("is not finite at the estimate"));
    }
  }
  EXPECT_EQ(records, ReadLogFile("run.json").scans.size());
  EXPECT_GT(errors, 0u);
  EXPECT_LT(errors, records);
}

TEST_F(Cli, ScanErrorsNameTheProblem) {
  Ok({"simulate", "--scene", "square", "--sensor", "lms200", "-o", "s.json"});
  EXPECT_THAT(
      Fails({"scan", "--prior", "rectangular", "-i", "s.json", "--index", "5", "-o", "m.json"}).err,
      HasSubstr("--index 5: s.json has 1 scan"));
  EXPECT_THAT(Fails({"scan", "--prior", "no-such-prior", "-i", "s.json", "-o", "m.json"}).err,
              HasSubstr("no-such-prior"));
  EXPECT_FALSE(fs::exists(Work("m.json")));
  // Outputs that would overwrite the input or each other, before any work.
  EXPECT_THAT(Fails({"scan", "--prior", "rectangular", "-i", "s.json", "-o", "./s.json"}).err,
              HasSubstr("-i/--log s.json and -o/--out ./s.json are the same file"));
  EXPECT_THAT(
      Fails({"scan", "--prior", "rectangular", "-i", "s.json", "-o", "m.json", "--lines", "m.json"})
          .err,
      HasSubstr("-o/--out m.json and --lines m.json are the same file"));
  // An option the input's reader would ignore.
  EXPECT_THAT(
      Fails({"scan", "--prior", "rectangular", "-i", "s.json", "-o", "m.json", "--max-range", "2"})
          .err,
      HasSubstr("--max-range is for CARMEN input: s.json is json"));
  EXPECT_THAT(Fails({"plot", "s.json", "-o", "p.png", "--max-range", "2"}).err,
              HasSubstr("--max-range is for CARMEN input"));
  // --all checks where it writes before it estimates every scan.
  EXPECT_THAT(
      Fails({"scan", "--prior", "rectangular", "--log", "s.json", "--all", "-o", "no/m.jsonl"}).err,
      HasSubstr("directory no does not exist"));
  EXPECT_EQ(WorkFiles(), (std::set<std::string>{"s.json"}));
}

TEST_F(Cli, SimulateRefusesOptionsOfTheOtherKindOfOutputAndAbsurdLogs) {
  EXPECT_THAT(Fails({"simulate", "--speed", "3", "-o", "s.json"}).err,
              HasSubstr("--speed and --rate set the trajectory of --log"));
  EXPECT_THAT(Fails({"simulate", "--log", "--pose", "1,1,0", "-o", "s.json"}).err,
              HasSubstr("--pose places a single scan"));
  EXPECT_THAT(Fails({"simulate", "--log", "--speed", "1e-300", "-o", "s.json"}).err,
              HasSubstr("more than 1e+07"));
  // A log of one scan that never moves; one that would not fit in memory.
  EXPECT_THAT(Fails({"simulate", "--log", "--speed", "100", "-o", "s.json"}).err,
              HasSubstr("the log would hold one scan"));
  EXPECT_THAT(Fails({"simulate", "--scene", "office", "--sensor", "pioneer16", "--log", "--rate",
                     "190000", "-o", "s.json"})
                  .err,
              HasSubstr("would take about 77 GB of memory, more than 8 GB"));
  EXPECT_THAT(Fails({"simulate", "--beams", "100000000", "-o", "s.json"}).err,
              HasSubstr("a scan of 100000000 readings would take about 15 GB"));
  // Outputs named for no log format, or that are directories, fail before anything is written.
  EXPECT_THAT(Fails({"simulate", "-o", "s.png"}).err,
              HasSubstr("--out s.png: no log format has this extension"));
  EXPECT_THAT(Fails({"simulate", "--write-scene", "w.json", "--png", "w.png"}).err,
              HasSubstr("--png draws the simulated scan or log: give --out too"));
  fs::create_directory(Work("d.png"));
  EXPECT_THAT(Fails({"simulate", "-o", "s.json", "--write-scene", "w.json", "--png", "d.png"}).err,
              HasSubstr("--png: cannot write 'd.png': it is a directory"));
  fs::remove(Work("d.png"));
  EXPECT_THAT(Fails({"simulate", "--sensor", "nope", "-o", "s.json"}).err,
              HasSubstr("or a sonar ring: pioneer8, pioneer16, robond"));
  EXPECT_EQ(WorkFiles(), std::set<std::string>{});
}

TEST_F(Cli, ConvertSaysWhereEachScansMaxRangeComesFrom) {
  WriteAll(Work("mixed.log"),
           "ROBOTLASER1 0 -1.5 3 0.01 8 0.01 0 3 1 2 9 0 0 0 0 0 0 0 0 0 0 0 0\n"
           "FLASER 3 1 2 3 0 0 0 0 0 0\n");
  EXPECT_THAT(Ok({"convert", "mixed.log", "-o", "a.json"}).out,
              HasSubstr("max range: 8 m (1 scan), none (1 scan) (the ROBOTLASER1 records' own; "
                        "none: no reading of a scan without one is max-range)\n"));
  EXPECT_THAT(Ok({"convert", "mixed.log", "-o", "b.json", "--max-range", "5"}).out,
              HasSubstr("max range: 5 m (--max-range 5 m where the sensor's is longer; the "
                        "ROBOTLASER1 records' own)\n"));
  WriteAll(Work("flaser.log"), "FLASER 3 1 2 3 0 0 0 0 0 0\n");
  EXPECT_THAT(Ok({"convert", "flaser.log", "-o", "c.json"}).out,
              HasSubstr("max range: none detected; no reading is treated as max-range"));
  // A log without scans has no max range to tell of, with or without --max-range.
  WriteAll(Work("odom.log"),
           "PARAM robot_front_laser_max 81.9 nohost 0 logger\n"
           "ODOM 0 0 0 0 0 0 1 nohost 1\n");
  EXPECT_THAT(Ok({"convert", "odom.log", "-o", "d.json"}).out,
              HasSubstr("read odom.log (carmen): 0 scans, 1 odometry, 0 true poses, 1 params\n"
                        "readings: 0 valid, 0 max-range, 0 invalid\n"
                        "max range: none (no scans)\n"
                        "wrote d.json (json)\n"));
  EXPECT_THAT(Ok({"convert", "odom.log", "-o", "e.json", "--max-range", "5"}).out,
              HasSubstr("max range: none (no scans)\n"));
}

TEST_F(Cli, SimulateRefusesWaypointsThatMakeNoPath) {
  Ok({"simulate", "--scene", "square", "--write-scene", "square.json"});
  nlohmann::json scene = nlohmann::json::parse(ReadAll(Work("square.json")));
  scene["waypoints"] = {{0, 0}, {0, 0}};
  WriteAll(Work("still.json"), scene.dump());
  EXPECT_THAT(Fails({"simulate", "--scene", "still.json", "--log", "-o", "s.json"}).err,
              HasSubstr("the waypoints of scene 'square' all coincide"));
}

TEST_F(Cli, ConvertRefusesOptionsTheInputsReaderWouldIgnore) {
  Ok({"simulate", "--scene", "square", "--sensor", "lms200", "-o", "s.json"});
  for (const char* option : {"--max-range", "--min-range", "--sigma"})
    EXPECT_THAT(Fails({"convert", "s.json", "-o", "c.json", option, "1"}).err,
                HasSubstr(std::string(option) + " is for other formats: s.json is json"))
        << option;
  EXPECT_THAT(Fails({"convert", "s.json", "-o", "c.json", "--fov", "90"}).err,
              HasSubstr("--fov is for other formats"));
  EXPECT_THAT(Fails({"convert", "s.json", "-o", "c.json", "--fov", "0"}).err,
              HasSubstr("not in range 0.01"));
  EXPECT_THAT(Fails({"convert", "s.json", "-o", "c.svg"}).err,
              HasSubstr("--out c.svg: no log format has this extension"));
  OkLosingToCarmen({"simulate", "--scene", "square", "--sensor", "lms200", "-o", "s.log"},
                   "the ground truth of 1 scan");
  EXPECT_THAT(
      Fails({"convert", "s.log", "-o", "c.json", "--min-range", "5", "--max-range", "2"}).err,
      HasSubstr("--min-range 5 must be below --max-range 2"));
  EXPECT_FALSE(fs::exists(Work("c.json")));
}

// A command whose output is lost must not report success: `priormap prior list > /dev/full`
// wrote nothing and exited 0.
TEST_F(Cli, AFailedWriteToStandardOutputIsAnError) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  const fs::path err = Work("stderr");
  const std::string command =
      fmt::format("{} prior list >/dev/full 2>{}", priormap::testing::ShellQuote(PRIORMAP_BINARY),
                  priormap::testing::ShellQuote(err.string()));
  const int raw = std::system(command.c_str());
  ASSERT_TRUE(raw != -1 && WIFEXITED(raw)) << raw;
  EXPECT_EQ(WEXITSTATUS(raw), 1);
  EXPECT_EQ(priormap::testing::ReadAll(err),
            "priormap: error: cannot write to standard output: No space left on device\n");
}

}  // namespace
}  // namespace priormap
