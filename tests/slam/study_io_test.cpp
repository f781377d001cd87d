// The outputs of a prior-map SLAM study and of one run: the documented columns and keys, one row
// per frame or relation, numbers that read back exactly, NaN as an empty cell or null, and
// atomic files in the documented places.
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <priormap/core/check.hpp>
#include <priormap/slam/study_io.hpp>

#include "testing/temp_dir.hpp"

namespace priormap::slam {
namespace {

namespace fs = std::filesystem;
using priormap::testing::FilesIn;
using priormap::testing::HasTemporaryFile;
using priormap::testing::ReadAll;
using priormap::testing::TempDir;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::Not;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// Cells of one CSV line (no quoting in these files); a trailing empty cell is kept.
std::vector<std::string> Cells(const std::string& line) {
  std::vector<std::string> cells;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    cells.push_back(line.substr(start, comma - start));
    if (comma == std::string::npos) return cells;
    start = comma + 1;
  }
}

// A run of three frames; the first has a singular covariance (NaN NEES).
RunTrace MakeTrace(double offset) {
  SlamResult result;
  for (int f = 0; f < 3; ++f) {
    FrameRecord frame;
    frame.time = 0.1 * f;  // 0.1 * 2 is not 0.2 exactly: the text must still read back
    frame.estimate = Se2(offset + f, -1.0 / 3.0, 0.25 * f);
    frame.covariance = Mat3::Identity() * 0.01 * f;  // zero at f = 0
    frame.covariance(0, 1) = frame.covariance(1, 0) = 1e-5 * f;
    frame.landmarks = 4 + f;
    frame.segments = f;
    frame.relations_in_state = 2 * f;
    frame.relations_correct = f;
    frame.relations_incorrect = f / 2;
    frame.relations_spurious = f / 2;
    frame.accepted = 1;
    result.frames.push_back(frame);
  }
  result.relations = {{.landmark = 3, .segment = 7, .time = 0.1, .correct = true, .walls = {}},
                      {.landmark = 5,
                       .segment = 2,
                       .time = 0.2,
                       .flagged = true,
                       .flagged_time = 0.3,
                       .correct = false,
                       .spurious_segment = true,
                       .building = -1,
                       .walls = {}},
                      {.landmark = 3,
                       .segment = 4,
                       .time = 0.3,
                       .flagged = false,
                       .flagged_time = 0.0,
                       .correct = true,
                       .spurious_segment = false,
                       .building = 1,
                       .walls = {4, 5}}};
  result.building_relations = 1;
  result.landmarks = {{.id = 3, .position = Vec2(1.0, 2.0), .covariance = Mat2::Identity()},
                      {.id = 5, .position = Vec2(-1.0, 0.5), .covariance = 2 * Mat2::Identity()}};
  // Landmark 4 was dropped by the window after the first frame.
  result.all_landmarks = {
      {.estimate = result.landmarks[0], .last_time = 0.2, .in_state = true},
      {.estimate = {.id = 4, .position = Vec2(7.0, 8.0), .covariance = 3 * Mat2::Identity()},
       .last_time = 0.0,
       .in_state = false},
      {.estimate = result.landmarks[1], .last_time = 0.2, .in_state = true}};
  result.segments = {
      {.segment = 7, .a = Vec2(0, 0), .b = Vec2(4, 0), .covariance = Mat4::Identity()}};
  result.landmarks_created = 9;
  RunTrace trace;
  for (int f = 0; f < 3; ++f) {
    trace.error.emplace_back(0.1 * f, -0.2 * f, 0.01 * f);
    trace.sigma.emplace_back(0.1, 0.2, 0.03);
    trace.nees.push_back(f == 0 ? kNaN : 1.5 * f);
  }
  trace.result = std::move(result);
  return trace;
}

StudyResult MakeStudy() {
  StudyResult study;
  study.times = {0.0, 0.1, 0.2};
  study.with_prior = {MakeTrace(0.0), MakeTrace(1.0)};
  study.without_prior = {MakeTrace(2.0), MakeTrace(3.0)};
  study.with_prior_summary.rms_position_m = 0.5;
  study.without_prior_summary.rms_position_m = 2.0;
  study.with_prior_summary.inside_3sigma = Vec3(0.75, 0.5, 1.0);
  study.with_prior_summary.inside_3sigma_fraction = 0.5;
  study.relations = {.correct = 8, .incorrect = 2, .from_spurious = 1, .flagged = 1};
  study.nees_band_low = 1.5;
  study.nees_band_high = 4.5;
  study.path_length_m = 1400.0;
  study.duration_s = 100.0;
  study.beacons = 480;
  study.prior_segments = 396;
  study.wall_time_s = 1.25;
  return study;
}

TEST(StudyIo, RunTraceCsvHasOneRowPerFrameThatReadsBack) {
  const RunTrace trace = MakeTrace(0.0);
  const std::vector<std::string> lines = Lines(RunTraceCsv(trace));
  ASSERT_EQ(lines.size(), 4u);
  EXPECT_EQ(lines[0],
            "time,x,y,theta,error_x,error_y,error_theta,sigma_x,sigma_y,sigma_theta,nees,"
            "landmarks,segments,relations_in_state,relations_correct,relations_incorrect,"
            "relations_spurious,accepted");
  for (std::size_t f = 0; f < 3; ++f) {
    const std::vector<std::string> cells = Cells(lines[f + 1]);
    ASSERT_EQ(cells.size(), 18u) << lines[f + 1];
    const FrameRecord& frame = trace.result.frames[f];
    EXPECT_EQ(std::stod(cells[0]), frame.time);
    EXPECT_EQ(std::stod(cells[2]), frame.estimate.y());
    EXPECT_EQ(std::stod(cells[5]), trace.error[f].y());
    EXPECT_EQ(std::stod(cells[9]), trace.sigma[f].z());
    if (f == 0) {
      EXPECT_EQ(cells[10], "");  // NaN NEES: an empty cell
    } else {
      EXPECT_EQ(std::stod(cells[10]), trace.nees[f]);
    }
    EXPECT_EQ(cells[11], std::to_string(frame.landmarks));
    EXPECT_EQ(cells[13], std::to_string(frame.relations_in_state));
    EXPECT_EQ(cells[17], "1");
  }
}

TEST(StudyIo, RunTraceCsvRejectsATraceWithoutAnEntryPerFrame) {
  RunTrace trace = MakeTrace(0.0);
  trace.nees.pop_back();
  EXPECT_THROW((void)RunTraceCsv(trace), ContractError);
}

TEST(StudyIo, SummaryJsonHasTheDocumentedKeysAndRatios) {
  StudyOptions options;
  options.runs = 2;
  options.seed = 17;
  const std::string json = StudySummaryJson(MakeStudy(), options);
  for (const char* key : {"\"format\": \"priormap.slam_study\"",
                          "\"version\": 1",
                          "\"runs\": 2",
                          "\"seed\": 17",
                          "\"with_prior\": {",
                          "\"without_prior\": {",
                          "\"rms_position_m\": 0.5",
                          "\"rms_heading_rad\"",
                          "\"inside_3sigma_fraction\": 0.5",
                          "\"inside_3sigma\": {",
                          "\"theta\": 1.0",
                          "\"mean_nees\"",
                          "\"nees_inside_band_fraction\"",
                          "\"mean_landmarks\"",
                          "\"constraints\": {",
                          "\"correct\": 8",
                          "\"incorrect\": 2",
                          "\"from_spurious\": 1",
                          "\"flagged\": 1",
                          "\"wall_time_s\": 1.25",
                          "\"nees_band\": [",
                          "\"path_length_m\": 1400.0",
                          "\"duration_s\": 100.0",
                          "\"beacons\": 480",
                          "\"prior_segments\": 396",
                          "\"rms_position_ratio\": 4.0",
                          "\"incorrect_per_correct\": 0.25"}) {
    EXPECT_THAT(json, HasSubstr(key));
  }
  EXPECT_TRUE(json.ends_with("}\n"));
}

TEST(StudyIo, SummaryJsonWritesUndefinedRatiosAsNull) {
  StudyResult study = MakeStudy();
  study.relations = {};
  study.with_prior_summary.rms_position_m = 0.0;
  const std::string json = StudySummaryJson(study, {});
  EXPECT_THAT(json, HasSubstr("\"rms_position_ratio\": null"));
  EXPECT_THAT(json, HasSubstr("\"incorrect_per_correct\": null"));
}

TEST(StudyIo, RelationsCsvListsTheRunsWithThePriorMap) {
  const std::vector<std::string> lines = Lines(StudyRelationsCsv(MakeStudy()));
  EXPECT_THAT(lines, ElementsAre("run,landmark,segment,time,correct,spurious_segment,flagged,"
                                 "flagged_time,building,walls,buildings",
                                 "0,3,7,0.1,1,0,0,,,,", "0,5,2,0.2,0,1,1,0.3,,,",
                                 "0,3,4,0.3,1,0,0,,1,4;5,1", "1,3,7,0.1,1,0,0,,,,",
                                 "1,5,2,0.2,0,1,1,0.3,,,", "1,3,4,0.3,1,0,0,,1,4;5,1"));
}

TEST(StudyIo, RunFileNamesSortInRunOrder) {
  EXPECT_EQ(RunFileName(true, 7, 30), "with_prior_run_07.csv");
  EXPECT_EQ(RunFileName(false, 0, 1), "without_prior_run_00.csv");
  EXPECT_EQ(RunFileName(true, 99, 100), "with_prior_run_99.csv");
  EXPECT_EQ(RunFileName(true, 5, 101), "with_prior_run_005.csv");
}

TEST(StudyIo, WriteStudyOutputsWritesEveryFileAtomically) {
  const TempDir dir;
  const fs::path out = dir / "study";
  const std::vector<fs::path> written = WriteStudyOutputs(MakeStudy(), {}, out);
  ASSERT_EQ(written.size(), 6u);
  EXPECT_EQ(written.front(), out / "summary.json");
  EXPECT_THAT(FilesIn(out), ElementsAre("relations.csv", "runs", "summary.json"));
  EXPECT_THAT(FilesIn(out / "runs"),
              ElementsAre("with_prior_run_00.csv", "with_prior_run_01.csv",
                          "without_prior_run_00.csv", "without_prior_run_01.csv"));
  EXPECT_FALSE(HasTemporaryFile(out));
  EXPECT_FALSE(HasTemporaryFile(out / "runs"));
  EXPECT_EQ(ReadAll(out / "runs" / "without_prior_run_01.csv"),
            RunTraceCsv(MakeStudy().without_prior[1]));
}

// --- one run ---------------------------------------------------------------------------------

TEST(SlamRunIo, TrajectoryCsvHasThePoseAndTheCovariancesUniqueEntries) {
  const SlamResult result = MakeTrace(0.0).result;
  const std::vector<std::string> lines = Lines(TrajectoryCsv(result));
  ASSERT_EQ(lines.size(), 4u);
  EXPECT_EQ(lines[0], "time,x,y,theta,cov_xx,cov_xy,cov_xtheta,cov_yy,cov_ytheta,cov_thetatheta");
  const std::vector<std::string> cells = Cells(lines[3]);
  ASSERT_EQ(cells.size(), 10u);
  const FrameRecord& frame = result.frames[2];
  EXPECT_EQ(std::stod(cells[0]), frame.time);
  EXPECT_EQ(std::stod(cells[1]), frame.estimate.x());
  EXPECT_EQ(std::stod(cells[3]), frame.estimate.theta());
  EXPECT_EQ(std::stod(cells[4]), frame.covariance(0, 0));
  EXPECT_EQ(std::stod(cells[5]), frame.covariance(0, 1));
  EXPECT_EQ(std::stod(cells[9]), frame.covariance(2, 2));
}

TEST(SlamRunIo, MapGeoJsonHasAPointPerLandmarkEverMappedAndALinePerSegment) {
  const std::string json = SlamMapGeoJson(MakeTrace(0.0).result);
  EXPECT_THAT(json, HasSubstr("\"type\": \"FeatureCollection\""));
  const auto count = [&](const std::string& what) {
    std::size_t n = 0;
    for (std::size_t at = json.find(what); at != std::string::npos; at = json.find(what, at + 1))
      ++n;
    return n;
  };
  EXPECT_EQ(count("\"type\":\"Point\""), 3u);
  EXPECT_EQ(count("\"type\":\"LineString\""), 1u);
  EXPECT_THAT(json, HasSubstr("\"kind\":\"landmark\",\"id\":3,\"covariance\":[1.0,0.0,1.0],"
                              "\"segments\":[7,4,5],\"in_state\":true,\"last_time\":0.2"));
  EXPECT_THAT(json, HasSubstr("\"coordinates\":[7.0,8.0]},\"properties\":{\"kind\":\"landmark\","
                              "\"id\":4,\"covariance\":[3.0,0.0,3.0],\"segments\":[],"
                              "\"in_state\":false,\"last_time\":0.0"));
  EXPECT_THAT(json, HasSubstr("\"kind\":\"segment\",\"segment\":7"));
}

TEST(SlamRunIo, RelationsCsvLeavesTheTruthEmptyWhenUnknown) {
  SlamResult result = MakeTrace(0.0).result;
  result.relations[0].correct.reset();
  EXPECT_THAT(Lines(SlamRelationsCsv(result)),
              ElementsAre("landmark,segment,time,flagged,flagged_time,correct,spurious_segment,"
                          "building,walls,buildings",
                          "3,7,0.1,0,,,,,,", "5,2,0.2,1,0.3,0,1,,,", "3,4,0.3,0,,1,0,1,4;5,1"));
}

// A relation to buildings that tie with the same walls names each of them in the last column, as
// it names its walls. `building` stays the first, a number: it was "1;3" on a tie, so a reader
// (pandas) took the column for numbers or for text depending on whether the run had a tie.
TEST(SlamRunIo, RelationsCsvNamesEveryBuildingOfATie) {
  SlamResult result = MakeTrace(0.0).result;
  result.relations[2].buildings = {1, 3};
  EXPECT_THAT(Lines(SlamRelationsCsv(result)).back(), "3,4,0.3,0,,1,0,1,4;5,1;3");
  StudyResult study = MakeStudy();
  study.with_prior[1].result.relations[2].buildings = {1, 3};
  EXPECT_THAT(Lines(StudyRelationsCsv(study)).back(), "1,3,4,0.3,1,0,0,,1,4;5,1;3");
}

TEST(SlamRunIo, WriteSlamRunOutputsCreatesTheDirectory) {
  const TempDir dir;
  const fs::path out = dir / "a" / "b";
  SlamRunInfo info;
  info.observations = "obs.csv";
  info.wall_time_s = 0.5;
  const std::vector<fs::path> written = WriteSlamRunOutputs(MakeTrace(0.0).result, info, out);
  EXPECT_EQ(written.size(), 4u);
  EXPECT_THAT(FilesIn(out),
              ElementsAre("map.geojson", "relations.csv", "summary.json", "trajectory.csv"));
  const std::string summary = ReadAll(out / "summary.json");
  for (const char* key :
       {"\"format\": \"priormap.slam_run\"", "\"frames\": 3", "\"landmarks_created\": 9",
        "\"applied\": 3", "\"to_buildings\": 1", "\"flagged\": 1", "\"rejected_updates\": 0",
        "\"wall_time_s\": 0.5", "\"hypotheses\"", "\"observations\": \"obs.csv\""}) {
    EXPECT_THAT(summary, HasSubstr(key));
  }
  EXPECT_THAT(summary, Not(HasSubstr("NaN")));
}

// A real (one-run) study: one table row per frame of the study.
TEST(StudyIo, TablesOfARealStudyHaveOneRowPerFrame) {
  StudyOptions options;
  options.runs = 1;
  options.seed = 5;
  const StudyResult study = RunStudy(options);
  ASSERT_FALSE(study.times.empty());
  EXPECT_EQ(Lines(RunTraceCsv(study.with_prior[0])).size(), study.times.size() + 1);
  EXPECT_EQ(Lines(RunTraceCsv(study.without_prior[0])).size(), study.times.size() + 1);
  EXPECT_EQ(Lines(StudyRelationsCsv(study)).size(),
            study.with_prior[0].result.relations.size() + 1);
  EXPECT_EQ(Lines(TrajectoryCsv(study.with_prior[0].result)).size(), study.times.size() + 1);
}

}  // namespace
}  // namespace priormap::slam
