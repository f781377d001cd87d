// End-to-end tests of `priormap prf` and `priormap grid`: the prior statistics as JSON; a
// simulated log mapped by PRF chains (every output, reproducible by seed, R-hat and acceptance
// in the summary) and by the occupancy grid; bad options reported without output.
#include <chrono>
#include <csignal>
#include <filesystem>
#include <limits>
#include <optional>
#include <set>
#include <string>
#include <sys/wait.h>
#include <system_error>
#include <unistd.h>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <priormap/prf/pooled_rhat.hpp>
#include <priormap/prf/rhat.hpp>

#include "cli_fixture.hpp"
#include "directory_lock.hpp"
#include "testing/ended_process.hpp"
#include "testing/temp_dir.hpp"

namespace priormap {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;
using ::testing::Not;

class PrfCli : public priormap::testing::CliFixture {};

TEST_F(PrfCli, PriorStatsPrintsEstimatesWithTheirClosedForms) {
  const auto r =
      Run({"prf", "prior-stats", "--p", "2", "--window", "0.5", "--samples", "400", "--thin", "50",
           "--burn-in", "20000", "--seed", "4", "--distances", "0.05,0.2"});
  ASSERT_EQ(r.status, 0) << r.err;
  const json out = json::parse(r.out);
  // In a 0.5 × 0.5 window with p = 2: p·perimeter + 4πp²·area = 4 + 4π.
  EXPECT_NEAR(out["expected_edges"].get<double>(), 4.0 + 4.0 * 3.14159265358979, 1e-9);
  EXPECT_GT(out["mean_edges"].get<double>(), 0.0);
  EXPECT_GT(out["mean_edges_se"].get<double>(), 0.0);
  EXPECT_EQ(out["black_fraction"]["closed_form"].get<double>(), 0.5);
  ASSERT_EQ(out["same_colour"].size(), 2u);
  EXPECT_DOUBLE_EQ(out["same_colour"][0]["distance"].get<double>(), 0.05);
  EXPECT_NEAR(out["same_colour"][1]["closed_form"].get<double>(),
              0.5 * (1.0 + std::exp(-4.0 * 2.0 * 0.2)), 1e-12);
  EXPECT_NEAR(out["crossings"][1]["mean"]["closed_form"].get<double>(), 0.8, 1e-12);
  EXPECT_EQ(out["steps"].get<int>(), 20000 + 400 * 50);
  for (const char* move : {"triangle_birth", "vertex_death", "local_recolor", "slide"})
    EXPECT_GT(out["acceptance"][move]["proposed"].get<int>(), 0) << move;
  // The same seed gives the same chain.
  const auto again =
      Run({"prf", "prior-stats", "--p", "2", "--window", "0.5", "--samples", "400", "--thin", "50",
           "--burn-in", "20000", "--seed", "4", "--distances", "0.05,0.2"});
  ASSERT_EQ(again.status, 0);
  EXPECT_EQ(json::parse(again.out)["mean_edges"], out["mean_edges"]);
}

// A chain that never leaves its empty start has no spread: its z-scores are infinite, and JSON
// has no infinity (nlohmann would write null, which a check `z < 3` could take for missing).
TEST_F(PrfCli, PriorStatsWritesAnInfiniteZScoreAsInf) {
  const auto r = Run({"prf", "prior-stats", "--samples", "100", "--burn-in", "0", "--moves",
                      "recolor", "--distances", "0.3"});
  ASSERT_EQ(r.status, 0) << r.err;
  const json out = json::parse(r.out);
  EXPECT_EQ(out["same_colour"][0]["se"].get<double>(), 0.0);
  EXPECT_EQ(out["same_colour"][0]["z"], "inf");
  EXPECT_TRUE(out.contains("mean_edges_z"));
}

TEST_F(PrfCli, PriorStatsWithSomeMoveKindsOnly) {
  const auto r = Run(
      {"prf", "prior-stats", "--samples", "100", "--burn-in", "0", "--moves", "triangle,vertex"});
  ASSERT_EQ(r.status, 0) << r.err;
  const json out = json::parse(r.out);
  EXPECT_GT(out["acceptance"]["triangle_birth"]["proposed"].get<int>(), 0);
  EXPECT_EQ(out["acceptance"]["slide"]["proposed"].get<int>(), 0);
  EXPECT_EQ(out["acceptance"]["corner_birth"]["proposed"].get<int>(), 0);
}

TEST_F(PrfCli, PriorStatsRejectsBadOptions) {
  EXPECT_THAT(RunFailing({"prf", "prior-stats", "--p", "0"}).err,
              HasSubstr("--p: 0 is not positive"));
  EXPECT_THAT(RunFailing({"prf", "prior-stats", "--moves", "teleport"}).err,
              HasSubstr("unknown move kind 'teleport'"));
  EXPECT_THAT(RunFailing({"prf", "prior-stats", "--window", "2", "--distances", "3"}).err,
              HasSubstr("--distances: 3 is not inside (0, window = 2)"));
  EXPECT_THAT(RunFailing({"prf", "prior-stats", "--samples", "10"}).err,
              HasSubstr("--samples must be at least 80"));
  EXPECT_NE(RunFailing({"prf"}).status, 0);
}

// A simulated localized log of the l-room (lms200), as CARMEN.
class MappingCli : public PrfCli {
 protected:
  void SetUp() override {
    const auto r = Run({"simulate", "--scene", "l-room", "--sensor", "lms200", "--log", "--seed",
                        "2", "-o", "room.log"});
    ASSERT_EQ(r.status, 0) << r.err;
  }
};

TEST_F(MappingCli, PrfWritesThePosteriorTheMapAndASummary) {
  const std::vector<std::string> args = {
      "prf",       "--log",    "room.log",      "--beam-step", "4",        "--p", "0.5",
      "--samples", "40000",    "--burn-in",     "40000",       "--chains", "2",   "--seed",
      "3",         "--anneal", "--trace-every", "2000"};
  auto with_out = [&](const std::string& dir) {
    std::vector<std::string> a = args;
    a.insert(a.end(), {"-o", dir});
    return a;
  };
  const auto r = Run(with_out("run1"));
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* file :
       {"summary.json", "posterior.png", "posterior.pgm", "posterior.yaml", "not_white.png",
        "trace.csv", "chains_disagree.png", "chain0.png", "chain1.png", "chain0_last.geojson",
        "chain1_last.geojson", "map.geojson", "map.svg", "map.png", "map.pgm", "map.yaml"})
    EXPECT_TRUE(std::filesystem::exists(Work("run1") / file)) << file;
  const json summary = json::parse(testing::ReadAll(Work("run1") / "summary.json"));
  EXPECT_GT(summary["proposals_per_second"].get<double>(), 0.0);
  EXPECT_GT(summary["wall_time_s"].get<double>(), 0.0);
  EXPECT_EQ(summary["log_posterior"].size(), 2u);
  // The last progress line shows both chains' final log posteriors, in chain order.
  EXPECT_THAT(r.err, HasSubstr(fmt::format("log posteriors {:.1f}, {:.1f}\n",
                                           summary["log_posterior"][0].get<double>(),
                                           summary["log_posterior"][1].get<double>())));
  // The log-posterior splits into the prior's part and the data's.
  for (std::size_t c = 0; c < 2; ++c)
    EXPECT_NEAR(summary["log_prior"][c].get<double>() + summary["log_likelihood"][c].get<double>(),
                summary["log_posterior"][c].get<double>(), 1e-9);
  EXPECT_EQ(json::parse(testing::ReadAll(Work("run1") / "chain1_last.geojson"))["type"],
            "FeatureCollection");
  EXPECT_TRUE(summary["rhat"]["log_posterior"].is_number());
  EXPECT_GE(summary["chain_disagreement"]["area_over_half_m2"].get<double>(), 0.0);
  EXPECT_LE(summary["chain_disagreement"]["largest"].get<double>(), 1.0);
  EXPECT_GT(summary["acceptance"]["slide"]["accepted"].get<int>(), 0);
  EXPECT_GT(summary["map"]["edges"].get<int>(), 4);
  const json map = json::parse(testing::ReadAll(Work("run1") / "map.geojson"));
  EXPECT_EQ(map["type"], "FeatureCollection");
  EXPECT_GT(map["features"].size(), 0u);
  // The same seed gives the same maps, whatever the threads did.
  ASSERT_EQ(Run(with_out("run2")).status, 0);
  const json again = json::parse(testing::ReadAll(Work("run2") / "summary.json"));
  EXPECT_EQ(again["log_posterior"], summary["log_posterior"]);
  EXPECT_EQ(testing::ReadAll(Work("run2") / "posterior.pgm"),
            testing::ReadAll(Work("run1") / "posterior.pgm"));
  EXPECT_EQ(testing::ReadAll(Work("run2") / "map.geojson"),
            testing::ReadAll(Work("run1") / "map.geojson"));
}

TEST_F(MappingCli, PrfWarnsWhenItsChainsHaveNotConverged) {
  const auto run = [&](const std::vector<std::string>& extra, const std::string& dir) {
    std::vector<std::string> args = {"prf", "--log",  "room.log", "--p", "0.5", "--chains",
                                     "2",   "--seed", "3",        "-o",  dir};
    args.insert(args.end(), extra.begin(), extra.end());
    const auto r = Run(args);
    EXPECT_EQ(r.status, 0) << r.err;
    const json rhat = json::parse(testing::ReadAll(Work(dir) / "summary.json"))["rhat"];
    return std::pair{r.err, rhat};
  };
  // All the scans, every 4th beam, a 1,000-step burn-in: the chains are still apart.
  const auto [short_err, short_rhat] =
      run({"--beam-step", "4", "--burn-in", "1000", "--samples", "20000", "--trace-every", "1000"},
          "short");
  ASSERT_GT(short_rhat["log_posterior"].get<double>(), 1.1);
  EXPECT_THAT(short_err, HasSubstr("priormap: warning: the chains have not converged"));
  // Which chain sits where: the second-half means, in summary.json and on stderr.
  const json short_summary = json::parse(testing::ReadAll(Work("short") / "summary.json"));
  const json& means = short_summary["log_posterior_second_half_means"];
  ASSERT_EQ(means.size(), 2u);
  const auto trace =
      prf::ParseLogPosteriorTrace(testing::ReadAll(Work("short") / "trace.csv"), "trace.csv");
  ASSERT_TRUE(trace.ok()) << trace.error();
  for (std::size_t c = 0; c < 2; ++c) {
    const std::vector<double>& records = trace.value().log_posterior[c];
    double sum = 0.0;  // the last 10 of the 20 records (--samples 20000, --trace-every 1000)
    ASSERT_EQ(records.size(), 20u);
    for (std::size_t i = 10; i < 20; ++i) sum += records[i];
    EXPECT_DOUBLE_EQ(means[c].get<double>(), sum / 10.0);
  }
  EXPECT_THAT(short_err, HasSubstr(fmt::format("{:.1f} (chain0.png), {:.1f} (chain1.png)",
                                               means[0].get<double>(), means[1].get<double>())));
  // Three scans, every 16th beam, three million samples: both R̂ far below 1.1, no warning.
  const auto [long_err, long_rhat] =
      run({"--range", "0:3", "--beam-step", "16", "--burn-in", "100000", "--samples", "3000000",
           "--trace-every", "20000"},
          "long");
  ASSERT_LT(long_rhat["log_posterior"].get<double>(), 1.05);
  ASSERT_LT(long_rhat["point_colours"].get<double>(), 1.05);
  EXPECT_THAT(long_err, Not(HasSubstr("warning")));
}

// --anneal without --anneal-steps anneals for --samples steps: the resumed run must see the
// same annealing length as the one that made the checkpoints.
TEST_F(MappingCli, AStoppedRunWithTheDefaultAnnealingResumes) {
  const std::vector<std::string> run = {
      "prf",  "--log",     "room.log", "--beam-step", "4", "--p",    "0.5", "--samples",
      "3000", "--burn-in", "3000",     "--chains",    "1", "--seed", "3",   "--anneal"};
  auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> a = run;
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  };
  ASSERT_EQ(Run(with({"-o", "whole"})).status, 0);
  ASSERT_EQ(Run(with({"-o", "parts", "--stop-after-steps", "2000"})).status, 0);
  const auto r = Run({"prf", "--resume", Work("parts").string()});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(testing::ReadAll(Work("parts") / "map.geojson"),
            testing::ReadAll(Work("whole") / "map.geojson"));
}

TEST_F(MappingCli, AStoppedRunResumesToTheUninterruptedResult) {
  const std::vector<std::string> run = {"prf",
                                        "--log",
                                        "room.log",
                                        "--beam-step",
                                        "4",
                                        "--p",
                                        "0.5",
                                        "--samples",
                                        "30000",
                                        "--burn-in",
                                        "20000",
                                        "--chains",
                                        "2",
                                        "--seed",
                                        "7",
                                        "--anneal",
                                        "--anneal-steps",
                                        "20000",
                                        "--trace-every",
                                        "1000"};
  auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> a = run;
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  };
  ASSERT_EQ(Run(with({"-o", "whole"})).status, 0);
  // Sessions that stop in the burn-in (at 15000 steps), in the sampling (32000) and in the
  // annealing (18000 of its 20000 steps); the last one completes the run.
  auto r = Run(with({"-o", "parts", "--stop-after-steps", "15000"}));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("priormap prf --resume"));
  EXPECT_TRUE(std::filesystem::exists(Work("parts") / "checkpoints" / "chain-1.ckpt"));
  EXPECT_FALSE(std::filesystem::exists(Work("parts") / "summary.json"));
  for (const char* steps : {"17000", "18000"}) {
    r = Run({"prf", "--resume", Work("parts").string(), "--stop-after-steps", steps});
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_THAT(r.err, HasSubstr("resumed"));
    // The status line starts where the checkpoints left the chains, not at 0 %.
    EXPECT_THAT(r.err, HasSubstr("% restored from the checkpoints\n"));
    EXPECT_THAT(r.err, Not(HasSubstr(" 0% restored")));
  }
  EXPECT_TRUE(std::filesystem::exists(Work("parts") / "checkpoints" / "anneal.ckpt"));
  EXPECT_FALSE(std::filesystem::exists(Work("parts") / "summary.json"));
  r = Run({"prf", "--resume", Work("parts").string()});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("resumed 118000 steps"));  // 18000 of them the annealing's
  // Chains restored at their end never report: this line says where the run stands, then the
  // annealing's lines go on from there.
  EXPECT_THAT(r.err, HasSubstr(" 98% restored from the checkpoints\n"));
  EXPECT_THAT(r.err, HasSubstr("100% "));
  EXPECT_THAT(r.err, HasSubstr(", annealing chain "));
  for (const char* file :
       {"posterior.pgm", "map.geojson", "map.pgm", "trace.csv", "point_traces.csv"})
    EXPECT_EQ(testing::ReadAll(Work("parts") / file), testing::ReadAll(Work("whole") / file))
        << file;
  const json whole = json::parse(testing::ReadAll(Work("whole") / "summary.json"));
  const json parts = json::parse(testing::ReadAll(Work("parts") / "summary.json"));
  for (const char* key : {"log_posterior", "edges", "acceptance", "rhat", "map"})
    EXPECT_EQ(parts[key], whole[key]) << key;
  EXPECT_FALSE(std::filesystem::exists(Work("parts") / "checkpoints"));
  EXPECT_THAT(RunFailing({"prf", "--resume", Work("parts").string()}).err,
              HasSubstr("is complete"));
}

TEST_F(MappingCli, ResumeRefusesAnEditedRunFileThatTheCommandLineWouldRefuse) {
  ASSERT_EQ(Run({"prf", "--log", "room.log", "--beam-step", "8", "--samples", "4000", "--burn-in",
                 "4000", "--chains", "1", "--stop-after-steps", "2000", "-o", "run"})
                .status,
            0);
  const auto run_file = Work("run") / "run.json";
  const json original = json::parse(testing::ReadAll(run_file));
  const std::vector<std::pair<std::string, json>> edits = {
      {"chains", 0},    {"chains", 1e300}, {"samples", -1.5},    {"trace_every", 0},
      {"cell_size", 0}, {"p", -1},         {"guide_jitter", -1}, {"sigma", -1}};
  for (const auto& [key, value] : edits) {
    json edited = original;
    edited[key] = value;
    testing::WriteAll(run_file, edited.dump(2));
    const auto r = RunFailing({"prf", "--resume", Work("run").string()});
    EXPECT_EQ(r.status, 1) << key;
    EXPECT_THAT(r.err, HasSubstr(run_file.string() + ": ")) << key;
    EXPECT_THAT(r.err, HasSubstr("\"" + key + "\"")) << key;
  }
}

// run.json keeps the orientation in radians too: -315.5 degrees read back as radians is one bit
// off, which the checkpoints' fingerprint of the options would not match.
TEST_F(MappingCli, AStoppedRunWithAnyOrientationResumes) {
  ASSERT_EQ(Run({"prf", "--log", "room.log", "--beam-step", "8", "--samples", "3000", "--burn-in",
                 "3000", "--chains", "1", "--orientation", "-315.5", "--orientation-weight", "1",
                 "--stop-after-steps", "100", "-o", "run"})
                .status,
            0);
  const auto r = Run({"prf", "--resume", Work("run").string()});
  EXPECT_EQ(r.status, 0) << r.err;
}

TEST_F(MappingCli, ResumeRefusesWhatWouldMakeAnotherRun) {
  EXPECT_THAT(RunFailing({"prf", "--resume", Work("nowhere").string()}).err,
              HasSubstr("no run.json"));
  ASSERT_EQ(Run({"prf", "--log", "room.log", "--beam-step", "8", "--samples", "4000", "--burn-in",
                 "4000", "--chains", "1", "--stop-after-steps", "2000", "-o", "run"})
                .status,
            0);
  EXPECT_THAT(RunFailing({"prf", "--resume", Work("run").string(), "--p", "2"}).err,
              HasSubstr("--p cannot be combined with --resume"));
  // A damaged checkpoint is refused, not half-read.
  const auto checkpoint = Work("run") / "checkpoints" / "chain-0.ckpt";
  std::string bytes = testing::ReadAll(checkpoint);
  bytes[bytes.size() / 2] ^= 0x10;
  testing::WriteAll(checkpoint, bytes);
  EXPECT_THAT(RunFailing({"prf", "--resume", Work("run").string()}).err,
              HasSubstr("checksum mismatch"));
  // A new run in the directory of a stopped one would delete its checkpoints: refused, until
  // they are removed; then it replaces the stopped run, whose checkpoints it must not meet.
  const std::vector<std::string> new_run = {
      "prf",       "--log", "room.log",  "--beam-step", "8",        "--p", "0.3",
      "--samples", "4000",  "--burn-in", "4000",        "--chains", "1",   "--stop-after-steps",
      "3000",      "-o",    "run"};
  EXPECT_THAT(RunFailing(new_run).err,
              HasSubstr("-o run: it holds a stopped run (run/checkpoints); continue it with "
                        "priormap prf --resume run, or remove run/checkpoints"));
  std::filesystem::remove_all(Work("run") / "checkpoints");
  ASSERT_EQ(Run(new_run).status, 0);
  const auto r = Run({"prf", "--resume", Work("run").string()});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("resumed 3000 steps"));
}

// A run of two chains, small enough to run again and again; `extra` adds options.
std::vector<std::string> SmallRun(const std::vector<std::string>& extra) {
  std::vector<std::string> args = {
      "prf",       "--log",         "room.log",  "--beam-step", "8",
      "--samples", "4000",          "--burn-in", "4000",        "--chains",
      "2",         "--seed",        "5",         "--anneal",    "--anneal-steps",
      "2000",      "--trace-every", "500"};
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}

// The outputs of two runs, byte for byte, but summary.json's session keys (its timing and what
// this session did or restored).
void ExpectTheSameOutputs(const std::filesystem::path& resumed,
                          const std::filesystem::path& whole) {
  for (const std::string& file : testing::FilesUnder(whole)) {
    if (file == "summary.json" || std::filesystem::is_directory(whole / file)) continue;
    EXPECT_EQ(testing::ReadAll(resumed / file), testing::ReadAll(whole / file)) << file;
  }
  EXPECT_EQ(testing::FilesUnder(resumed), testing::FilesUnder(whole));
  json a = json::parse(testing::ReadAll(resumed / "summary.json"));
  json b = json::parse(testing::ReadAll(whole / "summary.json"));
  for (const char* key : {"wall_time_s", "proposals", "proposals_per_second", "resumed_steps"}) {
    a.erase(key);
    b.erase(key);
  }
  EXPECT_EQ(a, b);
}

// Checkpoints a resume cannot go on from are refused, each saying why and what to do, and the
// run's files are left as they were; done as said, the run ends as the uninterrupted one.
TEST_F(MappingCli, AResumeRefusedSaysWhyAndWhatToDo) {
  ASSERT_EQ(Run(SmallRun({"-o", "whole"})).status, 0);
  ASSERT_EQ(Run(SmallRun({"--stop-after-steps", "3000", "-o", "run"})).status, 0);
  const std::filesystem::path run_file = Work("run") / "run.json";
  const std::string run_file_text = testing::ReadAll(run_file);
  const json recorded = json::parse(run_file_text);
  ASSERT_TRUE(recorded["fingerprints"]["data"].is_string());
  ASSERT_TRUE(recorded["fingerprints"]["run"].is_string());
  const std::string log = recorded["log"].get<std::string>();
  const auto refusal = [&] {
    const auto r = RunFailing({"prf", "--resume", "run"});
    EXPECT_EQ(r.status, 1);
    return r.err;
  };

  // The log changed since the run started (another simulation of the room).
  const std::string original_log = testing::ReadAll(Work("room.log"));
  ASSERT_EQ(Run({"simulate", "--scene", "l-room", "--sensor", "lms200", "--log", "--seed", "3",
                 "-o", "room.log"})
                .status,
            0);
  EXPECT_THAT(refusal(),
              HasSubstr("--resume run: the run's data are not those it started with: the log " +
                        log + " changed since"));
  // Without the record (a run file written before it), the checkpoints refuse it.
  json unrecorded = recorded;
  unrecorded.erase("fingerprints");
  testing::WriteAll(run_file, unrecorded.dump(2));
  std::string err = refusal();
  EXPECT_THAT(err, HasSubstr("cannot resume: run/checkpoints/chain-"));
  EXPECT_THAT(err, HasSubstr(": a checkpoint of another run (its data or options differ from this "
                             "one's): the log " +
                             log + " or run/run.json changed since the run started"));
  EXPECT_THAT(err, HasSubstr("or remove run/checkpoints and start a new run there"));
  testing::WriteAll(Work("room.log"), original_log);

  // The same data, hashed with other options: another version of priormap started the run.
  json other_version = recorded;
  other_version["fingerprints"]["run"] = "0123456789abcdef";
  testing::WriteAll(run_file, other_version.dump(2));
  EXPECT_THAT(refusal(), HasSubstr("--resume run: this priormap makes another run of run/run.json "
                                   "than the one that started there: the same data, but other "
                                   "options (run/run.json was edited, or another version"));
  // An edited option reads the same.
  other_version = recorded;
  other_version["p"] = 0.6;
  testing::WriteAll(run_file, other_version.dump(2));
  EXPECT_THAT(refusal(), HasSubstr("the same data, but other options (run/run.json was edited"));
  other_version = recorded;
  other_version["version"] = 3;
  testing::WriteAll(run_file, other_version.dump(2));
  EXPECT_THAT(refusal(), HasSubstr("run/run.json: version 3 of the run file, which another version "
                                   "of priormap wrote; this one reads version 2"));
  testing::WriteAll(run_file, run_file_text);

  // A checkpoint of an earlier format version: another priormap wrote it.
  const std::filesystem::path chain1 = Work("run") / "checkpoints" / "chain-1.ckpt";
  const std::string checkpoint = testing::ReadAll(chain1);
  std::string earlier = checkpoint;
  earlier[8] = static_cast<char>(earlier[8] - 1);  // the format's version (SealBinary's header)
  testing::WriteAll(chain1, earlier);
  err = refusal();
  EXPECT_THAT(err, HasSubstr("chain-1.ckpt: a checkpoint of version "));
  EXPECT_THAT(err, HasSubstr("which an earlier priormap wrote; this one reads version "));
  EXPECT_THAT(err, HasSubstr("continue the run with the priormap that started it, or remove "
                             "run/checkpoints"));

  // Unreadable (a directory in its place): not damage, so it is not to be removed.
  std::filesystem::remove(chain1);
  std::filesystem::create_directories(chain1 / "in the way");
  err = refusal();
  EXPECT_THAT(err, HasSubstr("run/checkpoints/chain-1.ckpt"));
  EXPECT_THAT(err, HasSubstr("the checkpoint is kept: make it a file priormap can read and "
                             "resume again"));
  EXPECT_THAT(err, Not(HasSubstr("remove that file")));
  std::filesystem::remove_all(chain1);

  // Damaged: removed as told, its chain starts afresh and the run ends as the uninterrupted one.
  std::string damaged = checkpoint;
  damaged[damaged.size() / 2] ^= 0x10;
  testing::WriteAll(chain1, damaged);
  EXPECT_THAT(refusal(), HasSubstr("run/checkpoints/chain-1.ckpt: checksum mismatch (the file is "
                                   "damaged); remove that file and resume again"));
  std::filesystem::remove(chain1);
  const auto r = Run({"prf", "--resume", "run"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("resumed 3000 steps"));  // chain 0's alone
  ExpectTheSameOutputs(Work("run"), Work("whole"));
}

// A write that fails (here summary.json, where a directory stands) loses nothing: the run keeps
// its checkpoints and says how to go on, and once the write can be done the resume ends as the
// uninterrupted run. A new run that cannot remove an earlier run's output says which.
TEST_F(MappingCli, AFailedWriteKeepsTheCheckpointsAndTheRunResumes) {
  ASSERT_EQ(Run(SmallRun({"-o", "whole"})).status, 0);
  ASSERT_EQ(Run(SmallRun({"--stop-after-steps", "3000", "-o", "run"})).status, 0);
  std::filesystem::create_directories(Work("run") / "summary.json" / "in the way");
  auto r = Run({"prf", "--resume", "run"});
  EXPECT_EQ(r.status, 1);
  EXPECT_THAT(r.err, HasSubstr("run/summary.json: cannot write: "));
  EXPECT_THAT(r.err, HasSubstr("; the run's checkpoints are kept: once run can be written, "
                               "continue it with: priormap prf --resume run\n"));
  EXPECT_THAT(r.err, Not(HasSubstr("internal error")));
  EXPECT_TRUE(std::filesystem::exists(Work("run") / "checkpoints" / "chain-0.ckpt"));

  r = Run(SmallRun({"-o", "run"}));  // not a resume: the earlier run's outputs go first
  EXPECT_EQ(r.status, 1);
  EXPECT_THAT(r.err, HasSubstr("it holds a stopped run"));
  std::filesystem::create_directories(Work("blocked") / "summary.json" / "in the way");
  r = Run(SmallRun({"-o", "blocked"}));
  EXPECT_EQ(r.status, 1);
  EXPECT_THAT(r.err,
              HasSubstr("-o blocked: cannot remove the earlier run's blocked/summary.json: "));

  std::filesystem::remove_all(Work("run") / "summary.json");
  r = Run({"prf", "--resume", "run"});
  ASSERT_EQ(r.status, 0) << r.err;
  ExpectTheSameOutputs(Work("run"), Work("whole"));
}

// The directory's lock is taken before its contents are judged: a run that holds it (here this
// test, in the middle of completing the run, say) is not taken for a complete one, nor its
// checkpoints for a stopped run's. A temporary that a checkpoint write killed mid-way left goes
// with the next session, whatever process its PID names now.
TEST_F(MappingCli, AResumeJudgesTheDirectoryUnderItsLock) {
  ASSERT_EQ(Run(SmallRun({"--stop-after-steps", "3000", "-o", "run"})).status, 0);
  ASSERT_EQ(Run(SmallRun({"-o", "complete"})).status, 0);
  {
    const app::DirectoryLock held(Work("complete"));
    EXPECT_THAT(RunFailing({"prf", "--resume", "complete"}).err,
                HasSubstr("-o complete: another priormap is running there"));
    const app::DirectoryLock stopped(Work("run"));
    EXPECT_THAT(RunFailing({"prf", "--resume", "run"}).err,
                HasSubstr("-o run: another priormap is running there"));
    EXPECT_THAT(RunFailing(SmallRun({"-o", "run"})).err,
                HasSubstr("-o run: another priormap is running there"));
  }
  // Process 1 runs (it is init), but holds no lock of this directory: it cannot be writing it.
  const std::filesystem::path stale = Work("run") / "checkpoints" / ".chain-0.ckpt.tmp-1-0";
  testing::WriteAll(stale, "half a checkpoint");
  const auto r = Run({"prf", "--resume", "run", "--stop-after-steps", "100"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_FALSE(std::filesystem::exists(stale));
}

// The traces a run wrote, as `prf rhat` reads them.
prf::RunTraces TracesOf(const std::filesystem::path& dir) {
  const auto traces = prf::ParseLogPosteriorTrace(testing::ReadAll(dir / "trace.csv"), "trace");
  EXPECT_TRUE(traces.ok()) << traces.error();
  const auto with_points =
      prf::ParsePointTraces(testing::ReadAll(dir / "point_traces.csv"), "points", traces.value());
  EXPECT_TRUE(with_points.ok()) << with_points.error();
  return with_points.value();
}

TEST_F(MappingCli, RhatPoolsTheChainsOfSeveralRuns) {
  const auto run = [&](const std::string& seed, const std::string& p, const std::string& dir) {
    const auto r = Run({"prf", "--log", "room.log", "--beam-step", "4", "--p", p, "--samples",
                        "20000", "--burn-in", "1000", "--chains", "2", "--seed", seed,
                        "--trace-every", "1000", "-o", dir});
    ASSERT_EQ(r.status, 0) << r.err;
  };
  run("3", "0.5", "a");
  run("5", "0.5", "b");
  // R̂ is +inf when each half of each chain is constant but the halves differ ("inf").
  const auto rhat = [](const json& value) {
    return value.is_string() && value == "inf" ? std::numeric_limits<double>::infinity()
                                               : value.get<double>();
  };
  // One run alone: its own R̂, from the files it wrote.
  auto r = Run({"prf", "rhat", "b"});
  ASSERT_EQ(r.status, 0) << r.err;
  const json alone = json::parse(r.out);
  const json summary = json::parse(testing::ReadAll(Work("b") / "summary.json"));
  EXPECT_EQ(alone["chains"], 2);
  EXPECT_EQ(alone["records"], 20);
  EXPECT_DOUBLE_EQ(rhat(alone["rhat"]["log_posterior"]),
                   summary["rhat"]["log_posterior"].get<double>());
  // Seed 5's chains are still settling (a short burn-in), so its colours' R̂ is finite and
  // above 1, which checks the colours point_traces.csv holds.
  ASSERT_TRUE(summary["rhat"]["point_colours"].is_number());
  ASSERT_GT(summary["rhat"]["point_colours"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(rhat(alone["rhat"]["point_colours"]),
                   summary["rhat"]["point_colours"].get<double>());
  EXPECT_EQ(alone["rhat"]["points"], summary["rhat"]["points"]);
  EXPECT_EQ(summary["trace_points"].size(), summary["rhat"]["points"].get<std::size_t>());

  // Two runs: split-R̂ over their four chains.
  r = Run({"prf", "rhat", "a", "b"});
  ASSERT_EQ(r.status, 0) << r.err;
  const json both = json::parse(r.out);
  EXPECT_EQ(both["chains"], 4);
  EXPECT_EQ(both["runs"][1]["chain_seeds"], json({5, 6}));
  std::vector<std::vector<double>> lp;
  double colours = 1.0;
  const prf::RunTraces a = TracesOf(Work("a")), b = TracesOf(Work("b"));
  for (const prf::RunTraces* t : {&a, &b})
    lp.insert(lp.end(), t->log_posterior.begin(), t->log_posterior.end());
  std::vector<std::pair<double, std::size_t>> disagreeing;  // (R̂, point), worst first
  for (std::size_t k = 0; k < a.point_colours[0].size(); ++k) {
    std::vector<std::vector<double>> point;
    for (const prf::RunTraces* t : {&a, &b})
      for (const auto& chain : t->point_colours) point.push_back(chain[k]);
    colours = std::max(colours, prf::SplitRhat(point));
    if (!(prf::SplitRhat(point) < prf::kConvergedRhat))
      disagreeing.emplace_back(prf::SplitRhat(point), k);
  }
  EXPECT_DOUBLE_EQ(rhat(both["rhat"]["log_posterior"]), prf::SplitRhat(lp));
  EXPECT_EQ(rhat(both["rhat"]["point_colours"]), colours);
  // The points behind a colours' R̂ not below 1.1, worst first, where they are and how often
  // each chain held them black.
  std::ranges::stable_sort(disagreeing, std::greater{}, [](const auto& p) { return p.first; });
  ASSERT_FALSE(disagreeing.empty());  // the colours' R̂ of seed 5 alone is above 1
  ASSERT_EQ(both["disagreeing_points"].size(), disagreeing.size());
  for (std::size_t i = 0; i < disagreeing.size(); ++i) {
    const json& point = both["disagreeing_points"][i];
    const std::size_t k = disagreeing[i].second;
    EXPECT_EQ(point["point"], k);
    EXPECT_EQ(point["at"], summary["trace_points"][k]);
    EXPECT_EQ(rhat(point["rhat"]), disagreeing[i].first);
    ASSERT_EQ(point["black"].size(), 4u);
    double black = 0.0;
    for (double c : b.point_colours[1][k]) black += c;
    EXPECT_DOUBLE_EQ(point["black"][3].get<double>(), black / b.point_colours[1][k].size());
  }

  // What cannot be pooled.
  EXPECT_THAT(RunFailing({"prf", "rhat", "a", "a"}).err,
              HasSubstr("a: a chain draws from seed 3, as one of another run does"));
  run("7", "1", "other_p");
  EXPECT_THAT(RunFailing({"prf", "rhat", "a", "other_p"}).err,
              HasSubstr("other_p maps another posterior than a: its p is 1.0, not 0.5"));
  // A run that has not completed may still hold an earlier run's traces.
  const auto stopped =
      Run({"prf",  "--log",     "room.log", "--beam-step",   "4",    "--p",
           "0.5",  "--samples", "20000",    "--burn-in",     "1000", "--chains",
           "2",    "--seed",    "9",        "--trace-every", "1000", "--stop-after-steps",
           "5000", "-o",        "stopped"});
  ASSERT_EQ(stopped.status, 0) << stopped.err;
  EXPECT_THAT(RunFailing({"prf", "rhat", "a", "stopped"}).err,
              HasSubstr("stopped: not a complete `priormap prf` run"));
  // Runs made elsewhere name their log by another path, maybe by another name: the data's
  // fingerprint is what must agree.
  std::filesystem::copy(Work("b"), Work("moved"));
  json moved = json::parse(testing::ReadAll(Work("moved") / "run.json"));
  moved["log"] = "/somewhere/else/other.log";
  testing::WriteAll(Work("moved") / "run.json", moved.dump(2));
  r = Run({"prf", "rhat", "a", "moved"});
  EXPECT_EQ(r.status, 0) << r.err;
  json moved_summary = json::parse(testing::ReadAll(Work("moved") / "summary.json"));
  const std::string fingerprint = summary["data_fingerprint"].get<std::string>();
  EXPECT_EQ(fingerprint.size(), 16u);
  moved_summary["data_fingerprint"] = "0123456789abcdef";
  testing::WriteAll(Work("moved") / "summary.json", moved_summary.dump(2));
  EXPECT_THAT(RunFailing({"prf", "rhat", "a", "moved"}).err,
              HasSubstr(fmt::format("its data fingerprint is \"0123456789abcdef\", not \"{}\"",
                                    fingerprint)));
  // Runs made before summary.json held the fingerprint are compared by the log's file name.
  moved_summary.erase("data_fingerprint");
  testing::WriteAll(Work("moved") / "summary.json", moved_summary.dump(2));
  EXPECT_THAT(RunFailing({"prf", "rhat", "a", "moved"}).err,
              HasSubstr("its log file name is \"other.log\", not \"room.log\""));
  moved["log"] = "/somewhere/else/room.log";
  testing::WriteAll(Work("moved") / "run.json", moved.dump(2));
  r = Run({"prf", "rhat", "a", "moved"});
  EXPECT_EQ(r.status, 0) << r.err;
  std::filesystem::copy(Work("b"), Work("broken"));
  testing::WriteAll(Work("broken") / "trace.csv", "sample,chain0,chain1\n1000,1,x\n");
  EXPECT_THAT(RunFailing({"prf", "rhat", "a", "broken"}).err,
              HasSubstr("broken/trace.csv:2:8: expected a finite log-posterior, found 'x'"));
  EXPECT_NE(RunFailing({"prf", "rhat", "missing"}).status, 0);
  // An edited summary.json is refused with its file named, never read out of range.
  std::filesystem::copy(Work("moved"), Work("edited"));
  json edited = moved_summary;
  edited["trace_points"] = 0;
  testing::WriteAll(Work("edited") / "summary.json", edited.dump(2));
  EXPECT_THAT(RunFailing({"prf", "rhat", "a", "edited"}).err,
              HasSubstr("edited/summary.json: the member 'trace_points' has the wrong type"));
  edited = moved_summary;
  edited["beams"] = -1.5;
  testing::WriteAll(Work("edited") / "summary.json", edited.dump(2));
  EXPECT_THAT(RunFailing({"prf", "rhat", "a", "edited"}).err,
              HasSubstr("edited/summary.json: \"beams\" must be a whole number"));
  // Not JSON: located in characters ("é" is two bytes, one column).
  testing::WriteAll(Work("edited") / "summary.json", "{\"name\": \"é\" x}");
  EXPECT_THAT(RunFailing({"prf", "rhat", "a", "edited"}).err,
              HasSubstr("edited/summary.json:1:14: expected the JSON a `priormap prf` run writes"));
}

TEST_F(MappingCli, AnEmptyOutputDirectoryNameIsRefusedAsSuch) {
  const auto r = RunFailing({"grid", "--log", "room.log", "-o", ""});
  EXPECT_EQ(r.status, 1);
  EXPECT_THAT(r.err, HasSubstr("expected an output directory, got an empty name (. is the "
                               "current one)"));
}

TEST_F(MappingCli, GridWritesTheMapAndASummary) {
  const auto r = Run({"grid", "--log", "room.log", "--resolution", "0.05", "-o", "grid"});
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* file : {"summary.json", "grid.png", "grid.pgm", "grid.yaml"})
    EXPECT_TRUE(std::filesystem::exists(Work("grid") / file)) << file;
  const json summary = json::parse(testing::ReadAll(Work("grid") / "summary.json"));
  EXPECT_GT(summary["beams"].get<int>(), 1000);
  EXPECT_GT(summary["beams_per_second"].get<double>(), 0.0);
}

// A run killed by SIGKILL (no handler runs) leaves the temporaries of the outputs it was
// writing in its -o DIR. The next command writing there removes those of its own outputs whose
// process has ended; a running process's, and the user's files, stay.
TEST_F(MappingCli, GridRemovesTheStaleTemporariesOfItsOutputsOnly) {
  std::filesystem::create_directory(Work("grid"));
  const std::string ended = std::to_string(testing::EndedProcessId());
  const std::vector<std::string> stale = {".summary.json.tmp-" + ended + "-0",
                                          ".grid.png.tmp-" + ended + "-3"};
  const std::vector<std::string> kept = {
      ".summary.json.tmp-" + std::to_string(::getpid()) + "-0",  // this test runs
      ".notes.txt.tmp-" + ended + "-0", "notes.txt"};
  for (const std::string& name : stale) testing::WriteAll(Work("grid") / name, "half written");
  for (const std::string& name : kept) testing::WriteAll(Work("grid") / name, "kept");
  const auto r = Run({"grid", "--log", "room.log", "--resolution", "0.05", "-o", "grid"});
  ASSERT_EQ(r.status, 0) << r.err;
  for (const std::string& name : stale)
    EXPECT_FALSE(std::filesystem::exists(Work("grid") / name)) << name;
  for (const std::string& name : kept)
    EXPECT_TRUE(std::filesystem::exists(Work("grid") / name)) << name;
}

// The laser grid maps laser scans only, refuses a log with nothing to map and a grid too large
// for memory, and leaves no directory behind when it refuses.
TEST_F(MappingCli, GridRefusesWhatItCannotMapBeforeWritingAnything) {
  testing::WriteAll(
      Work("mixed.json"),
      R"({"format":"priormap.log","version":1,"records":[)"
      R"({"type":"scan","pose":[0,0,0],"max_range":8,"angles":[0],"ranges":[1.0]},)"
      R"({"type":"scan","channel":"SONAR","pose":[0,0,0],"min_range":0.17,"max_range":5,)"
      R"("angles":[1.5707963267948966],"ranges":[2.0],"sonar":{"spread":0.5}}]})");
  const auto laser = Run({"grid", "--log", "mixed.json", "--sensor", "laser", "-o", "mixed"});
  ASSERT_EQ(laser.status, 0) << laser.err;
  EXPECT_THAT(laser.out, HasSubstr(": 1 beams"));

  testing::WriteAll(Work("unusable.json"),
                    R"({"format":"priormap.log","version":1,"records":[)"
                    R"({"type":"scan","pose":[0,0,0],"angles":[0,1],"ranges":[null,-1]}]})");
  EXPECT_THAT(RunFailing({"grid", "--log", "unusable.json", "-o", "u"}).err,
              HasSubstr("no usable reading"));
  EXPECT_THAT(RunFailing({"grid", "--log", "room.log", "--resolution", "0.0005", "-o", "huge"}).err,
              HasSubstr("more than 1e+08"));
  EXPECT_FALSE(std::filesystem::exists(Work("u")));
  EXPECT_FALSE(std::filesystem::exists(Work("huge")));
  testing::WriteAll(Work("afile"), "");
  EXPECT_THAT(RunFailing({"grid", "--log", "room.log", "-o", "afile"}).err,
              HasSubstr("afile is a file, not a directory"));
}

TEST_F(MappingCli, ReportsBadSelections) {
  EXPECT_THAT(RunFailing({"prf", "--log", "room.log", "--range", "5:2", "-o", "x"}).err,
              HasSubstr("--range: '5:2' is empty"));
  EXPECT_THAT(RunFailing({"prf", "--log", "room.log", "--range", "9000:", "-o", "x"}).err,
              HasSubstr("selects no scan"));
  EXPECT_THAT(RunFailing({"grid", "--log", "room.log", "--range", "0:9000", "-o", "x"}).err,
              HasSubstr("--range 0:9000: the log has only"));
  EXPECT_FALSE(std::filesystem::exists(Work("x")));
  EXPECT_THAT(RunFailing({"prf", "--range", "0:2", "-o", "x"}).err, HasSubstr("--log is required"));
  EXPECT_THAT(RunFailing({"grid", "--log", "missing.log", "-o", "x"}).err,
              HasSubstr("missing.log"));
  EXPECT_THAT(RunFailing({"grid", "--log", "room.log", "--range", "a:b", "-o", "x"}).err,
              HasSubstr("--range"));
}

// A signal stops the chains gracefully, checkpointed, with the shell's status for the signal
// (128 + its number), so that a scheduler sees which one ended the run.
TEST_F(MappingCli, ASignalStopsTheChainsWithItsExitStatus) {
  for (const int signal : {SIGTERM, SIGINT}) {
    const std::string out = fmt::format("run-{}", signal);
    const testing::SignalledRun r = testing::RunAndSignalOnceCheckpointed(
        Work("."),
        {"prf", "--log", "room.log", "--beam-step", "4", "--samples", "100000000", "--burn-in",
         "1000", "--chains", "1", "--checkpoint-every", "0.01", "-o", out},
        Work(out) / "checkpoints", signal);
    ASSERT_TRUE(WIFEXITED(r.wait_status))
        << "ended by signal " << (WIFSIGNALED(r.wait_status) ? WTERMSIG(r.wait_status) : 0)
        << "; stderr:\n"
        << r.err;
    EXPECT_EQ(WEXITSTATUS(r.wait_status), 128 + signal) << r.err;
    EXPECT_THAT(r.out, HasSubstr("stopped and checkpointed"));
    for (const std::string& file : testing::FilesUnder(Work(out)))
      EXPECT_THAT(file, Not(HasSubstr(".tmp-")));
  }
}

// A signal delivered twice within a second (a terminal's Ctrl-C and a wrapper that forwards it)
// is one request: the run still stops checkpointed, with the signal's status.
TEST_F(MappingCli, ASignalDeliveredTwiceStillStopsTheChainsCheckpointed) {
  const testing::SignalledRun r = testing::RunAndSignalOnceCheckpointed(
      Work("."),
      {"prf", "--log", "room.log", "--beam-step", "4", "--samples", "100000000", "--burn-in",
       "1000", "--chains", "1", "--checkpoint-every", "0.01", "-o", "run"},
      Work("run") / "checkpoints", SIGTERM, 2);
  ASSERT_TRUE(WIFEXITED(r.wait_status))
      << "ended by signal " << (WIFSIGNALED(r.wait_status) ? WTERMSIG(r.wait_status) : 0);
  EXPECT_EQ(WEXITSTATUS(r.wait_status), 128 + SIGTERM) << r.err;
  EXPECT_THAT(r.out, HasSubstr("stopped and checkpointed"));
  EXPECT_TRUE(Run({"prf", "--resume", "run", "--stop-after-steps", "1000"}).status == 0);
}

// A second signal a second or more after the first is a user who insists: it ends the process at
// once, by that signal, without waiting for the chains' chunk, checkpointing or writing outputs.
// The checkpoint written before it is left whole, and the run resumes from it.
TEST_F(MappingCli, ASecondSignalASecondOrMoreLaterEndsTheRunAtOnce) {
  using namespace std::chrono_literals;
  // --check recomputes the likelihood after every accepted move: the burn-in's 20 steps (a chunk,
  // checkpointed after it) take a fraction of a second, the next chunk's 20000 steps tens of
  // seconds. The first signal comes 1 s after that checkpoint appears, which leaves the run the
  // time to sync the checkpoint's directory and begin the long chunk (a signal before would stop
  // it there, checkpointed); the second 2 s later (the second within which a signal is the first
  // delivered twice, with a margin), the run still in that chunk.
  const std::filesystem::path checkpoint = Work("run") / "checkpoints" / "chain-0.ckpt";
  std::string checkpointed;
  std::optional<std::chrono::steady_clock::time_point> checkpointed_at;
  const testing::SignalledRun r = testing::RunAndSignalWhen(
      Work("."),
      {"prf", "--log", "room.log", "--beam-step", "2", "--samples", "100000000", "--burn-in", "20",
       "--chains", "1", "--check", "--trace-every", "100000000", "--checkpoint-every", "0.000001",
       "-o", "run"},
      [&] {
        std::error_code ec;
        if (!checkpointed_at && std::filesystem::exists(checkpoint, ec)) {
          checkpointed = testing::ReadAll(checkpoint);
          checkpointed_at = std::chrono::steady_clock::now();
        }
        return checkpointed_at && std::chrono::steady_clock::now() - *checkpointed_at >= 1s;
      },
      "no checkpoint after 30 s", {.signal = SIGINT, .times = 2, .apart = 2s});
  ASSERT_EQ(r.signals_while_running, 2)
      << "the run ended before the second signal: " << testing::HowItEnded(r.wait_status)
      << "; stdout:\n"
      << r.out << "stderr:\n"
      << r.err;
  ASSERT_TRUE(WIFSIGNALED(r.wait_status)) << testing::HowItEnded(r.wait_status) << "; stderr:\n"
                                          << r.err;
  EXPECT_EQ(WTERMSIG(r.wait_status), SIGINT);
  EXPECT_EQ(r.out, "");  // not "stopped and checkpointed": it did not wait for the chunk's end
  // Neither outputs nor temporary files; the checkpoint as it was before the signals.
  EXPECT_EQ(testing::FilesUnder(Work("run")),
            (std::set<std::string>{"checkpoints", "checkpoints/chain-0.ckpt", "run.json"}));
  EXPECT_EQ(testing::ReadAll(checkpoint), checkpointed);
  const auto resumed = Run({"prf", "--resume", "run", "--stop-after-steps", "20"});
  EXPECT_EQ(resumed.status, 0) << resumed.err;
  EXPECT_THAT(resumed.err, HasSubstr("resumed 20 steps from"));
}

}  // namespace
}  // namespace priormap
