// End-to-end test of `priormap prf study`: a tiny study writes its summary (scores per case and
// overall), its markdown table and the figures of each case; bad options are reported without
// output; a study stopped (after some steps or by a signal) resumes to the uninterrupted result.
#include <algorithm>
#include <csignal>
#include <cstdint>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <sys/wait.h>
#include <tuple>
#include <utility>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_fixture.hpp"
#include "testing/temp_dir.hpp"

namespace priormap {
namespace {

using nlohmann::json;
using ::testing::ContainsRegex;
using ::testing::HasSubstr;
using ::testing::Not;

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

  // A study of one of the cases: the other's figures are the earlier study's, which no summary
  // lists any more; they go, and their folder with them unless it holds something else.
  const auto one_case = [&](const std::string& sensor) {
    return Run({"prf",       "study",   "--scenes",  "square",      "--sensors",
                sensor,      "--poses", "2",         "--beam-step", "6",
                "--samples", "3000",    "--burn-in", "3000",        "--anneal-steps",
                "0",         "--seed",  "3",         "-o",          "out"});
  };
  testing::WriteAll(Work("out") / "square-lms200" / "notes.txt", "mine");
  ASSERT_EQ(one_case("utm30").status, 0);
  EXPECT_EQ(testing::FilesUnder(Work("out") / "square-lms200"),
            (std::set<std::string>{"notes.txt"}));
  EXPECT_TRUE(std::filesystem::exists(Work("out") / "square-utm30" / "posterior.png"));
  ASSERT_EQ(one_case("lms200").status, 0);
  EXPECT_FALSE(std::filesystem::exists(Work("out") / "square-utm30"));
  EXPECT_TRUE(std::filesystem::exists(Work("out") / "square-lms200" / "notes.txt"));
  EXPECT_TRUE(std::filesystem::exists(Work("out") / "square-lms200" / "posterior.png"));
  EXPECT_EQ(json::parse(testing::ReadAll(Work("out") / "summary.json"))["cases"].size(), 1u);
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

// A study of two small cases (the square seen by the lms200 and by the utm30): two chains per
// case of 3000 burn-in and 3000 recorded steps, then 3000 steps of annealing; `extra` adds options.
std::vector<std::string> SmallStudy(const std::vector<std::string>& extra,
                                    const std::string& seed = "3") {
  std::vector<std::string> args = {
      "prf",       "study", "--scenes",       "square", "--sensors", "lms200,utm30",
      "--poses",   "2",     "--beam-step",    "6",      "--samples", "3000",
      "--burn-in", "3000",  "--anneal-steps", "3000",   "--seed",    seed};
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}

// Sessions that stop in the chains (at 2000 and 5000 of their 6000 steps) and in the annealing
// (2000 of its 3000 steps), then one that completes the study: the summary of the uninterrupted
// study, apart from what belongs to the session, and no checkpoints left.
TEST_F(PrfStudyCli, AStudyStoppedAfterStepsResumesToTheUninterruptedSummary) {
  const auto whole = Run(SmallStudy({"-o", "whole"}));
  ASSERT_EQ(whole.status, 0) << whole.err;

  auto r = Run(SmallStudy({"--stop-after-steps", "2000", "-o", "parts"}));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out,
            "stopped and checkpointed in 2 of 2 cases (parts/square-lms200/checkpoints, ...); "
            "continue with the same command and --resume\n");
  EXPECT_THAT(r.err, ContainsRegex("[0-9]+% of the PRF steps, 0/2 cases done"));
  EXPECT_THAT(r.err, Not(HasSubstr("case square/")));
  for (const char* folder : {"square-lms200", "square-utm30"})
    for (const char* file : {"chain-0.ckpt", "chain-1.ckpt"})
      EXPECT_TRUE(std::filesystem::exists(Work("parts") / folder / "checkpoints" / file))
          << folder << "/" << file;
  for (const char* file : {"summary.json", "table.md", "square-lms200/truth.png"})
    EXPECT_FALSE(std::filesystem::exists(Work("parts") / file)) << file;

  r = Run(SmallStudy({"--resume", "--stop-after-steps", "3000", "-o", "parts"}));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("stopped and checkpointed in 2 of 2 cases"));
  EXPECT_THAT(r.err, HasSubstr("resumed 8000 steps from the cases' checkpoints\n"));  // 4 × 2000
  r = Run(SmallStudy({"--resume", "--stop-after-steps", "2000", "-o", "parts"}));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("stopped and checkpointed in 2 of 2 cases"));
  EXPECT_THAT(r.err, HasSubstr("resumed 20000 steps"));  // 4 × 5000
  for (const char* folder : {"square-lms200", "square-utm30"})
    EXPECT_TRUE(std::filesystem::exists(Work("parts") / folder / "checkpoints" / "anneal.ckpt"))
        << folder;
  EXPECT_FALSE(std::filesystem::exists(Work("parts") / "summary.json"));

  r = Run(SmallStudy({"--resume", "-o", "parts"}));
  ASSERT_EQ(r.status, 0) << r.err;
  // 4 × 6000 of the chains and 2 × 2000 of the annealing.
  EXPECT_THAT(r.err, HasSubstr("resumed 28000 steps from the cases' checkpoints\n"));
  EXPECT_THAT(r.err, HasSubstr("case square/lms200 done\n"));
  EXPECT_THAT(r.err, HasSubstr("case square/utm30 done\n"));
  EXPECT_THAT(r.err, ContainsRegex("100% of the PRF steps, 2/2 cases done, [0-9]+ s\n"));
  EXPECT_THAT(r.out, HasSubstr("wrote parts (summary.json, table.md, "
                               "<scene>-<sensor>/{truth,grid,posterior,map}.png)"));
  const json expected = json::parse(testing::ReadAll(Work("whole") / "summary.json"));
  const json resumed = json::parse(testing::ReadAll(Work("parts") / "summary.json"));
  EXPECT_EQ(testing::WithoutSessionKeys(resumed), testing::WithoutSessionKeys(expected));
  // What the comparison leaves out is there, and the scores it compares.
  ASSERT_EQ(resumed["cases"].size(), 2u);
  EXPECT_TRUE(testing::WithoutSessionKeys(expected)["cases"][1]["map"].contains("mean_distance_m"));
  std::uint64_t resumed_steps = 0;
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_GT(resumed["cases"][k]["prf"]["resumed_steps"].get<std::uint64_t>(), 0u) << k;
    EXPECT_EQ(expected["cases"][k]["prf"]["resumed_steps"], 0) << k;
    resumed_steps += resumed["cases"][k]["prf"]["resumed_steps"].get<std::uint64_t>();
  }
  EXPECT_EQ(resumed_steps, 28000u);
  EXPECT_THAT(testing::ReadAll(Work("parts") / "table.md"), HasSubstr("| **all** |"));
  for (const char* folder : {"square-lms200", "square-utm30"}) {
    EXPECT_FALSE(std::filesystem::exists(Work("parts") / folder / "checkpoints")) << folder;
    EXPECT_TRUE(testing::IsPng(testing::ReadAll(Work("parts") / folder / "map.png"))) << folder;
  }
  testing::ExpectNoTemporaryFile(Work("parts"));

  // Complete: nothing left to resume.
  const auto again = RunFailing(SmallStudy({"--resume", "-o", "parts"}));
  EXPECT_EQ(again.status, 1);
  EXPECT_THAT(again.err, HasSubstr("--resume: -o parts holds no stopped study of these cases (no "
                                   "parts/square-lms200/checkpoints); run without --resume"));

  // A new study there, stopped before its end: the complete study's results do not stay beside
  // it (whether a study is complete is told by its summary.json).
  ASSERT_EQ(Run(SmallStudy({"--stop-after-steps", "2000", "-o", "parts"})).status, 0);
  EXPECT_FALSE(std::filesystem::exists(Work("parts") / "summary.json"));
  EXPECT_FALSE(std::filesystem::exists(Work("parts") / "table.md"));
}

// A new study over a stopped one would start its cases afresh and lose their progress; a resume
// with other options would not give the study that was started; a resume where no study stopped
// has nothing to go on from. All are refused, the checkpoints untouched, and the stopped study
// then resumes.
TEST_F(PrfStudyCli, RefusesToOverwriteAStoppedStudyOrToResumeAnother) {
  auto refused = RunFailing(SmallStudy({"--resume", "-o", "fresh"}));
  EXPECT_EQ(refused.status, 1);
  EXPECT_THAT(refused.err, HasSubstr("--resume: -o fresh holds no stopped study of these cases"));
  EXPECT_FALSE(std::filesystem::exists(Work("fresh")));

  ASSERT_EQ(Run(SmallStudy({"--stop-after-steps", "2000", "-o", "parts"})).status, 0);
  const auto stopped = testing::FilesAndContents(Work("parts"));
  // Two chains' checkpoints per case, and the record of the cases.
  ASSERT_EQ(stopped.size(), 5u);
  EXPECT_TRUE(stopped.contains("study-in-progress.json"));

  refused = RunFailing(SmallStudy({"-o", "parts"}));
  EXPECT_EQ(refused.status, 1);
  EXPECT_THAT(refused.err,
              HasSubstr("-o parts: it holds a stopped study (parts/square-lms200/checkpoints); "
                        "continue it with the same command and --resume, or remove the cases' "
                        "checkpoints folders to start a new study there"));
  EXPECT_EQ(testing::FilesAndContents(Work("parts")), stopped);

  // Other options are named, before any case is simulated.
  for (const auto& [options, seed, named] :
       std::vector<std::tuple<std::vector<std::string>, std::string, std::string>>{
           {{"--resume", "-o", "parts"}, "4", "\"seed\" 3, not 4"},
           {{"--resume", "--p", "2", "-o", "parts"}, "3", "\"p\" 0.1, not 2.0"}}) {
    refused = RunFailing(SmallStudy(options, seed));
    EXPECT_EQ(refused.status, 1) << named;
    EXPECT_THAT(refused.err, HasSubstr("priormap: error: --resume: the study stopped in parts was "
                                       "started with other options: " +
                                       named + " (give the options it was started with)"));
    EXPECT_EQ(testing::FilesAndContents(Work("parts")), stopped) << named;
  }
  // A record without the options (an earlier priormap's): the checkpoints refuse them.
  const std::filesystem::path record = Work("parts") / "study-in-progress.json";
  json earlier_record = json::parse(stopped.at("study-in-progress.json"));
  earlier_record.erase("options");
  earlier_record["version"] = 1;
  testing::WriteAll(record, earlier_record.dump(2));
  refused = RunFailing(SmallStudy({"--resume", "-o", "parts"}, "4"));
  EXPECT_EQ(refused.status, 1);
  EXPECT_THAT(refused.err, HasSubstr("priormap: error: cannot resume: "));
  EXPECT_THAT(refused.err, HasSubstr(": a checkpoint of another run (its data or options differ "
                                     "from this one's); give the options the study was started "
                                     "with. If they are, the case's data differ"));
  testing::WriteAll(record, stopped.at("study-in-progress.json"));

  // A resume with fewer cases would run another study and leave the others' checkpoints behind.
  std::vector<std::string> one_sensor = SmallStudy({"--resume", "-o", "parts"});
  *std::find(one_sensor.begin(), one_sensor.end(), "lms200,utm30") = "lms200";
  refused = RunFailing(one_sensor);
  EXPECT_EQ(refused.status, 1);
  EXPECT_THAT(refused.err, HasSubstr("--resume: the study stopped in parts has the cases "
                                     "square-lms200, square-utm30; these options give "
                                     "square-lms200 (give the scenes and sensors"));
  EXPECT_EQ(testing::FilesAndContents(Work("parts")), stopped);

  const auto r = Run(SmallStudy({"--resume", "--no-figures", "-o", "parts"}));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("resumed 8000 steps"));
  EXPECT_TRUE(std::filesystem::exists(Work("parts") / "summary.json"));
  // Without figures the case folders held the checkpoints alone and go with them, and so does
  // the record of the study in progress.
  for (const char* folder : {"square-lms200", "square-utm30"})
    EXPECT_FALSE(std::filesystem::exists(Work("parts") / folder)) << folder;
  EXPECT_FALSE(std::filesystem::exists(Work("parts") / "study-in-progress.json"));

  // With the cases' checkpoints removed, as the refusal says, a new study starts there.
  ASSERT_EQ(Run(SmallStudy({"--stop-after-steps", "2000", "-o", "other"})).status, 0);
  for (const char* folder : {"square-lms200", "square-utm30"})
    std::filesystem::remove_all(Work("other") / folder / "checkpoints");
  const auto fresh = Run(SmallStudy({"--no-figures", "-o", "other"}));
  ASSERT_EQ(fresh.status, 0) << fresh.err;
  EXPECT_THAT(fresh.err, Not(HasSubstr("resumed")));
  EXPECT_TRUE(std::filesystem::exists(Work("other") / "summary.json"));
}

// A write that fails (here the summary's, where a directory stands) loses nothing: the cases keep
// their checkpoints, the error says how to go on, and once the write can be done the resume ends
// with the uninterrupted study's summary. A checkpoint temporary that a write killed mid-way left
// goes with the next session, whatever process its PID names now.
TEST_F(PrfStudyCli, AFailedWriteKeepsTheCasesCheckpointsAndTheStudyResumes) {
  const auto whole = Run(SmallStudy({"--no-figures", "-o", "whole"}));
  ASSERT_EQ(whole.status, 0) << whole.err;
  ASSERT_EQ(Run(SmallStudy({"--stop-after-steps", "2000", "-o", "parts"})).status, 0);
  const std::filesystem::path stale =
      Work("parts") / "square-utm30" / "checkpoints" / ".chain-1.ckpt.tmp-1-0";
  testing::WriteAll(stale, "half a checkpoint");  // process 1 runs, but holds no lock of parts
  std::filesystem::create_directories(Work("parts") / "summary.json" / "in the way");
  auto r = Run(SmallStudy({"--resume", "--no-figures", "-o", "parts"}));
  EXPECT_EQ(r.status, 1);
  EXPECT_THAT(r.err, HasSubstr("parts/summary.json: cannot write: "));
  EXPECT_THAT(r.err, HasSubstr("; the cases' checkpoints are kept: once parts can be written, "
                               "continue with the same command and --resume\n"));
  EXPECT_FALSE(std::filesystem::exists(stale));
  for (const char* folder : {"square-lms200", "square-utm30"})
    EXPECT_TRUE(std::filesystem::exists(Work("parts") / folder / "checkpoints" / "chain-1.ckpt"))
        << folder;

  std::filesystem::remove_all(Work("parts") / "summary.json");
  r = Run(SmallStudy({"--resume", "--no-figures", "-o", "parts"}));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(
      testing::WithoutSessionKeys(json::parse(testing::ReadAll(Work("parts") / "summary.json"))),
      testing::WithoutSessionKeys(json::parse(testing::ReadAll(Work("whole") / "summary.json"))));
  EXPECT_EQ(testing::FilesUnder(Work("parts")),
            (std::set<std::string>{"summary.json", "table.md"}));
}

// SIGTERM once the chains have checkpointed: they stop at their next chunk, checkpointed, with
// the shell's status for the signal (143), no temporary file left and no summary; the same
// command with --resume then ends with the uninterrupted study's summary.
TEST_F(PrfStudyCli, ASignalStopsTheStudyCheckpointedAndItResumes) {
  // One case whose chains run about a second, long enough to be signalled while they run.
  const std::vector<std::string> study = {"prf",         "study",  "--scenes",       "square",
                                          "--sensors",   "lms200", "--poses",        "2",
                                          "--beam-step", "6",      "--samples",      "200000",
                                          "--burn-in",   "20000",  "--anneal-steps", "3000",
                                          "--seed",      "5",      "--no-figures"};
  const auto with = [&](const std::vector<std::string>& extra) {
    std::vector<std::string> args = study;
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
  };
  const testing::SignalledRun stopped = testing::RunAndSignalOnceCheckpointed(
      Work("."), with({"--checkpoint-every", "0.01", "-o", "run"}),
      Work("run") / "square-lms200" / "checkpoints", SIGTERM);
  testing::ExpectStoppedBy(
      stopped, SIGTERM,
      "stopped and checkpointed in 1 of 1 cases (run/square-lms200/checkpoints); continue "
      "with the same command and --resume\n");
  EXPECT_FALSE(std::filesystem::exists(Work("run") / "summary.json"));
  EXPECT_FALSE(std::filesystem::is_empty(Work("run") / "square-lms200" / "checkpoints"));
  testing::ExpectNoTemporaryFile(Work("run"));

  const auto resumed = Run(with({"--resume", "-o", "run"}));
  ASSERT_EQ(resumed.status, 0) << resumed.err;
  EXPECT_THAT(resumed.err, ContainsRegex("resumed [1-9][0-9]* steps from the cases' checkpoints"));
  EXPECT_FALSE(std::filesystem::exists(Work("run") / "square-lms200" / "checkpoints"));
  testing::ExpectNoTemporaryFile(Work("run"));
  const auto whole = Run(with({"-o", "whole"}));
  ASSERT_EQ(whole.status, 0) << whole.err;
  const json expected = json::parse(testing::ReadAll(Work("whole") / "summary.json"));
  const json summary = json::parse(testing::ReadAll(Work("run") / "summary.json"));
  EXPECT_EQ(testing::WithoutSessionKeys(summary), testing::WithoutSessionKeys(expected));
  EXPECT_GT(summary["cases"][0]["prf"]["resumed_steps"].get<std::uint64_t>(), 0u);
}

}  // namespace
}  // namespace priormap
