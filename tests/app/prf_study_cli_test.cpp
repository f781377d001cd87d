// End-to-end test of `priormap prf study`: a tiny study writes its summary (scores per case and
// overall), its markdown table and the figures of each case; bad options are reported without
// output.
#include <filesystem>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_fixture.hpp"
#include "testing/temp_dir.hpp"

namespace priormap {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

class PrfStudyCli : public priormap::testing::CliFixture {};

TEST_F(PrfStudyCli, WritesSummaryTableAndFigures) {
  const auto r = Run({"prf",          "study",   "--scenes",  "square",      "--sensors",
                      "lms200,utm30", "--poses", "2",         "--beam-step", "6",
                      "--samples",    "3000",    "--burn-in", "3000",        "--anneal-steps",
                      "3000",         "--seed",  "3",         "-o",          "out"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("| square/lms200 | 62 |"));
  const json summary = json::parse(testing::ReadAll(Work("out") / "summary.json"));
  EXPECT_EQ(summary["format"], "priormap.prf_study");
  EXPECT_EQ(summary["options"]["poses"], 2);
  ASSERT_EQ(summary["cases"].size(), 2u);
  const json& c = summary["cases"][0];
  EXPECT_EQ(c["scene"], "square");
  EXPECT_EQ(c["sensor"], "lms200");
  EXPECT_EQ(c["beams"], 62);  // 31 of 181 beams from each of two poses
  for (const char* method : {"grid", "prf posterior", "prf map"}) {
    const json& m = c["methods"][method];
    EXPECT_GT(m["observed"]["points"].get<int>(), 1000) << method;
    EXPECT_EQ(m["observed"]["points"], c["methods"]["grid"]["observed"]["points"]) << method;
    EXPECT_LE(m["observed"]["accuracy"].get<double>(), 1.0) << method;
  }
  EXPECT_TRUE(c["map"].contains("mean_distance_m"));
  EXPECT_TRUE(summary["overall"].contains("prf posterior"));
  EXPECT_THAT(testing::ReadAll(Work("out") / "table.md"), HasSubstr("| **all** |"));
  for (const char* figure : {"truth", "grid", "posterior", "map"})
    EXPECT_TRUE(testing::IsPng(
        testing::ReadAll(Work("out") / "square-utm30" / (std::string(figure) + ".png"))))
        << figure;

  // Again without annealing: no MAP map, so none of the last run's may stay beside the numbers.
  const auto again =
      Run({"prf",       "study", "--scenes",       "square", "--sensors", "lms200,utm30",
           "--poses",   "2",     "--beam-step",    "6",      "--samples", "3000",
           "--burn-in", "3000",  "--anneal-steps", "0",      "--seed",    "3",
           "-o",        "out"});
  ASSERT_EQ(again.status, 0) << again.err;
  EXPECT_FALSE(std::filesystem::exists(Work("out") / "square-utm30" / "map.png"));
  EXPECT_TRUE(std::filesystem::exists(Work("out") / "square-utm30" / "posterior.png"));
  EXPECT_THAT(again.out, HasSubstr("{truth,grid,posterior}.png"));
}

TEST_F(PrfStudyCli, RejectsUnknownScenesAndSensors) {
  EXPECT_THAT(RunFailing({"prf", "study", "--sensors", "sonar9", "-o", "out"}).err,
              HasSubstr("unknown sensor 'sonar9'"));
  EXPECT_THAT(RunFailing({"prf", "study", "--scenes", "no-such-scene", "-o", "out"}).err,
              HasSubstr("no-such-scene"));
  EXPECT_NE(RunFailing({"prf", "study", "--poses", "0", "-o", "out"}).status, 0);
}

// Settings that would score nothing meaningful, or would end in an internal error, are refused
// before any work.
TEST_F(PrfStudyCli, RefusesDegenerateStudies) {
  const auto refused = [&](std::vector<std::string> args) { return RunFailing(args).err; };
  EXPECT_THAT(refused({"prf", "study", "--samples", "0", "-o", "out"}),
              HasSubstr("at least one sample"));
  EXPECT_THAT(refused({"prf", "sonar-study", "--samples", "0", "-o", "out"}),
              HasSubstr("at least one sample"));
  EXPECT_THAT(refused({"prf", "study", "--resolution", "10", "-o", "out"}),
              HasSubstr("at most 1 m"));
  EXPECT_THAT(refused({"prf", "study", "--scenes", "square,square", "-o", "out"}),
              HasSubstr("scene 'square' is given twice"));
  EXPECT_THAT(refused({"prf", "study", "--sensors", "utm30,utm30", "-o", "out"}),
              HasSubstr("sensor 'utm30' is given twice"));
  const std::string square =
      R"({"format":"priormap.scene","version":1,"name":"z","surfaces":[{"type":"polyline",)"
      R"("points":[[-2,-2],[2,-2],[2,2],[-2,2]],"closed":true}],"default_pose":[0,0,0],)";
  testing::WriteAll(Work("still.json"), square + R"("waypoints":[[0,0],[0,0]]})");
  testing::WriteAll(Work("through.json"), square + R"("waypoints":[[0,0],[3,0]]})");
  EXPECT_THAT(refused({"prf", "sonar-study", "--scenes", "still.json", "-o", "out"}),
              HasSubstr("no waypoint path"));
  EXPECT_THAT(refused({"prf", "study", "--scenes", "through.json", "--poses", "2", "-o", "out"}),
              HasSubstr("meets surface 1"));
  // One pose is the first waypoint's, and the truth is seeded by every waypoint.
  EXPECT_THAT(refused({"prf", "study", "--scenes", "through.json", "--poses", "1", "-o", "out"}),
              HasSubstr("meets surface 1"));
  ASSERT_EQ(Run({"simulate", "--scene", "square", "--sensor", "pioneer16", "--log", "--rate", "1",
                 "-o", "rings.json"})
                .status,
            0);
  EXPECT_THAT(refused({"prf", "fit-sonar", "--log", "rings.json", "--scene", "square",
                       "--max-range", "0.1", "-o", "m.json"}),
              HasSubstr("hear nothing closer than"));
  EXPECT_THAT(refused({"prf", "fit-sonar", "--scenes", "through.json", "-o", "m.json"}),
              HasSubstr("meets surface 1"));
  EXPECT_THAT(refused({"prf", "fit-sonar", "--max-range", "0.01", "-o", "m.json"}),
              HasSubstr("--max-range"));
  EXPECT_FALSE(std::filesystem::exists(Work("out")));
}

}  // namespace
}  // namespace priormap
