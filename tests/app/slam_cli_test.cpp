// End-to-end tests of `priormap slam`: the study's outputs and figures, its exported inputs
// filtered again by `slam run`, errors in the user's files reported at file:line:col, and
// reproducibility for a seed.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_fixture.hpp"
#include "testing/temp_dir.hpp"

namespace priormap {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using priormap::testing::ReadAll;
using priormap::testing::TempDir;
using priormap::testing::WriteAll;
using ::testing::ContainsRegex;
using ::testing::HasSubstr;
using ::testing::Not;

using RunResult = priormap::testing::ProcessResult;

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

using priormap::testing::IsPng;

class SlamCli : public priormap::testing::CliFixture {
 protected:
  /// Success; stderr holds at most the progress bar.
  RunResult Ok(const std::vector<std::string>& args) const {
    RunResult r = Run(args);
    EXPECT_EQ(r.status, 0) << "stdout:\n" << r.out << "stderr:\n" << r.err;
    EXPECT_THAT(r.err, Not(HasSubstr("error")));
    return r;
  }

  /// Exit status 1 with an error on stderr, and nothing written.
  RunResult Fails(const std::vector<std::string>& args) const {
    RunResult r = RunFailing(args);
    EXPECT_EQ(r.status, 1) << "stdout:\n" << r.out << "stderr:\n" << r.err;
    return r;
  }

  [[nodiscard]] json ReadJson(const std::string& name) const {
    return json::parse(ReadAll(Work(name)));
  }

  // Small valid inputs of `slam run`: a car driving along x past a wall at y = 5 with two
  // landmarks on it.
  void WriteSmallInputs() const {
    WriteAll(Work("odometry.csv"), "time,speed,steer\n0,2,0\n1,2,0\n2,2,0\n");
    WriteAll(Work("observations.csv"),
             "time,id,range,bearing\n"
             "0.5,0,5.385164807134504,1.1902899496825317\n"
             "0.5,1,7.0710678118654755,0.7853981633974483\n"
             "1.5,0,5.0,1.5707963267948966\n"
             "1.5,1,5.385164807134504,1.1902899496825317\n");
    WriteAll(Work("map.geojson"),
             R"({"type": "FeatureCollection", "features": [
  {"type": "Feature", "properties": {"name": "wall"},
   "geometry": {"type": "LineString", "coordinates": [[-5, 5], [20, 5]]}}
]}
)");
  }

  [[nodiscard]] std::vector<std::string> RunArgs(const std::string& observations,
                                                 const std::string& odometry,
                                                 const std::string& map) const {
    return {"slam",       "run",    "--observations", observations,
            "--odometry", odometry, "--prior-map",    map,
            "-o",         "out"};
  }
};

void ExpectFraction(const json& value, const std::string& what) {
  ASSERT_TRUE(value.is_number()) << what;
  EXPECT_GE(value.get<double>(), 0.0) << what;
  EXPECT_LE(value.get<double>(), 1.0) << what;
}

void ExpectVariant(const json& v, const std::string& name) {
  SCOPED_TRACE(name);
  for (const char* key : {"rms_position_m", "rms_heading_rad", "mean_nees", "mean_landmarks"}) {
    ASSERT_TRUE(v.contains(key)) << key;
    ASSERT_TRUE(v[key].is_number()) << key;
    EXPECT_GT(v[key].get<double>(), 0.0) << key;
  }
  EXPECT_LT(v["rms_position_m"].get<double>(), 100.0);
  EXPECT_LT(v["rms_heading_rad"].get<double>(), 1.0);
  ExpectFraction(v["inside_3sigma_fraction"], "inside_3sigma_fraction");
  ExpectFraction(v["nees_inside_band_fraction"], "nees_inside_band_fraction");
  for (const char* axis : {"x", "y", "theta"}) {
    ExpectFraction(v["inside_3sigma"][axis], axis);
    EXPECT_GE(v["inside_3sigma"][axis].get<double>(), v["inside_3sigma_fraction"].get<double>());
  }
}

// A study written over an earlier one leaves none of the earlier one's run tables or figures.
TEST_F(SlamCli, SimulateOverAnEarlierStudyLeavesNoneOfItsOutputs) {
  Ok({"slam", "simulate", "--runs", "3", "--seed", "1", "-o", "study"});
  ASSERT_TRUE(fs::exists(Work("study/runs/with_prior_run_02.csv")));
  ASSERT_TRUE(fs::exists(Work("study/figures/map.png")));
  WriteAll(Work("study/runs/notes.txt"), "mine");
  Ok({"slam", "simulate", "--runs", "1", "--seed", "1", "--no-figures", "-o", "study"});
  std::set<std::string> tables;
  for (const auto& entry : fs::directory_iterator(Work("study/runs")))
    tables.insert(entry.path().filename().string());
  EXPECT_EQ(tables, (std::set<std::string>{"with_prior_run_00.csv", "without_prior_run_00.csv",
                                           "notes.txt"}));
  EXPECT_FALSE(fs::exists(Work("study/figures")));
}

// The exported README's command filters with the study's options where they are not the
// defaults, so that it gives the study's run 0.
TEST_F(SlamCli, TheExportedCommandCarriesTheStudysFilterOptions) {
  Ok({"slam", "simulate", "--runs", "1", "--no-figures", "-o", "a", "--export-inputs", "plain"});
  EXPECT_THAT(ReadAll(Work("plain/README.txt")),
              HasSubstr("--bearing-std 1.15 \\\n    -o slam_out"));
  Ok({"slam", "simulate", "--runs", "1", "--no-figures", "-o", "b", "--window", "2", "--p-accept",
      "0.9", "--building-relations", "--first-order-ekf", "--export-inputs", "tuned"});
  EXPECT_THAT(ReadAll(Work("tuned/README.txt")),
              HasSubstr("    --window 2 --p-accept 0.9 --building-relations --first-order-ekf -o "
                        "slam_out\n"));
}

TEST_F(SlamCli, SimulateWritesTheStudyAndRunFiltersItsExportedInputs) {
  const RunResult r = Ok(
      {"slam", "simulate", "--runs", "2", "--seed", "3", "-o", "study", "--export-inputs", "in"});
  EXPECT_THAT(r.out, HasSubstr("RMS position (m)"));
  EXPECT_THAT(r.out, HasSubstr("constraints:"));
  EXPECT_THAT(r.out, HasSubstr("wrote study"));

  const json summary = ReadJson("study/summary.json");
  EXPECT_EQ(summary["format"], "priormap.slam_study");
  EXPECT_EQ(summary["version"], 1);
  EXPECT_EQ(summary["runs"], 2);
  EXPECT_EQ(summary["seed"], 3);
  ExpectVariant(summary["with_prior"], "with_prior");
  ExpectVariant(summary["without_prior"], "without_prior");
  const json& constraints = summary["constraints"];
  for (const char* key : {"correct", "incorrect", "from_spurious", "flagged"})
    EXPECT_TRUE(constraints[key].is_number_unsigned()) << key;
  EXPECT_LE(constraints["from_spurious"].get<int>(), constraints["incorrect"].get<int>());
  EXPECT_GT(summary["wall_time_s"].get<double>(), 0.0);
  ASSERT_EQ(summary["nees_band"].size(), 2u);
  EXPECT_LT(summary["nees_band"][0].get<double>(), summary["nees_band"][1].get<double>());
  EXPECT_GT(summary["path_length_m"].get<double>(), 1000.0);
  EXPECT_GT(summary["duration_s"].get<double>(), 0.0);
  EXPECT_GT(summary["beacons"].get<int>(), 0);
  EXPECT_GT(summary["prior_segments"].get<int>(), 0);
  EXPECT_TRUE(summary["rms_position_ratio"].is_number());
  EXPECT_TRUE(summary["incorrect_per_correct"].is_number() ||
              summary["incorrect_per_correct"].is_null());

  // Per-run tables: a header and one row per frame.
  const auto frames = summary["frames"].get<std::size_t>();
  ASSERT_GT(frames, 100u);
  for (const char* name : {"with_prior_run_00.csv", "with_prior_run_01.csv",
                           "without_prior_run_00.csv", "without_prior_run_01.csv"}) {
    const std::vector<std::string> lines = Lines(ReadAll(Work("study/runs/" + std::string(name))));
    ASSERT_EQ(lines.size(), frames + 1) << name;
    EXPECT_TRUE(lines[0].starts_with("time,x,y,theta,error_x,error_y,error_theta,sigma_x"));
  }
  EXPECT_TRUE(ReadAll(Work("study/relations.csv"))
                  .starts_with("run,landmark,segment,time,correct,spurious_segment,flagged,"
                               "flagged_time,building,walls,buildings\n"));
  for (const char* figure : {"pose_error", "nees", "relations", "map"}) {
    EXPECT_TRUE(IsPng(ReadAll(Work("study/figures/" + std::string(figure) + ".png")))) << figure;
    EXPECT_THAT(ReadAll(Work("study/figures/" + std::string(figure) + ".svg")), HasSubstr("<svg"))
        << figure;
  }

  // Run 0 filtered again from the exported files, from its true start pose.
  for (const char* name : {"observations.csv", "odometry.csv", "prior_map.geojson", "truth.csv"})
    EXPECT_TRUE(fs::exists(Work("in/" + std::string(name)))) << name;
  const std::vector<std::string> truth = Lines(ReadAll(Work("in/truth.csv")));
  ASSERT_GT(truth.size(), 1u);
  const std::string start = truth[1].substr(truth[1].find(',') + 1);  // x,y,theta
  std::set<std::string> times;
  for (const std::string& line : Lines(ReadAll(Work("in/observations.csv"))))
    times.insert(line.substr(0, line.find(',')));
  times.erase("time");
  const RunResult run =
      Ok({"slam", "run", "--observations", "in/observations.csv", "--odometry", "in/odometry.csv",
          "--prior-map", "in/prior_map.geojson", "--initial-pose=" + start, "-o", "run"});
  EXPECT_EQ(run.err, "");
  EXPECT_THAT(run.out, HasSubstr("wrote run"));
  const std::vector<std::string> trajectory = Lines(ReadAll(Work("run/trajectory.csv")));
  EXPECT_EQ(trajectory.size(), times.size() + 1);
  const json run_summary = ReadJson("run/summary.json");
  EXPECT_EQ(run_summary["format"], "priormap.slam_run");
  EXPECT_EQ(run_summary["frames"].get<std::size_t>(), times.size());
  EXPECT_GT(run_summary["landmarks_created"].get<int>(), 0);
  EXPECT_EQ(ReadJson("run/map.geojson")["type"], "FeatureCollection");
  EXPECT_TRUE(IsPng(ReadAll(Work("run/map.png"))));
  // Again without figures, into the same directory: the first run's figure goes.
  Ok({"slam", "run", "--observations", "in/observations.csv", "--odometry", "in/odometry.csv",
      "--prior-map", "in/prior_map.geojson", "--initial-pose=" + start, "--no-figures", "-o",
      "run"});
  EXPECT_FALSE(fs::exists(Work("run/map.png")));
  EXPECT_FALSE(fs::exists(Work("run/map.svg")));
}

TEST_F(SlamCli, TheSameSeedGivesTheSameNumbersWithAnyNumberOfThreads) {
  Ok({"slam", "simulate", "--runs", "2", "--seed", "3", "--no-figures", "--threads", "1", "-o",
      "a"});
  Ok({"slam", "simulate", "--runs", "2", "--seed", "3", "--no-figures", "-o", "b"});
  json a = ReadJson("a/summary.json"), b = ReadJson("b/summary.json");
  a.erase("wall_time_s");
  b.erase("wall_time_s");
  EXPECT_EQ(a, b);
  EXPECT_EQ(ReadAll(Work("a/runs/with_prior_run_01.csv")),
            ReadAll(Work("b/runs/with_prior_run_01.csv")));
  EXPECT_EQ(ReadAll(Work("a/relations.csv")), ReadAll(Work("b/relations.csv")));
  EXPECT_FALSE(fs::exists(Work("a/figures")));
}

// --first-order-ekf is the textbook filter, overconfident on the same data; the algorithm's
// options reach the filter (a different p_accept changes the relations).
TEST_F(SlamCli, AlgorithmOptionsReachTheFilter) {
  Ok({"slam", "simulate", "--runs", "2", "--seed", "1", "--no-figures", "-o", "default"});
  Ok({"slam", "simulate", "--runs", "2", "--seed", "1", "--no-figures", "--first-order-ekf", "-o",
      "textbook"});
  Ok({"slam", "simulate", "--runs", "2", "--seed", "1", "--no-figures", "--p-accept", "0.7",
      "--null-density", "1", "-o", "papers"});
  Ok({"slam", "simulate", "--runs", "2", "--seed", "1", "--no-figures", "--building-relations",
      "-o", "buildings"});
  const json consistent = ReadJson("default/summary.json");
  const json textbook = ReadJson("textbook/summary.json");
  const json papers = ReadJson("papers/summary.json");
  EXPECT_GT(textbook["without_prior"]["mean_nees"].get<double>(),
            5.0 * consistent["without_prior"]["mean_nees"].get<double>());
  EXPECT_NE(papers["constraints"]["correct"], consistent["constraints"]["correct"]);
  EXPECT_EQ(papers["without_prior"], consistent["without_prior"]);
  // Relations to buildings show in the relations table (a building index, its walls).
  const auto building_rows = [&](const char* dir) {
    int rows = 0;
    for (const std::string& line : Lines(ReadAll(Work(dir) / "relations.csv"))) {
      // A row with buildings (and walls); the header ends in "buildings".
      if (!line.ends_with(",")) ++rows;
    }
    return rows - 1;
  };
  EXPECT_EQ(building_rows("default"), 0);
  EXPECT_GT(building_rows("buildings"), 0);
}

// At p = 1 (or 0) the association prior is NaN, so the prior map was silently never used; at 1
// with --building-relations the mixture weights were infinite. A std beyond the world's bound
// squares to infinity in the filter.
TEST_F(SlamCli, PriorsThatGiveNonFiniteProbabilitiesAreRefused) {
  WriteSmallInputs();
  // Refused as an option (CLI11's exit status), before any file is read.
  const auto refused = [&](const std::vector<std::string>& args) {
    const RunResult r = RunFailing(args);
    EXPECT_NE(r.status, 0);
    return r.err;
  };
  for (const char* p : {"1", "0", "1.5"}) {
    std::vector<std::string> args = RunArgs("observations.csv", "odometry.csv", "map.geojson");
    args.insert(args.end(), {"--building-relations", "--p-point-on-line", p});
    EXPECT_THAT(refused(args), HasSubstr(std::string("--p-point-on-line: ") + p +
                                         " is not in (0, 1), 0 and 1 excluded"));
    EXPECT_THAT(refused({"slam", "simulate", "--runs", "1", "--no-figures", "--p-point-on-line", p,
                         "-o", "study"}),
                HasSubstr("--p-point-on-line"));
  }
  std::vector<std::string> args = RunArgs("observations.csv", "odometry.csv", "map.geojson");
  args.insert(args.end(), {"--prior-std", "1e200"});
  EXPECT_THAT(refused(args), HasSubstr("--prior-std: 1e200 is not in (0, 1000000000] m"));
  EXPECT_THAT(refused({"slam", "simulate", "--runs", "1", "--prior-std", "2e9", "-o", "study"}),
              HasSubstr("--prior-std: 2e9 is not in (0, 1000000000] m"));
  WriteAll(Work("huge.geojson"),
           R"({"type": "FeatureCollection", "std": 1e200, "features": [
  {"type": "Feature", "properties": {"name": "wall"},
   "geometry": {"type": "LineString", "coordinates": [[-5, 5], [20, 5]]}}
]}
)");
  EXPECT_THAT(Fails(RunArgs("observations.csv", "odometry.csv", "huge.geojson")).err,
              HasSubstr("huge.geojson:1:38: expected \"std\" of at most 1e+09 m"));
  EXPECT_FALSE(fs::exists(Work("out")));
  EXPECT_FALSE(fs::exists(Work("study")));
}

TEST_F(SlamCli, RunFiltersSmallHandWrittenInputsWithAndWithoutThePriorMap) {
  WriteSmallInputs();
  Ok(RunArgs("observations.csv", "odometry.csv", "map.geojson"));
  EXPECT_EQ(Lines(ReadAll(Work("out/trajectory.csv"))).size(), 3u);
  std::vector<std::string> args = RunArgs("observations.csv", "odometry.csv", "map.geojson");
  args.back() = "plain";
  args.push_back("--no-prior");
  Ok(args);
  EXPECT_EQ(ReadJson("plain/summary.json")["use_prior_map"], false);
  EXPECT_EQ(ReadJson("plain/summary.json")["relations"]["applied"], 0);
}

TEST_F(SlamCli, MalformedGeoJsonIsReportedAtItsLineAndColumn) {
  WriteSmallInputs();
  WriteAll(Work("bad.geojson"), "{\"type\": \"FeatureCollection\",\n \"features\": [\n");
  const RunResult r = Fails(RunArgs("observations.csv", "odometry.csv", "bad.geojson"));
  EXPECT_THAT(r.err, ContainsRegex("priormap: error: bad\\.geojson:[0-9]+:[0-9]+: "));
}

TEST_F(SlamCli, AnEmptyPriorMapIsAnError) {
  WriteSmallInputs();
  WriteAll(Work("empty.geojson"), "{\"type\": \"FeatureCollection\", \"features\": []}\n");
  const RunResult r = Fails(RunArgs("observations.csv", "odometry.csv", "empty.geojson"));
  EXPECT_THAT(r.err, ContainsRegex("empty\\.geojson:1:[0-9]+: "));
}

TEST_F(SlamCli, NaNInTheObservationsIsReportedAtItsCell) {
  WriteSmallInputs();
  WriteAll(Work("nan.csv"), "time,id,range,bearing\n0.5,0,5,0.1\n1.5,0,nan,0.2\n");
  const RunResult r = Fails(RunArgs("nan.csv", "odometry.csv", "map.geojson"));
  EXPECT_THAT(r.err, HasSubstr("nan.csv:3:7: "));
  EXPECT_THAT(r.err, HasSubstr("NaN"));
}

TEST_F(SlamCli, InconsistentIdsAreReportedAtTheirCell) {
  WriteSmallInputs();
  WriteAll(Work("ids.csv"), "time,id,range,bearing\n0.5,0,5,0.1\n0.5,,6,0.2\n");
  const RunResult r = Fails(RunArgs("ids.csv", "odometry.csv", "map.geojson"));
  EXPECT_THAT(r.err, ContainsRegex("ids\\.csv:3:[0-9]+: "));
  WriteAll(Work("twice.csv"), "time,id,range,bearing\n0.5,0,5,0.1\n0.5,0,6,0.2\n");
  EXPECT_THAT(Fails(RunArgs("twice.csv", "odometry.csv", "map.geojson")).err,
              ContainsRegex("twice\\.csv:3:[0-9]+: "));
}

TEST_F(SlamCli, TheProblemsOfEveryFileAreReportedTogether) {
  WriteSmallInputs();
  WriteAll(Work("nan.csv"), "time,id,range,bearing\n0.5,0,nan,0.1\n");
  WriteAll(Work("odo.csv"), "time,speed,steer\n0,2,0\n");
  WriteAll(Work("bad.geojson"), "{\"type\": \"Feature\"}\n");
  const RunResult r = Fails(RunArgs("nan.csv", "odo.csv", "bad.geojson"));
  EXPECT_THAT(r.err, ContainsRegex("error: nan\\.csv:2:[0-9]+: "));
  EXPECT_THAT(r.err, ContainsRegex("error: odo\\.csv:[0-9]+:[0-9]+: "));
  EXPECT_THAT(r.err, ContainsRegex("error: bad\\.geojson:1:[0-9]+: "));
}

TEST_F(SlamCli, InputsThatDoNotFitEachOtherOrTheOptionsAreErrors) {
  WriteSmallInputs();
  // Observations after the odometry ends.
  WriteAll(Work("late.csv"), "time,id,range,bearing\n0.5,0,5,0.1\n9,0,5,0.1\n");
  EXPECT_THAT(Fails(RunArgs("late.csv", "odometry.csv", "map.geojson")).err,
              ContainsRegex("late\\.csv:3:1: observations at t = 9 s, but .* covers only"));
  // Unknown ids need nearest-neighbour association.
  WriteAll(Work("anonymous.csv"), "time,range,bearing\n0.5,5,0.1\n");
  EXPECT_THAT(Fails(RunArgs("anonymous.csv", "odometry.csv", "map.geojson")).err,
              HasSubstr("--association nearest"));
  // A malformed option and a missing one: command lines that do not parse (status 2).
  std::vector<std::string> args = RunArgs("observations.csv", "odometry.csv", "map.geojson");
  args.push_back("--initial-pose=1,2");
  const RunResult pose = RunFailing(args);
  EXPECT_EQ(pose.status, 2);
  EXPECT_THAT(pose.err, HasSubstr("--initial-pose: expected x,y,theta"));
  const RunResult no_map = RunFailing({"slam", "run", "--observations", "observations.csv",
                                       "--odometry", "odometry.csv", "-o", "out"});
  EXPECT_EQ(no_map.status, 2);
  EXPECT_THAT(no_map.err, HasSubstr("--prior-map is required"));
  EXPECT_THAT(Fails({"slam", "simulate", "--runs", "1", "-o", "missing/out"}).err,
              HasSubstr("does not exist"));
}

}  // namespace
}  // namespace priormap
