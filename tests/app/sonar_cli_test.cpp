// End-to-end tests of the sonar paths of the CLI: `priormap convert --from roboND-sonar` on the
// real files and on malformed ones, `priormap grid` / `priormap prf` on a simulated sonar log
// (picked automatically, or refused when the sensor asked for is not in the log), and
// `priormap prf sonar-study`, stopped (after some steps or by a signal) and resumed.
#include <cmath>
#include <csignal>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <string>
#include <sys/wait.h>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <priormap/core/json_io.hpp>
#include <priormap/core/log_io.hpp>
#include <priormap/core/sonar_simulate.hpp>

#include "cli_fixture.hpp"
#include "testing/temp_dir.hpp"

namespace priormap {
namespace {

using nlohmann::json;
using ::testing::ContainsRegex;
using ::testing::HasSubstr;
using ::testing::Not;

class SonarCli : public priormap::testing::CliFixture {
 protected:
  void WriteText(const std::string& name, const std::string& text) const {
    std::ofstream(Work(name)) << text;
  }
  // A short simulated sonar log of the l-office in the working directory.
  void WriteSonarLog(const std::string& name) const {
    const Scene scene = *BuiltinScene("l-office");
    const auto trajectory = TrajectoryFromWaypoints(scene.waypoints, 1.0, 1.0);
    WriteJsonLog(SimulateSonarLog(scene, *SonarSensor::Preset("pioneer8"), trajectory, 2),
                 Work(name));
  }
  json Summary(const std::string& dir) const {
    return json::parse(testing::ReadAll(Work(dir) / "summary.json"));
  }
};

TEST_F(SonarCli, ConvertsTheRoboNdFilesToOurJson) {
  const auto shared = testing::SharedDataDir();
  if (!shared) GTEST_SKIP() << "../shared/data is absent: no RoboND sonar files to convert";
  const std::string z = (*shared / "sonar-roboND/measurement.txt").string();
  const std::string p = (*shared / "sonar-roboND/poses.txt").string();
  const auto r = Run({"convert", "--from", "roboND-sonar", z, p, "-o", "robond.json"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("413 sonar rings"));
  EXPECT_THAT(r.out, HasSubstr("1068 max-range"));
  const Result<Log> log = ReadJsonLog(Work("robond.json"));
  ASSERT_TRUE(log.ok()) << log.error();
  ASSERT_EQ(log.value().scans.size(), 413u);
  EXPECT_TRUE(log.value().scans[0].sonar.has_value());
  // CARMEN has no cones: refused, nothing written.
  EXPECT_EQ(RunFailing({"convert", "--from", "roboND-sonar", z, p, "-o", "robond.log"}).status, 1);
}

TEST_F(SonarCli, SimulatesSonarRingsAndLogsWithTheirTruth) {
  const auto ring = Run(
      {"simulate", "--scene", "office", "--sensor", "pioneer16", "--seed", "3", "-o", "r.json"});
  ASSERT_EQ(ring.status, 0) << ring.err;
  const Result<Log> one = ReadJsonLog(Work("r.json"));
  ASSERT_TRUE(one.ok()) << one.error();
  ASSERT_EQ(one.value().scans.size(), 1u);
  const Scan& scan = one.value().scans[0];
  ASSERT_TRUE(scan.sonar.has_value());
  EXPECT_EQ(scan.size(), 16u);
  EXPECT_EQ(scan.sonar->true_echo.size(), 16u);
  EXPECT_DOUBLE_EQ(scan.max_range, 5.0);

  const std::vector<std::string> log = {"simulate", "--scene", "office", "--sensor", "pioneer8",
                                        "--log",    "--rate",  "1",      "--seed",   "3"};
  auto first = log, second = log;
  first.insert(first.end(), {"-o", "a.json"});
  second.insert(second.end(), {"-o", "b.json", "--max-range", "4"});
  ASSERT_EQ(Run(first).status, 0);
  ASSERT_EQ(Run(second).status, 0);
  const Result<Log> a = ReadJsonLog(Work("a.json"));
  const Result<Log> b = ReadJsonLog(Work("b.json"));
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_GT(a.value().scans.size(), 20u);
  EXPECT_EQ(a.value().scans[0].size(), 8u);
  EXPECT_DOUBLE_EQ(b.value().scans[0].max_range, 4.0);
  // The same seed gives the same log.
  auto again = log;
  again.insert(again.end(), {"-o", "c.json"});
  ASSERT_EQ(Run(again).status, 0);
  EXPECT_EQ(testing::ReadAll(Work("a.json")), testing::ReadAll(Work("c.json")));

  // Cones do not fit a CARMEN log, and laser options do not fit a ring: refused, nothing written.
  EXPECT_THAT(RunFailing({"simulate", "--sensor", "pioneer8", "--log", "-o", "x.log"}).err,
              HasSubstr("JSON logs only"));
  EXPECT_THAT(RunFailing({"simulate", "--sensor", "pioneer8", "--beams", "9", "-o", "y.json"}).err,
              HasSubstr("lasers only"));
  EXPECT_FALSE(std::filesystem::exists(Work("x.log")));
  EXPECT_FALSE(std::filesystem::exists(Work("y.json")));
}

TEST_F(SonarCli, SonarStudyWritesItsSummaryTableAndFigures) {
  // An earlier study's state of a chain this one does not have.
  std::filesystem::create_directories(Work("study") / "office-pioneer16");
  std::ofstream(Work("study") / "office-pioneer16" / "chain3_last.geojson") << "{}";
  const auto r = Run({"prf",
                      "sonar-study",
                      "--scenes",
                      "office",
                      "--samples",
                      "2000",
                      "--burn-in",
                      "2000",
                      "--chains",
                      "1",
                      "--seed",
                      "2",
                      "--edge-shifts",
                      "1",
                      "--vertex-birth-widths",
                      "0.5,1.5",
                      "--corner-completion",
                      "0.25",
                      "-o",
                      "study"});
  ASSERT_EQ(r.status, 0) << r.err;
  const json summary = Summary("study");
  EXPECT_EQ(summary["format"], "priormap.prf_sonar_study");
  // Every sampler option that changes the chains is in the record.
  EXPECT_EQ(summary["options"]["edge_shifts"], 1.0);
  EXPECT_EQ(summary["options"]["vertex_birth_widths"], json::array({0.5, 1.5}));
  EXPECT_EQ(summary["options"]["corner_completion"]["probability"], 0.25);
  EXPECT_EQ(summary["options"]["delayed_acceptance"], 1);
  EXPECT_EQ(summary["options"]["step_scales"].size(), 3u);
  ASSERT_EQ(summary["cases"].size(), 1u);
  const json& c = summary["cases"][0];
  EXPECT_EQ(c["scene"], "office");
  EXPECT_GT(c["readings"].get<int>(), 1000);
  for (const char* method : {"grid", "prf posterior"}) {
    EXPECT_GT(c["methods"][method]["walls"]["walls_seen"].get<int>(), 30) << method;
    EXPECT_GT(c["methods"][method]["observed"]["points"].get<int>(), 10000) << method;
  }
  EXPECT_THAT(testing::ReadAll(Work("study") / "table.md"), HasSubstr("| office |"));
  for (const char* figure : {"truth.png", "grid.png", "posterior.png"})
    EXPECT_TRUE(testing::IsPng(testing::ReadAll(Work("study") / "office-pioneer16" / figure)));
  // Each chain's log-posterior is its prior plus its likelihood, and the truth's likelihood is
  // given apart from its log-posterior, to tell where chains and truth differ.
  const json& chain = c["chains"][0];
  ASSERT_TRUE(chain.contains("log_prior") && chain.contains("log_likelihood")) << chain.dump();
  ASSERT_TRUE(c.contains("truth_log_likelihood")) << c.dump();
  EXPECT_NEAR(chain["log_prior"].get<double>() + chain["log_likelihood"].get<double>(),
              chain["log_posterior"].get<double>(),
              1e-6 * std::abs(chain["log_posterior"].get<double>()));
  EXPECT_NE(chain["log_prior"].get<double>(), 0.0);
  EXPECT_TRUE(c["truth_log_likelihood"].is_number());
  EXPECT_NE(c["truth_log_likelihood"].get<double>(), c["truth_log_posterior"].get<double>());
  // The chain's last state, as `priormap prf` writes it.
  const json state =
      json::parse(testing::ReadAll(Work("study") / "office-pioneer16" / "chain0_last.geojson"));
  EXPECT_EQ(state["type"], "FeatureCollection");
  EXPECT_FALSE(std::filesystem::exists(Work("study") / "office-pioneer16" / "chain3_last.geojson"));

  EXPECT_THAT(RunFailing({"prf", "sonar-study", "--sensor", "utm30", "-o", "bad"}).err,
              HasSubstr("unknown sonar 'utm30'"));
}

// A sonar study of the office and the l-office, one chain per case of 2000 burn-in and 2000
// recorded steps; `extra` adds options.
std::vector<std::string> SmallSonarStudy(const std::vector<std::string>& extra,
                                         const std::string& seed = "2") {
  std::vector<std::string> args = {"prf",       "sonar-study", "--scenes",  "office,l-office",
                                   "--samples", "2000",        "--burn-in", "2000",
                                   "--chains",  "1",           "--seed",    seed};
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}

// Stopped after 1500 of its chains' 4000 steps, refused where it would start over or resume
// another study, then resumed: the uninterrupted study's summary, apart from what belongs to the
// session, and no checkpoints left.
TEST_F(SonarCli, ASonarStudyStoppedAfterStepsResumesToTheUninterruptedSummary) {
  const auto whole = Run(SmallSonarStudy({"--no-figures", "-o", "whole"}));
  ASSERT_EQ(whole.status, 0) << whole.err;
  auto refused = RunFailing(SmallSonarStudy({"--resume", "-o", "parts"}));
  EXPECT_EQ(refused.status, 1);
  EXPECT_THAT(refused.err, HasSubstr("--resume: -o parts holds no stopped study of these cases (no "
                                     "parts/office-pioneer16/checkpoints)"));

  auto r = Run(SmallSonarStudy({"--stop-after-steps", "1500", "-o", "parts"}));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out,
            "stopped and checkpointed in 2 of 2 cases (parts/office-pioneer16/checkpoints, ...); "
            "continue with the same command and --resume\n");
  EXPECT_THAT(r.err, Not(HasSubstr("case office/")));
  for (const char* folder : {"office-pioneer16", "l-office-pioneer16"})
    EXPECT_TRUE(std::filesystem::exists(Work("parts") / folder / "checkpoints" / "chain-0.ckpt"))
        << folder;
  for (const char* file : {"summary.json", "table.md", "office-pioneer16/truth.png"})
    EXPECT_FALSE(std::filesystem::exists(Work("parts") / file)) << file;
  const auto stopped = testing::FilesAndContents(Work("parts"));

  refused = RunFailing(SmallSonarStudy({"-o", "parts"}));
  EXPECT_EQ(refused.status, 1);
  EXPECT_THAT(refused.err,
              HasSubstr("-o parts: it holds a stopped study (parts/office-pioneer16/checkpoints); "
                        "continue it with the same command and --resume"));
  refused = RunFailing(SmallSonarStudy({"--resume", "--free-space", "0.5", "-o", "parts"}, "3"));
  EXPECT_EQ(refused.status, 1);
  EXPECT_THAT(refused.err, HasSubstr("priormap: error: --resume: the study stopped in parts was "
                                     "started with other options: \"free_space\" 0.0, not 0.5; "
                                     "\"seed\" 2, not 3 (give the options it was started with)"));
  EXPECT_EQ(testing::FilesAndContents(Work("parts")), stopped);
  // A sonar model of other parameters is named, not shown.
  WriteText("m.json", R"({"format": "priormap.sonar_model", "version": 1, "sigma_min": 0.02})");
  refused = RunFailing(SmallSonarStudy({"--resume", "--sonar-model", "m.json", "-o", "parts"}));
  EXPECT_THAT(refused.err, HasSubstr("started with other options: \"sonar_model\" (give"));
  std::filesystem::remove(Work("m.json"));

  r = Run(SmallSonarStudy({"--resume", "-o", "parts"}));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("resumed 3000 steps from the cases' checkpoints\n"));  // 2 × 1500
  EXPECT_THAT(r.err, HasSubstr("case office/pioneer16 done\n"));
  EXPECT_THAT(r.err, HasSubstr("case l-office/pioneer16 done\n"));
  EXPECT_THAT(r.err, ContainsRegex("100% of the PRF steps, 2/2 cases done, [0-9]+ s\n"));
  const json expected = Summary("whole");
  const json resumed = Summary("parts");
  EXPECT_EQ(testing::WithoutSessionKeys(resumed), testing::WithoutSessionKeys(expected));
  ASSERT_EQ(resumed["cases"].size(), 2u);
  EXPECT_TRUE(testing::WithoutSessionKeys(expected)["cases"][0].contains("chains"));
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(resumed["cases"][k]["resumed_steps"], 1500) << k;
    EXPECT_EQ(expected["cases"][k]["resumed_steps"], 0) << k;
  }
  for (const char* folder : {"office-pioneer16", "l-office-pioneer16"}) {
    EXPECT_FALSE(std::filesystem::exists(Work("parts") / folder / "checkpoints")) << folder;
    EXPECT_TRUE(testing::IsPng(testing::ReadAll(Work("parts") / folder / "posterior.png")))
        << folder;
  }
  EXPECT_THAT(testing::ReadAll(Work("parts") / "table.md"), HasSubstr("| l-office |"));
  testing::ExpectNoTemporaryFile(Work("parts"));
  EXPECT_THAT(RunFailing(SmallSonarStudy({"--resume", "-o", "parts"})).err,
              HasSubstr("holds no stopped study of these cases"));
}

// SIGTERM once the chain has checkpointed: it stops, checkpointed, with the shell's status for
// the signal (143), no temporary file left and no summary; --resume then ends with the
// uninterrupted study's summary.
TEST_F(SonarCli, ASignalStopsTheSonarStudyCheckpointedAndItResumes) {
  // One case whose chain runs about a second, long enough to be signalled while it runs.
  const std::vector<std::string> study = {
      "prf",  "sonar-study", "--scenes", "office", "--samples", "20000",       "--burn-in",
      "2000", "--chains",    "1",        "--seed", "4",         "--no-figures"};
  const auto with = [&](const std::vector<std::string>& extra) {
    std::vector<std::string> args = study;
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
  };
  const testing::SignalledRun stopped = testing::RunAndSignalOnceCheckpointed(
      Work("."), with({"--checkpoint-every", "0.01", "-o", "run"}),
      Work("run") / "office-pioneer16" / "checkpoints", SIGTERM);
  testing::ExpectStoppedBy(
      stopped, SIGTERM,
      "stopped and checkpointed in 1 of 1 cases (run/office-pioneer16/checkpoints); "
      "continue with the same command and --resume\n");
  EXPECT_FALSE(std::filesystem::exists(Work("run") / "summary.json"));
  testing::ExpectNoTemporaryFile(Work("run"));

  const auto resumed = Run(with({"--resume", "-o", "run"}));
  ASSERT_EQ(resumed.status, 0) << resumed.err;
  EXPECT_THAT(resumed.err, ContainsRegex("resumed [1-9][0-9]* steps from the cases' checkpoints"));
  EXPECT_FALSE(std::filesystem::exists(Work("run") / "office-pioneer16" / "checkpoints"));
  const auto whole = Run(with({"-o", "whole"}));
  ASSERT_EQ(whole.status, 0) << whole.err;
  EXPECT_EQ(testing::WithoutSessionKeys(Summary("run")),
            testing::WithoutSessionKeys(Summary("whole")));
  EXPECT_GT(Summary("run")["cases"][0]["resumed_steps"].get<std::uint64_t>(), 0u);
}

TEST_F(SonarCli, ReportsMalformedRoboNdFilesAtFileLineAndColumn) {
  WriteText("m.txt", "1 2 3 4 5 6 7 8 9\n2 1 2 3 x 5 6 7 8\n");
  WriteText("p.txt", "1 0 0 0\n2 0 0 0\n");
  const auto r =
      RunFailing({"convert", "--from", "roboND-sonar", "m.txt", "p.txt", "-o", "x.json"});
  EXPECT_EQ(r.status, 1);
  EXPECT_THAT(r.err, HasSubstr("m.txt:2:9"));
  EXPECT_THAT(r.err, HasSubstr("a range in mm"));
  EXPECT_THAT(RunFailing({"convert", "--from", "roboND-sonar", "m.txt", "-o", "x.json"}).err,
              HasSubstr("--from roboND-sonar reads two files: measurement.txt poses.txt"));
  EXPECT_THAT(RunFailing({"convert", "m.txt", "p.txt", "-o", "x.json"}).err,
              HasSubstr("convert reads one log (two files only with --from roboND-sonar)"));
  EXPECT_NE(
      RunFailing({"convert", "--from", "roboND-sonar", "m.txt", "p.txt", "p.txt", "-o", "x.json"})
          .status,
      0);
}

TEST_F(SonarCli, RefusesRoboNdRangeLimitsThatWouldTurnNoEchoIntoWalls) {
  WriteText("m.txt", "1 2000 5110 3 4 5 6 7 8\n");
  WriteText("p.txt", "1 0 0 0\n");
  const auto beyond = RunFailing(
      {"convert", "--from", "roboND-sonar", "m.txt", "p.txt", "-o", "x.json", "--max-range", "6"});
  EXPECT_EQ(beyond.status, 1);
  EXPECT_THAT(beyond.err, HasSubstr("at most 5.11 m"));
  EXPECT_THAT(RunFailing({"convert", "--from", "roboND-sonar", "m.txt", "p.txt", "-o", "x.json",
                          "--min-range", "6"})
                  .err,
              HasSubstr("--min-range 6 m: with --from roboND-sonar it must be below"));
  for (const char* option : {"--fov", "--sigma"})
    EXPECT_THAT(RunFailing({"convert", "--from", "roboND-sonar", "m.txt", "p.txt", "-o", "x.json",
                            option, "10"})
                    .err,
                HasSubstr(std::string(option) + " is for laser formats"))
        << option;
  EXPECT_FALSE(std::filesystem::exists(Work("x.json")));
  // A shorter max range is the user's choice: the readings beyond it become max-range.
  Run({"convert", "--from", "roboND-sonar", "m.txt", "p.txt", "-o", "x.json", "--max-range",
       "1.5"});
  const Result<Log> read = ReadLog(Work("x.json"));
  ASSERT_TRUE(read.ok()) << read.error();
  const Log& log = read.value();
  ASSERT_EQ(log.scans.size(), 1u);
  EXPECT_EQ(log.scans[0].max_range, 1.5);
  EXPECT_EQ(log.scans[0].status[0], BeamStatus::kMaxRange);
  EXPECT_EQ(log.scans[0].status[1], BeamStatus::kMaxRange);
}

// A range limit that leaves no reading valid is reported naming the option given, its value and
// the limit it must clear, which may be the sensor's own (0.17 m, 5.11 m) that the user never
// gave.
TEST_F(SonarCli, NamesTheRoboNdRangeOptionThatLeavesNoReadingValid) {
  WriteText("m.txt", "1 2000 5110 3 4 5 6 7 8\n");
  WriteText("p.txt", "1 0 0 0\n");
  const auto refused = [&](const std::vector<std::string>& limits) {
    std::vector<std::string> args = {"convert", "--from", "roboND-sonar", "m.txt",
                                     "p.txt",   "-o",     "x.json"};
    args.insert(args.end(), limits.begin(), limits.end());
    const auto r = RunFailing(args);
    EXPECT_EQ(r.status, 1) << limits[0];
    return r.err;
  };
  EXPECT_THAT(refused({"--min-range", "6"}),
              HasSubstr("--min-range 6 m: with --from roboND-sonar it must be below the max "
                        "range, the sensor's 5.11 m"));
  EXPECT_THAT(refused({"--max-range", "0.1"}),
              HasSubstr("--max-range 0.1 m: with --from roboND-sonar it must be above the min "
                        "range, the sensor's 0.17 m"));
  EXPECT_THAT(refused({"--min-range", "3", "--max-range", "2"}),
              HasSubstr("--min-range 3 must be below --max-range 2"));
  // Within the limits, the other option moves the limit: both are accepted.
  ASSERT_EQ(Run({"convert", "--from", "roboND-sonar", "m.txt", "p.txt", "-o", "x.json",
                 "--max-range", "0.1", "--min-range", "0.05"})
                .status,
            0);
}

// A repeated or earlier time is a line copied or moved, refused at the file, line and column of
// the time.
TEST_F(SonarCli, RefusesRoboNdTimesThatRepeatOrGoBack) {
  WriteText("m.txt", "1 2000 5110 3 4 5 6 7 8\n2 2000 5110 3 4 5 6 7 8\n2 2000 5110 3 4 5 6 7 8\n");
  WriteText("p.txt", "1 0 0 0\n2 0 0 0\n2 0 0 0\n");
  const auto r =
      RunFailing({"convert", "--from", "roboND-sonar", "m.txt", "p.txt", "-o", "x.json"});
  EXPECT_EQ(r.status, 1);
  EXPECT_THAT(r.err, HasSubstr("m.txt:3:1: expected a time after the previous line's 2 ms "
                               "(m.txt:2), got 2 ms"));
}

// A scene given twice would be simulated with the same seed and fitted twice: its readings
// counted double. Refused naming the entry, also when two spellings load the same scene (the
// input, status 1; the same entry twice is the option's own value, status 2).
TEST_F(SonarCli, FitSonarRefusesASceneGivenTwice) {
  // Few rings (a fast robot, a slow ring), so that a fit that is not refused ends at once.
  const std::vector<std::string> fast = {"--speed", "100", "--rate", "0.05", "-o", "m.json"};
  const auto fit = [&](const std::string& scenes) {
    std::vector<std::string> args = {"prf", "fit-sonar", "--scenes", scenes};
    args.insert(args.end(), fast.begin(), fast.end());
    return args;
  };
  const auto twice = RunFailing(fit("office,l-office,office"));
  EXPECT_EQ(twice.status, 2);
  EXPECT_THAT(twice.err, HasSubstr("--scenes: 'office' is given twice"));
  WriteText("box.json", R"({"format": "priormap.scene", "version": 1, "name": "box",
    "surfaces": [{"type": "polyline", "points": [[-3, -3], [3, -3], [3, 3], [-3, 3]],
                  "closed": true}],
    "waypoints": [[-1, 0], [1, 0]]})");
  const auto aliases = RunFailing(fit("box.json,./box.json"));
  EXPECT_EQ(aliases.status, 1);
  EXPECT_THAT(aliases.err, HasSubstr("--scenes: 'box.json' and './box.json' are both scene 'box'"));
  const auto distinct = Run(fit("box.json,office"));
  EXPECT_EQ(distinct.status, 0) << distinct.err;
}

// summary.json is a grid's last output: a run that fails (or is stopped) while writing leaves
// none, so that an earlier run's cannot vouch for the mix of old and new files.
TEST_F(SonarCli, AGridThatFailsWhileWritingLeavesNoEarlierSummary) {
  WriteSonarLog("sonar.json");
  ASSERT_EQ(Run({"simulate", "--scene", "l-room", "--sensor", "lms200", "--log", "--seed", "2",
                 "-o", "laser.log"})
                .status,
            0);
  for (const char* log : {"sonar.json", "laser.log"}) {
    const std::string dir = std::string("grid-") + log;
    const auto first = Run({"grid", "--log", log, "-o", dir});
    ASSERT_EQ(first.status, 0) << first.err;
    ASSERT_TRUE(std::filesystem::exists(Work(dir) / "summary.json"));
    // grid.png is written after grid.pgm; a directory in its place makes it fail.
    std::filesystem::remove(Work(dir) / "grid.png");
    std::filesystem::create_directory(Work(dir) / "grid.png");
    // (Not RunFailing: the run fails after it has begun to write, by design.)
    const auto failed = Run({"grid", "--log", log, "-o", dir});
    EXPECT_EQ(failed.status, 1) << log;
    EXPECT_THAT(failed.err, HasSubstr("grid.png: cannot write: Is a directory")) << log;
    EXPECT_FALSE(std::filesystem::exists(Work(dir) / "summary.json")) << log;
  }
}

TEST_F(SonarCli, GridAndPrfMapASonarLogWhichTheyRecogniseByItself) {
  WriteSonarLog("sonar.json");
  const auto grid = Run({"grid", "--log", "sonar.json", "-o", "grid"});
  ASSERT_EQ(grid.status, 0) << grid.err;
  EXPECT_EQ(Summary("grid")["sensor"], "sonar");
  EXPECT_GT(Summary("grid")["readings"].get<int>(), 100);
  EXPECT_TRUE(testing::IsPng(testing::ReadAll(Work("grid") / "grid.png")));

  const auto prf = Run({"prf", "--log", "sonar.json", "--samples", "3000", "--burn-in", "3000",
                        "--chains", "1", "--trace-every", "500", "--seed", "5", "-o", "prf"});
  ASSERT_EQ(prf.status, 0) << prf.err;
  EXPECT_THAT(prf.err, HasSubstr("sonar readings"));
  const json summary = Summary("prf");
  EXPECT_EQ(summary["sensor"], "sonar");
  EXPECT_GT(summary["beams"].get<int>(), 100);
  EXPECT_TRUE(testing::IsPng(testing::ReadAll(Work("prf") / "posterior.png")));

  // A sonar run resumes exactly, like a laser one.
  const std::vector<std::string> run = {
      "prf",      "--log", "sonar.json",    "--samples", "3000",   "--burn-in", "3000",
      "--chains", "1",     "--trace-every", "500",       "--seed", "5"};
  auto stopped = run;
  for (const char* arg : {"--stop-after-steps", "2500", "-o", "resumed"}) stopped.push_back(arg);
  ASSERT_EQ(Run(stopped).status, 0);
  ASSERT_EQ(Run({"prf", "--resume", "resumed"}).status, 0);
  EXPECT_EQ(testing::ReadAll(Work("resumed") / "posterior.pgm"),
            testing::ReadAll(Work("prf") / "posterior.pgm"));

  EXPECT_THAT(RunFailing({"grid", "--log", "sonar.json", "--sensor", "laser", "-o", "g"}).err,
              HasSubstr("--sensor laser"));
  EXPECT_THAT(RunFailing({"prf", "--log", "sonar.json", "--sensor", "laser", "-o", "p"}).err,
              HasSubstr("--sensor laser"));
}

// Options a sonar run would otherwise drop or misread are refused before any work.
TEST_F(SonarCli, RefusesLaserOptionsStepCountsAndRastersItCannotHonour) {
  WriteSonarLog("sonar.json");
  const std::vector<std::string> prf = {"prf", "--log", "sonar.json", "-o", "p"};
  const auto refused = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = prf;
    args.insert(args.end(), extra.begin(), extra.end());
    return RunFailing(args).err;
  };
  EXPECT_THAT(refused({"--beam-step", "4"}), HasSubstr("--beam-step 4 is for laser scans"));
  EXPECT_THAT(refused({"--sigma", "0.2"}), HasSubstr("--sigma 0.2 is the laser beam model's"));
  // Given at its default value it would be dropped as silently.
  EXPECT_THAT(refused({"--sigma", "0.05"}), HasSubstr("--sigma 0.05 is the laser beam model's"));
  EXPECT_THAT(refused({"--resolution", "0.0001"}), HasSubstr("would make rasters of"));
  for (const char* option : {"--samples", "--burn-in", "--anneal-steps", "--stop-after-steps"})
    EXPECT_THAT(refused({option, "-5"}), HasSubstr("'-5' is not a step count")) << option;
  EXPECT_THAT(refused({"--replica-steps", "2000000000000"}), HasSubstr("not a step count"));
  // Stages whose steps would wrap round to a small sum.
  EXPECT_THAT(refused({"--thinned-burn-in", "1:18446744073709551615,1:2"}),
              HasSubstr("more than the burn-in's"));
  EXPECT_FALSE(std::filesystem::exists(Work("p") / "run.json"));
  EXPECT_THAT(RunFailing({"grid", "--log", "sonar.json", "--beam-step", "2", "-o", "g"}).err,
              HasSubstr("--beam-step 2 is for laser scans"));
}

// A new run in a directory removes what an earlier run made that it will not make again.
TEST_F(SonarCli, ANewRunLeavesNoOutputsOfAnEarlierOneInItsDirectory) {
  WriteSonarLog("sonar.json");
  const std::vector<std::string> common = {"prf",   "--log",     "sonar.json", "--samples",
                                           "02000", "--burn-in", "1000",       "--trace-every",
                                           "500",   "-o",        "run"};
  auto first = common;
  for (const char* arg : {"--chains", "3", "--anneal"}) first.push_back(arg);
  ASSERT_EQ(Run(first).status, 0);
  // A step count with a leading zero is decimal, as everywhere else (CLI11 alone reads octal).
  EXPECT_EQ(Summary("run")["samples"], 2000);
  for (const char* file : {"chain2.png", "chain2_last.geojson", "map.png", "map.yaml"})
    ASSERT_TRUE(std::filesystem::exists(Work("run") / file)) << file;
  WriteText("run/notes.txt", "mine");
  WriteText("run/chain007.png", "not a run's name");
  std::filesystem::create_symlink("loop", Work("run") / "loop");  // a link to itself
  auto second = common;
  for (const char* arg : {"--chains", "2"}) second.push_back(arg);
  ASSERT_EQ(Run(second).status, 0);
  for (const char* file : {"chain2.png", "chain2_last.geojson", "map.png", "map.geojson", "map.svg",
                           "map.pgm", "map.yaml"})
    EXPECT_FALSE(std::filesystem::exists(Work("run") / file)) << file;
  EXPECT_TRUE(std::filesystem::exists(Work("run") / "chain1.png"));
  EXPECT_EQ(testing::ReadAll(Work("run") / "notes.txt"), "mine");  // not a run's output
  EXPECT_TRUE(std::filesystem::exists(Work("run") / "chain007.png"));
}

// `prf fit-sonar` writes a model file that `prf --sonar-model` reads, with the posterior options
// of docs/prf.md and the step scales; run.json keeps them for --resume; bad values are refused
// before any work.
TEST_F(SonarCli, FitsASonarModelAndMapsWithItAndThePriors) {
  const auto fit = Run({"prf", "fit-sonar", "--scenes", "office", "--rate", "1", "-o", "m.json"});
  ASSERT_EQ(fit.status, 0) << fit.err;
  // An output it cannot write is refused before the fit, not after it.
  EXPECT_THAT(RunFailing({"prf", "fit-sonar", "--scenes", "office", "--rate", "1", "-o",
                          "no-such-dir/m.json"})
                  .err,
              HasSubstr("no-such-dir"));
  const json model = json::parse(testing::ReadAll(Work("m.json")));
  EXPECT_EQ(model["format"], "priormap.sonar_model");
  EXPECT_GT(model["fit"]["log_likelihood"].get<double>(),
            model["fit"]["start_log_likelihood"].get<double>());

  WriteSonarLog("sonar.json");
  const std::vector<std::string> run = {"prf",
                                        "--log",
                                        "sonar.json",
                                        "--sonar-model",
                                        "m.json",
                                        "--free-space",
                                        "0.3",
                                        "--orientation-weight",
                                        "1",
                                        "--burn-in-temperature",
                                        "3",
                                        "--thinned-burn-in",
                                        "4:1000,2:1000",
                                        "--thinned-rotation",
                                        "300",
                                        "--thinned-weighed",
                                        "--warm-burn-in",
                                        "2:500",
                                        "--burn-in-replicas",
                                        "3",
                                        "--replica-temperature",
                                        "4",
                                        "--step-scales",
                                        "0.01,0.05,0.3",
                                        "--vertex-birth-widths",
                                        "0.5,1.5",
                                        "--corner-completion",
                                        "0.25",
                                        "--corner-completion-jitter",
                                        "0.03",
                                        "--neighbour-births",
                                        "0.2",
                                        "--neighbour-birth-jitter",
                                        "0.08",
                                        "--vertex-jumps",
                                        "2",
                                        "--vertex-jump-reach",
                                        "1.5",
                                        "--vertex-jump-jitter",
                                        "0.06",
                                        "--vertex-pairs",
                                        "1.5",
                                        "--burn-in",
                                        "3000",
                                        "--samples",
                                        "2000",
                                        "--chains",
                                        "1",
                                        "--trace-every",
                                        "500",
                                        "--seed",
                                        "5"};
  auto whole = run;
  for (const char* arg : {"-o", "prf"}) whole.push_back(arg);
  const auto prf = Run(whole);
  ASSERT_EQ(prf.status, 0) << prf.err;
  // The progress lines say which log posteriors are of thinned data.
  EXPECT_THAT(prf.err, HasSubstr("(on 1/4 of the readings)"));
  EXPECT_THAT(prf.err, HasSubstr("(on 1/2 of the readings)"));
  EXPECT_THAT(prf.err, ContainsRegex("100% [^\n]*log posterior -?[0-9.]+\n"));
  const json posterior = Summary("prf")["posterior"];
  EXPECT_EQ(posterior["free_space"], 0.3);
  EXPECT_EQ(posterior["thinned_burn_in"].size(), 2u);
  EXPECT_EQ(posterior["thinned_rotation"], 300u);
  EXPECT_EQ(posterior["thinned_weighed"], true);
  EXPECT_EQ(posterior["burn_in_replicas"], 3);
  EXPECT_EQ(posterior["step_scales"], json::array({0.01, 0.05, 0.3}));
  EXPECT_EQ(posterior["warm_burn_in"]["temperature"], 2.0);
  EXPECT_EQ(posterior["warm_burn_in"]["steps"], 500u);
  EXPECT_EQ(posterior["vertex_birth_widths"], json::array({0.5, 1.5}));
  EXPECT_EQ(posterior["corner_completion"]["probability"], 0.25);
  EXPECT_EQ(posterior["corner_completion"]["jitter"], 0.03);
  EXPECT_EQ(posterior["neighbour_birth"]["probability"], 0.2);
  EXPECT_EQ(posterior["neighbour_birth"]["jitter"], 0.08);
  EXPECT_EQ(posterior["vertex_jump"]["weight"], 2.0);
  EXPECT_EQ(posterior["vertex_jump"]["reach"], 1.5);
  EXPECT_EQ(posterior["vertex_jump"]["jitter"], 0.06);
  EXPECT_EQ(posterior["vertex_pairs"], 1.5);
  EXPECT_GT(Summary("prf")["acceptance"]["vertex_birth"]["accepted"].get<int>(), 0);
  EXPECT_GT(Summary("prf")["acceptance"]["vertex_jump"]["accepted"].get<int>(), 0);
  EXPECT_GT(Summary("prf")["acceptance"]["vertex_pair_birth"]["accepted"].get<int>(), 0);
  EXPECT_GT(Summary("prf")["acceptance"]["vertex_pair_death"]["accepted"].get<int>(), 0);
  EXPECT_EQ(Summary("prf")["swap_rates"][0].size(), 2u);  // one chain, two pairs of rungs
  // Stopped in the second thinned stage, replicas and all, and resumed: the same map.
  auto stopped = run;
  for (const char* arg : {"--stop-after-steps", "1500", "-o", "resumed"}) stopped.push_back(arg);
  ASSERT_EQ(Run(stopped).status, 0);
  ASSERT_EQ(Run({"prf", "--resume", "resumed"}).status, 0);
  EXPECT_EQ(testing::ReadAll(Work("resumed") / "posterior.pgm"),
            testing::ReadAll(Work("prf") / "posterior.pgm"));

  EXPECT_THAT(RunFailing({"prf", "--log", "sonar.json", "--thinned-burn-in", "4:x", "-o", "b"}).err,
              HasSubstr("expected STRIDE:STEPS"));
  EXPECT_THAT(RunFailing({"prf", "--log", "sonar.json", "--thinned-burn-in", "4:5000", "--burn-in",
                          "1000", "-o", "b"})
                  .err,
              HasSubstr("more than the burn-in's 1000"));
  EXPECT_THAT(
      RunFailing({"prf", "--log", "sonar.json", "--warm-burn-in", "0.5:100", "-o", "b"}).err,
      HasSubstr("expected T:STEPS with a temperature from 1 to 1000"));
  EXPECT_THAT(RunFailing({"prf", "--log", "sonar.json", "--warm-burn-in", "2:x", "-o", "b"}).err,
              HasSubstr("got '2:x'"));
  EXPECT_THAT(RunFailing({"prf", "--log", "sonar.json", "--thinned-burn-in", "4:600",
                          "--warm-burn-in", "2:500", "--burn-in", "1000", "-o", "b"})
                  .err,
              HasSubstr("--warm-burn-in: 500 steps after the thinned stages' 600, more than"));
  EXPECT_THAT(RunFailing({"prf", "--log", "sonar.json", "--burn-in-replicas", "2",
                          "--replica-temperature", "1", "-o", "b"})
                  .err,
              HasSubstr("--replica-temperature must be above 1"));
  EXPECT_THAT(RunFailing({"prf", "--log", "sonar.json", "--step-scales", "0.01,0", "-o", "b"}).err,
              HasSubstr("--step-scales"));
  EXPECT_THAT(
      RunFailing({"prf", "--log", "sonar.json", "--vertex-birth-widths", "0.5,0", "-o", "b"}).err,
      HasSubstr("--vertex-birth-widths"));
  EXPECT_THAT(RunFailing({"prf", "--log", "sonar.json", "--vertex-jump-reach", "0", "-o", "b"}).err,
              HasSubstr("--vertex-jump-reach"));
  EXPECT_THAT(RunFailing({"prf", "--log", "sonar.json", "--corner-completion", "1", "-o", "b"}).err,
              HasSubstr("--corner-completion"));
  EXPECT_THAT(RunFailing({"prf", "--log", "sonar.json", "--corner-completion", "0.5",
                          "--neighbour-births", "0.5", "-o", "b"})
                  .err,
              HasSubstr("sum to 1 or more"));
  WriteText("bad.json",
            "{\"format\": \"priormap.sonar_model\", \"version\": 1,\n \"face_bias\": \"x\"}");
  EXPECT_THAT(
      RunFailing({"prf", "--log", "sonar.json", "--sonar-model", "bad.json", "-o", "b"}).err,
      HasSubstr("bad.json:2:15"));
  EXPECT_FALSE(std::filesystem::exists(Work("b")));
}

// A log fitted against a scene it was not recorded in puts transducers inside walls: a user
// error saying so, not an internal one. Speeds and rates that would simulate more readings than a
// fit can take are refused before anything is simulated (not a std::bad_alloc, nor hours of run).
TEST_F(SonarCli, FitSonarRefusesTheWrongSceneAndMoreReadingsThanAFitTakes) {
  ASSERT_EQ(Run({"simulate", "--scene", "office", "--sensor", "pioneer8", "--log", "--rate", "1",
                 "--seed", "2", "-o", "office.json"})
                .status,
            0);
  const auto wrong = RunFailing(
      {"prf", "fit-sonar", "--log", "office.json", "--scene", "l-office", "-o", "m.json"});
  EXPECT_EQ(wrong.status, 1);
  EXPECT_THAT(wrong.err, HasSubstr("lies inside the walls of scene l-office: the log was not "
                                   "recorded in this scene, its poses are off"));
  // A waypoint path 5 cm from a wall: a Pioneer's rear transducers (26 cm behind its centre)
  // are inside it.
  WriteText("tight.json", R"({"format": "priormap.scene", "version": 1, "name": "tight",
    "surfaces": [{"type": "polyline", "points": [[-2, -2], [2, -2], [2, 2], [-2, 2]],
                  "closed": true}],
    "waypoints": [[-1.95, 0], [1.95, 0]]})");
  const auto tight = RunFailing({"prf", "fit-sonar", "--scenes", "tight.json", "-o", "m.json"});
  EXPECT_EQ(tight.status, 1);
  EXPECT_THAT(tight.err, HasSubstr("lies inside the walls of scene tight"));
  const std::vector<std::vector<std::string>> trajectories = {
      {"--rate", "1e12"}, {"--speed", "1e-9"}, {"--rate", "1000"}};
  for (const std::vector<std::string>& trajectory : trajectories) {
    std::vector<std::string> args = {"prf", "fit-sonar", "-o", "m.json"};
    args.insert(args.end(), trajectory.begin(), trajectory.end());
    const auto r = RunFailing(args);
    EXPECT_EQ(r.status, 1) << trajectory[0];
    EXPECT_THAT(r.err, HasSubstr("more than the 1e+06 a fit takes: use a lower --rate or a higher "
                                 "--speed"))
        << trajectory[0];
  }
}

// A max range beyond priormap's bound on returns (1e9 m) is refused before the simulation: a
// spurious reading, uniform below it, would make a log that cannot be written (or read back).
TEST_F(SonarCli, SimulateRefusesASonarMaxRangeBeyondTheWorldsBound) {
  for (const bool log : {false, true}) {
    std::vector<std::string> args = {"simulate",  "--scene", "office", "--sensor",
                                     "pioneer16", "--seed",  "1",      "--max-range",
                                     "1e10",      "-o",      "r.json"};
    if (log) args.push_back("--log");
    const auto r = RunFailing(args);
    EXPECT_EQ(r.status, 1);
    EXPECT_THAT(r.err, HasSubstr("max_range 1e+10 m is beyond 1e+09 m")) << log;
  }
  ASSERT_EQ(Run({"simulate", "--scene", "office", "--sensor", "pioneer16", "--max-range", "1e9",
                 "-o", "r.json"})
                .status,
            0);
}

// A sigma out of range is reported at its value, like every other parameter, and a subnormal
// sigma_min (whose Gaussian density at its mean is +inf) is refused.
TEST_F(SonarCli, ASonarModelsBadSigmaIsReportedAtItsValue) {
  WriteSonarLog("sonar.json");
  const auto refused = [&](const std::string& member) {
    WriteText("bad.json",
              "{\"format\": \"priormap.sonar_model\", \"version\": 1,\n " + member + "}");
    const auto r = RunFailing({"prf", "--log", "sonar.json", "--sonar-model", "bad.json",
                               "--samples", "100", "--burn-in", "100", "-o", "b"});
    EXPECT_EQ(r.status, 1) << member;
    return r.err;
  };
  EXPECT_THAT(refused("\"sigma_min\": -0.01"),
              HasSubstr("bad.json:2:15: not a usable sonar model: sigma_min -0.01 is not"));
  EXPECT_THAT(refused("\"sigma_min\": 0"), HasSubstr("bad.json:2:15:"));
  EXPECT_THAT(refused("\"sigma_min\": 1e-310"),
              HasSubstr("bad.json:2:15: not a usable sonar model: sigma_min 1e-310 is not"));
  EXPECT_THAT(refused("\"sigma_relative\": -0.5"),
              HasSubstr("bad.json:2:20: not a usable sonar model: sigma_relative -0.5 is not"));
}

// Each line of `text` with `edit` applied to it.
std::string EachLine(const std::string& text,
                     const std::function<std::string(const std::string&)>& edit) {
  std::istringstream in(text);
  std::string out, line;
  while (std::getline(in, line)) out += edit(line) + "\n";
  return out;
}

// `prf rhat` on traces whose (finite) log-posteriors are huge: R-hat and the chains' means are
// numbers, not "nan" and null; a trace.csv or point_traces.csv that does not match the run's
// own record is reported at its file:line:col.
TEST_F(SonarCli, RhatOfHugeLogPosteriorsIsANumberAndMismatchedTracesAreLocated) {
  WriteSonarLog("sonar.json");
  for (const std::string seed : {"1", "2"})
    ASSERT_EQ(Run({"prf", "--log", "sonar.json", "--samples", "2000", "--burn-in", "500",
                   "--chains", "1", "--trace-every", "100", "--seed", seed, "-o", "run" + seed})
                  .status,
              0);
  const auto rhat = [&] {
    const auto r = Run({"prf", "rhat", "run1", "run2"});
    EXPECT_EQ(r.status, 0) << r.err;
    return r.status == 0 ? json::parse(r.out) : json();
  };
  const json before = rhat();
  ASSERT_TRUE(before["rhat"]["log_posterior"].is_number()) << before.dump();
  // Every log-posterior of run2 times 1e300 (their squares overflow a double), then its last
  // one the most negative double.
  const std::string original = testing::ReadAll(Work("run2") / "trace.csv");
  std::string huge = EachLine(original, [](const std::string& line) {
    return line.starts_with("sample") ? line : line + "e300";
  });
  for (int variant = 0; variant < 2; ++variant) {
    WriteText("run2/trace.csv", huge);
    const json after = rhat();
    EXPECT_TRUE(after["rhat"]["log_posterior"].is_number()) << after.dump();
    if (after["rhat"]["log_posterior"].is_number()) {
      EXPECT_GT(after["rhat"]["log_posterior"].get<double>(), 1.0);
    }
    for (const json& run : after["runs"])
      for (const json& mean : run["second_half_means"]) EXPECT_TRUE(mean.is_number()) << mean;
    // run1's chain keeps its own mean, to the last digit.
    EXPECT_EQ(after["runs"][0]["second_half_means"], before["runs"][0]["second_half_means"]);
    huge.replace(huge.rfind(',') + 1, std::string::npos, "-1.7976931348623157e308\n");
  }
  WriteText("run2/trace.csv", original);
  EXPECT_EQ(rhat(), before);

  // A trace.csv of two chains for a run of one.
  WriteText("run2/trace.csv", EachLine(original, [](const std::string& line) {
              return line + (line.starts_with("sample") ? ",chain1" : ",-5");
            }));
  auto r = RunFailing({"prf", "rhat", "run1", "run2"});
  EXPECT_EQ(r.status, 1);
  EXPECT_THAT(r.err, HasSubstr("run2/trace.csv:1:1: expected a column for each chain, 1 as "
                               "run2/run.json says, found 2"));
  WriteText("run2/trace.csv", original);
  // point_traces.csv without the last trace point's column, in both runs, whose summary.json
  // lists it: the points' positions would be matched to the wrong columns.
  ASSERT_GT(Summary("run1")["trace_points"].size(), 1u);
  for (const char* run : {"run1", "run2"}) {
    const std::string path = std::string(run) + "/point_traces.csv";
    WriteText(path, EachLine(testing::ReadAll(Work(path)), [](const std::string& line) {
                return line.substr(0, line.rfind(','));
              }));
  }
  r = RunFailing({"prf", "rhat", "run1", "run2"});
  EXPECT_EQ(r.status, 1);
  EXPECT_THAT(r.err, HasSubstr("run1/point_traces.csv:1:1: expected a column per chain for each "
                               "trace point, "));
}

}  // namespace
}  // namespace priormap
