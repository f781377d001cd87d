// Resumable studies (study_session.hpp, study_cases.hpp): the progress of a study's cases, the
// cases run in parallel that stop each other when one fails, and studies stopped and resumed from
// their checkpoints that end exactly as the uninterrupted study.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <functional>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <priormap/core/binary_io.hpp>
#include <priormap/core/file_io.hpp>
#include <priormap/core/range_sensor.hpp>
#include <priormap/core/scene.hpp>
#include <priormap/prf/chain_checkpoint.hpp>
#include <priormap/prf/map_study.hpp>
#include <priormap/prf/sonar_study.hpp>
#include <priormap/prf/study_session.hpp>

#include "study_cases.hpp"
#include "testing/temp_dir.hpp"

namespace priormap::prf {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Exact equality, NaN equal to NaN (a score of nothing is NaN in both runs).
void ExpectSame(double a, double b, const std::string& what) {
  if (std::isnan(a)) {
    EXPECT_TRUE(std::isnan(b)) << what << ": NaN vs " << b;
  } else {
    EXPECT_EQ(a, b) << what;
  }
}

void ExpectSameCounts(const ClassificationScore& a, const ClassificationScore& b,
                      const std::string& what) {
  EXPECT_EQ(a.points, b.points) << what;
  EXPECT_EQ(a.decided, b.decided) << what;
  EXPECT_EQ(a.correct, b.correct) << what;
}

void ExpectSameClassification(const MapClassification& a, const MapClassification& b,
                              const std::string& method) {
  ExpectSameCounts(a.observed, b.observed, method + " observed");
  ExpectSameCounts(a.sparse, b.sparse, method + " sparse");
  ExpectSameCounts(a.covered, b.covered, method + " covered");
}

void ExpectSameMatrix(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, const std::string& what) {
  ASSERT_EQ(a.rows(), b.rows()) << what;
  ASSERT_EQ(a.cols(), b.cols()) << what;
  EXPECT_TRUE(a == b) << what << ": largest difference " << (a - b).cwiseAbs().maxCoeff();
}

// The PRF run of a case: the posterior rasters bit for bit, R̂, the chains' traces and ends, the
// MAP map.
void ExpectSamePrf(const MappingResult& a, const MappingResult& b) {
  ASSERT_TRUE(a.complete);
  ASSERT_TRUE(b.complete);
  ExpectSameMatrix(a.black_fraction, b.black_fraction, "black_fraction");
  ExpectSameMatrix(a.white_fraction, b.white_fraction, "white_fraction");
  ExpectSameMatrix(a.chain_spread, b.chain_spread, "chain_spread");
  // Enough trace records for R̂, so that it is compared at all.
  EXPECT_TRUE(std::isfinite(a.rhat_log_posterior));
  EXPECT_EQ(a.rhat_log_posterior, b.rhat_log_posterior);
  EXPECT_EQ(a.rhat_point_colours, b.rhat_point_colours);
  ASSERT_EQ(a.chains.size(), b.chains.size());
  for (std::size_t c = 0; c < a.chains.size(); ++c) {
    SCOPED_TRACE("chain " + std::to_string(c));
    EXPECT_EQ(a.chains[c].log_posterior, b.chains[c].log_posterior);
    EXPECT_EQ(a.chains[c].log_posterior_trace, b.chains[c].log_posterior_trace);
    EXPECT_EQ(a.chains[c].point_traces, b.chains[c].point_traces);
    EXPECT_EQ(a.chains[c].edges, b.chains[c].edges);
    ExpectSameMatrix(a.chains[c].black_fraction, b.chains[c].black_fraction, "chain P(black)");
  }
  ASSERT_EQ(a.map.has_value(), b.map.has_value());
  if (a.map) {
    EXPECT_EQ(a.map_log_posterior, b.map_log_posterior);
    EXPECT_EQ(a.map->stats().edges, b.map->stats().edges);
  }
}

void ExpectSameWalls(const WallScore& a, const WallScore& b) {
  ExpectSame(a.scored_length, b.scored_length, "walls scored_length");
  ExpectSame(a.border_length, b.border_length, "walls border_length");
  ExpectSame(a.mean_distance, b.mean_distance, "walls mean_distance");
  ExpectSame(a.p90_distance, b.p90_distance, "walls p90_distance");
  ExpectSame(a.max_distance, b.max_distance, "walls max_distance");
  ExpectSame(a.supported_length, b.supported_length, "walls supported_length");
  ExpectSame(a.supported_mean_distance, b.supported_mean_distance, "supported_mean_distance");
  ExpectSame(a.supported_p90_distance, b.supported_p90_distance, "supported_p90_distance");
  ExpectSame(a.supported_max_distance, b.supported_max_distance, "supported_max_distance");
  EXPECT_EQ(a.wall_points, b.wall_points);
  ExpectSame(a.recovered_fraction, b.recovered_fraction, "walls recovered_fraction");
}

void ExpectSameMapCase(const MapStudyCase& a, const MapStudyCase& b) {
  SCOPED_TRACE(a.Name());
  EXPECT_EQ(a.Name(), b.Name());
  EXPECT_EQ(a.seed, b.seed);
  ASSERT_EQ(a.methods.size(), 3u);  // grid, posterior, MAP map
  ASSERT_EQ(a.methods.size(), b.methods.size());
  for (std::size_t m = 0; m < a.methods.size(); ++m) {
    EXPECT_EQ(a.methods[m].method, b.methods[m].method);
    ExpectSameClassification(a.methods[m].classification, b.methods[m].classification,
                             a.methods[m].method);
  }
  ExpectSameWalls(a.walls, b.walls);
  ExpectSamePrf(a.prf, b.prf);
}

void ExpectSameContour(const ContourWallScore& a, const ContourWallScore& b,
                       const std::string& method) {
  ExpectSame(a.contour_length, b.contour_length, method + " contour_length");
  ExpectSame(a.mean_distance, b.mean_distance, method + " mean_distance");
  ExpectSame(a.p90_distance, b.p90_distance, method + " p90_distance");
  EXPECT_EQ(a.walls_seen, b.walls_seen) << method;
  EXPECT_EQ(a.walls_missed, b.walls_missed) << method;
  ExpectSame(a.recovered_fraction, b.recovered_fraction, method + " recovered_fraction");
}

void ExpectSameSonarCase(const SonarStudyCase& a, const SonarStudyCase& b) {
  SCOPED_TRACE(a.scene);
  EXPECT_EQ(a.scene, b.scene);
  EXPECT_EQ(a.seed, b.seed);
  EXPECT_EQ(a.readings, b.readings);
  ExpectSame(a.truth_log_posterior, b.truth_log_posterior, "truth_log_posterior");
  ASSERT_EQ(a.methods.size(), 2u);  // grid, posterior
  ASSERT_EQ(a.methods.size(), b.methods.size());
  for (std::size_t m = 0; m < a.methods.size(); ++m) {
    EXPECT_EQ(a.methods[m].method, b.methods[m].method);
    ExpectSameClassification(a.methods[m].classification, b.methods[m].classification,
                             a.methods[m].method);
    ExpectSameContour(a.methods[m].walls, b.methods[m].walls, a.methods[m].method);
  }
  ExpectSamePrf(a.prf, b.prf);
}

bool HasChainCheckpoints(const fs::path& checkpoints, int chains) {
  for (int c = 0; c < chains; ++c)
    if (!fs::exists(ChainCheckpointPath(checkpoints, static_cast<std::size_t>(c)))) return false;
  return true;
}

// ----------------------------------------------------------------------------------------------
// Progress

// A chain report of a case: `done` of `total` steps (over its chains).
MappingProgress Steps(std::uint64_t done, std::uint64_t total) {
  MappingProgress progress;
  progress.steps_done = done;
  progress.steps_total = total;
  return progress;
}

TEST(StudySession, TrackerReportsTheMeanOfTheCasesFractionsAndTheirEnds) {
  std::vector<StudyProgress> reports;
  StudySession session;
  session.progress = [&](const StudyProgress& p) { reports.push_back(p); };
  StudyProgressTracker tracker(session, 3);
  const auto case0 = tracker.ForCase(0);
  const auto case1 = tracker.ForCase(1);
  const auto case2 = tracker.ForCase(2);
  ASSERT_TRUE(case0 && case1 && case2);

  case0(Steps(10, 40));
  ASSERT_EQ(reports.size(), 1u);
  EXPECT_DOUBLE_EQ(reports[0].fraction, 0.25 / 3.0);
  EXPECT_EQ(reports[0].cases_done, 0);
  EXPECT_EQ(reports[0].cases_total, 3);
  EXPECT_EQ(reports[0].case_done, "");
  EXPECT_GE(reports[0].seconds, 0.0);

  case2(Steps(3, 4));
  ASSERT_EQ(reports.size(), 2u);
  EXPECT_DOUBLE_EQ(reports[1].fraction, (0.25 + 0.75) / 3.0);

  // A case's later report replaces its earlier one (it is not added to it).
  case0(Steps(20, 40));
  ASSERT_EQ(reports.size(), 3u);
  EXPECT_DOUBLE_EQ(reports[2].fraction, (0.5 + 0.75) / 3.0);

  // No steps at all: the case counts as 0 rather than NaN.
  case1(Steps(0, 0));
  ASSERT_EQ(reports.size(), 4u);
  EXPECT_DOUBLE_EQ(reports[3].fraction, (0.5 + 0.75) / 3.0);

  // A scored case is whole, whatever its chains last reported.
  tracker.CaseDone(2, "square/lms200", true);
  ASSERT_EQ(reports.size(), 5u);
  EXPECT_DOUBLE_EQ(reports[4].fraction, (0.5 + 0.0 + 1.0) / 3.0);
  EXPECT_EQ(reports[4].cases_done, 1);
  EXPECT_EQ(reports[4].cases_total, 3);
  EXPECT_EQ(reports[4].case_done, "square/lms200");
  EXPECT_GE(reports[4].seconds, reports[0].seconds);

  // A stopped case reports nothing and keeps its fraction.
  tracker.CaseDone(0, "l-room/lms200", false);
  EXPECT_EQ(reports.size(), 5u);
  case1(Steps(1, 4));
  ASSERT_EQ(reports.size(), 6u);
  EXPECT_DOUBLE_EQ(reports[5].fraction, (0.5 + 0.25 + 1.0) / 3.0);
  EXPECT_EQ(reports[5].cases_done, 1);
  EXPECT_EQ(reports[5].case_done, "");  // a chain report names no case

  tracker.CaseDone(0, "l-room/lms200", true);
  tracker.CaseDone(1, "corridor/lms200", true);
  ASSERT_EQ(reports.size(), 8u);
  EXPECT_EQ(reports[6].cases_done, 2);
  EXPECT_EQ(reports[6].case_done, "l-room/lms200");
  EXPECT_DOUBLE_EQ(reports[6].fraction, (1.0 + 0.25 + 1.0) / 3.0);
  EXPECT_EQ(reports[7].cases_done, 3);
  EXPECT_EQ(reports[7].case_done, "corridor/lms200");
  EXPECT_EQ(reports[7].fraction, 1.0);
}

TEST(StudySession, TrackerWithoutCallbackGivesNoCaseCallback) {
  const StudySession session;
  StudyProgressTracker tracker(session, 2);
  EXPECT_FALSE(tracker.ForCase(0));
  EXPECT_FALSE(tracker.ForCase(1));
  tracker.CaseDone(0, "square/lms200", true);  // nothing to call, no crash
  tracker.CaseDone(1, "l-room/lms200", false);
}

// ----------------------------------------------------------------------------------------------
// The cases and their sessions

TEST(StudySession, CaseFoldersAndSessions) {
  EXPECT_EQ(StudyCaseFolder("square", "lms200"), "square-lms200");
  StudySession session;
  EXPECT_TRUE(StudyCaseCheckpoints(session, "square", "lms200").empty());
  session.directory = "/some/study";
  EXPECT_EQ(StudyCaseCheckpoints(session, "square", "lms200"),
            fs::path("/some/study/square-lms200/checkpoints"));

  const std::atomic<bool> stop{false};
  session.checkpoint_every_s = 7.5;
  session.resume = true;
  session.stop_after_steps = 1234;
  session.stop = &stop;
  const StudyCases cases(session, {{"office", "pioneer16"}});
  const MappingSession mapping = cases.CaseSession({"office", "pioneer16"});
  EXPECT_EQ(mapping.checkpoint_directory, fs::path("/some/study/office-pioneer16/checkpoints"));
  EXPECT_EQ(mapping.checkpoint_every_s, 7.5);
  EXPECT_TRUE(mapping.resume);
  EXPECT_EQ(mapping.stop_after_steps, 1234u);
  EXPECT_EQ(mapping.stop, &stop);
  ASSERT_NE(mapping.also_stop, nullptr);
  EXPECT_FALSE(mapping.also_stop->load());
  EXPECT_FALSE(cases.Skip());

  session.resume = false;
  EXPECT_FALSE(cases.CaseSession({"office", "pioneer16"}).resume);
}

TEST(StudySession, SkipFollowsTheStopFlag) {
  std::atomic<bool> stop{false};
  StudySession session;
  session.stop = &stop;
  const StudyCases cases(session, {});
  EXPECT_FALSE(cases.Skip());
  stop = true;
  EXPECT_TRUE(cases.Skip());
}

TEST(StudySession, AFailingCaseStopsTheOthersAndIsRethrownOnceAllReturned) {
  if (tbb::this_task_arena::max_concurrency() < 2)
    GTEST_SKIP() << "the cases run one after the other on one thread";
  const StudySession session;
  StudyCases cases(session, {{"square", "lms200"}, {"l-room", "lms200"}});
  std::atomic<bool> other_saw_stop{false};
  std::atomic<bool> other_returned{false};
  std::atomic<int> ran{0};
  const auto start = Clock::now();
  try {
    static_cast<void>(cases.Run([&](std::size_t k, const MappingSession& mapping, const auto&) {
      ++ran;
      if (k == 0) {
        // Once case 1 has begun: a case not yet begun when one fails does not begin at all.
        while (ran.load() < 2 && SecondsSince(start) < 5.0)
          std::this_thread::sleep_for(std::chrono::milliseconds(1));
        throw std::runtime_error("case 0 failed");
      }
      // Case 1 runs until the failure reaches it through its session's also_stop (at most 5 s).
      if (mapping.also_stop == nullptr) return true;  // (CaseFoldersAndSessions fails)
      while (!mapping.also_stop->load() && SecondsSince(start) < 5.0)
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
      other_saw_stop = mapping.also_stop->load();
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      other_returned = true;
      return false;
    }));
    ADD_FAILURE() << "the failure was not rethrown";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "case 0 failed");
  }
  EXPECT_EQ(ran.load(), 2);
  EXPECT_TRUE(other_saw_stop.load());
  EXPECT_TRUE(other_returned.load());  // rethrown only after it returned
  EXPECT_TRUE(cases.Skip());           // a case not yet begun would not begin
  EXPECT_LT(SecondsSince(start), 4.0);
}

TEST(StudySession, RunGivesEachCaseItsSessionAndProgressAndTellsWhetherAllCompleted) {
  std::vector<StudyProgress> reports;
  StudySession session;
  session.directory = "/some/study";
  session.progress = [&](const StudyProgress& p) { reports.push_back(p); };
  std::vector<fs::path> checkpoints(3);
  std::vector<char> had_progress(3, 0);  // bytes: written from concurrent cases
  StudyCases cases(session, {{"square", "lms200"}, {"l-room", "lms200"}, {"office", "pioneer16"}});
  const bool all = cases.Run([&](std::size_t k, const MappingSession& mapping,
                                 const std::function<void(const MappingProgress&)>& progress) {
    checkpoints[k] = mapping.checkpoint_directory;
    had_progress[k] = progress ? 1 : 0;
    return k != 1;  // case 1 stopped
  });
  EXPECT_FALSE(all);
  EXPECT_EQ(checkpoints[0], fs::path("/some/study/square-lms200/checkpoints"));
  EXPECT_EQ(checkpoints[1], fs::path("/some/study/l-room-lms200/checkpoints"));
  EXPECT_EQ(checkpoints[2], fs::path("/some/study/office-pioneer16/checkpoints"));
  EXPECT_EQ(had_progress, std::vector<char>(3, 1));
  // One report per completed case, named scene/sensor; the stopped case reports nothing.
  std::vector<std::string> done;
  for (const StudyProgress& p : reports) done.push_back(p.case_done);
  std::sort(done.begin(), done.end());
  EXPECT_EQ(done, (std::vector<std::string>{"office/pioneer16", "square/lms200"}));
  ASSERT_FALSE(reports.empty());
  EXPECT_EQ(reports.back().cases_done, 2);
  EXPECT_EQ(reports.back().cases_total, 3);

  StudyCases complete(session, {{"square", "lms200"}, {"l-room", "lms200"}});
  EXPECT_TRUE(complete.Run([](std::size_t, const MappingSession&, const auto&) { return true; }));
}

TEST(StudySession, RunBeginsNoCaseOnceAStopIsAskedFor) {
  const std::atomic<bool> stop{true};
  StudySession session;
  session.stop = &stop;
  StudyCases cases(session, {{"square", "lms200"}, {"l-room", "lms200"}});
  std::atomic<int> ran{0};
  EXPECT_FALSE(cases.Run([&](std::size_t, const MappingSession&, const auto&) {
    ++ran;
    return true;
  }));
  EXPECT_EQ(ran.load(), 0);
}

// ----------------------------------------------------------------------------------------------
// Studies stopped and resumed

// 2 chains of 8000 steps (half burn-in), traced every 500 (8 records: R̂), 4000 annealing steps.
MapStudyOptions SmallMapStudy() {
  MapStudyOptions options;
  options.scenes = {*BuiltinScene("square"), *BuiltinScene("l-room")};
  options.sensors = {*RangeSensor::Preset("lms200")};
  options.poses = 3;
  options.beam_step = 4;
  options.mapping.burn_in = 4000;
  options.mapping.samples = 4000;
  options.mapping.anneal_steps = 4000;
  options.mapping.chains = 2;
  options.mapping.trace_every = 500;
  options.mapping.chunk = 500;
  options.seed = 3;
  return options;
}

StudySession StoppingAfter(const fs::path& directory, std::uint64_t steps, bool resume) {
  StudySession session;
  session.directory = directory;
  session.checkpoint_every_s = 1e9;  // only where a chain stops or ends
  session.resume = resume;
  session.stop_after_steps = steps;
  return session;
}

TEST(StudySession, AMapStudyResumedAcrossStopsEqualsTheUninterruptedOne) {
  const MapStudyOptions options = SmallMapStudy();
  ASSERT_EQ(options.Problem(), "");
  const MapStudyResult whole = RunMapStudy(options);
  ASSERT_TRUE(whole.complete);
  ASSERT_EQ(whole.cases.size(), 2u);

  testing::TempDir dir;
  // 1: mid-burn-in.
  const MapStudyResult first = RunMapStudy(options, StoppingAfter(dir.path(), 2500, false));
  EXPECT_FALSE(first.complete);
  EXPECT_TRUE(first.overall.empty());
  for (const MapStudyCase& c : first.cases) {
    SCOPED_TRACE(c.Name());
    EXPECT_FALSE(c.prf.complete);
    EXPECT_TRUE(c.methods.empty());
    const fs::path checkpoints = dir / (c.scene + "-" + c.sensor) / "checkpoints";
    EXPECT_TRUE(HasChainCheckpoints(checkpoints, 2));
    EXPECT_FALSE(fs::exists(AnnealCheckpointPath(checkpoints)));
  }

  // 2: from there to mid-sampling, with progress: the restored steps count from the first report.
  std::vector<StudyProgress> reports;
  StudySession second_session = StoppingAfter(dir.path(), 3000, true);
  second_session.progress = [&](const StudyProgress& p) { reports.push_back(p); };
  const MapStudyResult second = RunMapStudy(options, second_session);
  EXPECT_FALSE(second.complete);
  for (const MapStudyCase& c : second.cases) {
    EXPECT_FALSE(c.prf.complete);
    EXPECT_EQ(c.prf.resumed_steps, 2u * 2500u) << c.Name();
  }
  ASSERT_FALSE(reports.empty());
  // First, what a case's checkpoints restored, before any chunk: 2 chains × 2500 of 2 × 8000
  // steps and 4000 of annealing, the other case at 0 yet.
  EXPECT_DOUBLE_EQ(reports.front().fraction, 5000.0 / 20000.0 / 2.0);
  for (std::size_t i = 1; i < reports.size(); ++i)
    EXPECT_GE(reports[i].fraction, reports[i - 1].fraction);
  // Both cases stopped at 5500 steps a chain, neither scored.
  EXPECT_DOUBLE_EQ(reports.back().fraction, 11000.0 / 20000.0);
  for (const StudyProgress& p : reports) {
    EXPECT_EQ(p.cases_done, 0);
    EXPECT_EQ(p.cases_total, 2);
    EXPECT_EQ(p.case_done, "");
  }

  // 3: the chains' end (2500 more), then 2500 of the 4000 annealing steps.
  const MapStudyResult third = RunMapStudy(options, StoppingAfter(dir.path(), 2500, true));
  EXPECT_FALSE(third.complete);
  for (const MapStudyCase& c : third.cases) {
    EXPECT_FALSE(c.prf.complete) << c.Name();
    EXPECT_TRUE(fs::exists(AnnealCheckpointPath(dir / (c.scene + "-lms200") / "checkpoints")));
  }

  // 4: to the end.
  reports.clear();
  StudySession last_session = StoppingAfter(dir.path(), 0, true);
  last_session.progress = [&](const StudyProgress& p) { reports.push_back(p); };
  const MapStudyResult resumed = RunMapStudy(options, last_session);
  ASSERT_TRUE(resumed.complete);
  ASSERT_EQ(resumed.cases.size(), whole.cases.size());
  for (std::size_t i = 0; i < whole.cases.size(); ++i) {
    EXPECT_EQ(resumed.cases[i].prf.resumed_steps, 2u * 8000u + 2500u);  // the annealing's too
    ExpectSameMapCase(resumed.cases[i], whole.cases[i]);
  }
  ASSERT_EQ(resumed.overall.size(), whole.overall.size());
  for (std::size_t m = 0; m < whole.overall.size(); ++m)
    ExpectSameClassification(resumed.overall[m].classification, whole.overall[m].classification,
                             "overall " + whole.overall[m].method);
  ASSERT_FALSE(reports.empty());
  // First what a case's checkpoints restored, its annealing's 2500 steps included.
  EXPECT_DOUBLE_EQ(reports.front().fraction, 18500.0 / 20000.0 / 2.0);
  EXPECT_EQ(reports.back().cases_done, 2);
  EXPECT_EQ(reports.back().fraction, 1.0);
  std::set<std::string> done;
  for (const StudyProgress& p : reports)
    if (!p.case_done.empty()) done.insert(p.case_done);
  EXPECT_EQ(done, (std::set<std::string>{"square/lms200", "l-room/lms200"}));
}

// 2 chains of 4000 steps (half burn-in), traced every 250 (8 records: R̂); rings every 2 s at 1 m/s.
SonarStudyOptions SmallSonarStudy(std::vector<std::string> scenes) {
  SonarStudyOptions options;
  for (const std::string& name : scenes) options.scenes.push_back(*BuiltinScene(name));
  options.speed = 1.0;
  options.rate = 0.5;
  options.mapping.burn_in = 2000;
  options.mapping.samples = 2000;
  options.mapping.chains = 2;
  options.mapping.trace_every = 250;
  options.mapping.chunk = 250;
  options.seed = 5;
  return options;
}

TEST(StudySession, ASonarStudyResumedAcrossStopsEqualsTheUninterruptedOne) {
  const SonarStudyOptions options = SmallSonarStudy({"office"});
  ASSERT_EQ(options.Problem(), "");
  const SonarStudyResult whole = RunSonarStudy(options);
  ASSERT_TRUE(whole.complete);
  ASSERT_EQ(whole.cases.size(), 1u);

  testing::TempDir dir;
  const fs::path checkpoints = dir / "office-pioneer16" / "checkpoints";
  // Mid-burn-in, then mid-sampling, then to the end.
  const SonarStudyResult first = RunSonarStudy(options, StoppingAfter(dir.path(), 1500, false));
  EXPECT_FALSE(first.complete);
  EXPECT_FALSE(first.cases.at(0).prf.complete);
  EXPECT_TRUE(first.cases.at(0).methods.empty());
  EXPECT_TRUE(HasChainCheckpoints(checkpoints, 2));
  const SonarStudyResult second = RunSonarStudy(options, StoppingAfter(dir.path(), 1000, true));
  EXPECT_FALSE(second.complete);
  EXPECT_EQ(second.cases.at(0).prf.resumed_steps, 2u * 1500u);
  const SonarStudyResult resumed = RunSonarStudy(options, StoppingAfter(dir.path(), 0, true));
  ASSERT_TRUE(resumed.complete);
  EXPECT_EQ(resumed.cases.at(0).prf.resumed_steps, 2u * 2500u);
  ExpectSameSonarCase(resumed.cases.at(0), whole.cases.at(0));
}

TEST(StudySession, AStopAlreadyAskedForBeginsNoCase) {
  testing::TempDir dir;
  const std::atomic<bool> stop{true};
  int reports = 0;
  StudySession session;
  session.directory = dir.path();
  session.stop = &stop;
  session.progress = [&](const StudyProgress&) { ++reports; };

  const MapStudyResult map = RunMapStudy(SmallMapStudy(), session);
  EXPECT_FALSE(map.complete);
  ASSERT_EQ(map.cases.size(), 2u);
  EXPECT_EQ(map.cases[0].Name(), "square/lms200");
  EXPECT_EQ(map.cases[1].Name(), "l-room/lms200");
  for (const MapStudyCase& c : map.cases) {
    EXPECT_FALSE(c.prf.complete) << c.Name();
    EXPECT_TRUE(c.methods.empty()) << c.Name();
    EXPECT_FALSE(c.data) << c.Name();  // not even simulated
  }
  EXPECT_TRUE(map.overall.empty());

  const SonarStudyResult sonar = RunSonarStudy(SmallSonarStudy({"square", "l-room"}), session);
  EXPECT_FALSE(sonar.complete);
  ASSERT_EQ(sonar.cases.size(), 2u);
  EXPECT_EQ(sonar.cases[0].scene, "square");
  EXPECT_EQ(sonar.cases[1].scene, "l-room");
  for (const SonarStudyCase& c : sonar.cases) {
    EXPECT_FALSE(c.prf.complete) << c.scene;
    EXPECT_TRUE(c.methods.empty()) << c.scene;
    EXPECT_EQ(c.readings, 0u) << c.scene;
  }

  EXPECT_TRUE(testing::FilesIn(dir.path()).empty());  // no case folder
  EXPECT_EQ(reports, 0);
}

// The steps a case's chains had checkpointed, all chains: what a session of one step more restores.
std::uint64_t CheckpointedSteps(const Scene& scene, const RangeSensor& sensor,
                                const MapStudyOptions& options, const fs::path& checkpoints) {
  const MapStudyCase c =
      RunMapStudyCase(scene, sensor, options,
                      {.checkpoint_directory = checkpoints, .resume = true, .stop_after_steps = 1});
  EXPECT_FALSE(c.prf.complete);
  return c.prf.resumed_steps;
}

std::uint64_t CheckpointedSteps(const Scene& scene, const SonarStudyOptions& options,
                                const fs::path& checkpoints) {
  const SonarStudyCase c = RunSonarStudyCase(
      scene, options, {.checkpoint_directory = checkpoints, .resume = true, .stop_after_steps = 1});
  EXPECT_FALSE(c.prf.complete);
  return c.prf.resumed_steps;
}

// Chains of 2 × 400000 steps: several seconds a case, unless something stops them.
constexpr std::uint64_t kLongHalf = 400000;

// A damaged checkpoint in one case: the study throws BinaryFormatError once the other case's
// chains have stopped (checkpointed), rather than crash or run the other case to its end.
// Here the first case is damaged: the second stops at its chains' next chunk, or (when it has
// not begun yet) does not begin.
TEST(StudySession, ADamagedCheckpointFailsTheMapStudyAndStopsTheOtherCase) {
  MapStudyOptions options = SmallMapStudy();
  options.mapping.burn_in = kLongHalf;
  options.mapping.samples = kLongHalf;
  options.mapping.anneal_steps = 0;
  testing::TempDir dir;
  const MapStudyResult first = RunMapStudy(options, StoppingAfter(dir.path(), 1000, false));
  ASSERT_FALSE(first.complete);
  const fs::path damaged = dir / "square-lms200" / "checkpoints";
  const fs::path other = dir / "l-room-lms200" / "checkpoints";
  ASSERT_TRUE(HasChainCheckpoints(damaged, 2));
  ASSERT_TRUE(HasChainCheckpoints(other, 2));
  testing::WriteAll(ChainCheckpointPath(damaged, 0), "not a checkpoint at all");

  const auto start = Clock::now();
  EXPECT_THROW((void)RunMapStudy(options, StoppingAfter(dir.path(), 0, true)), BinaryFormatError);
  EXPECT_LT(SecondsSince(start), 20.0);  // a loose bound: the steps below are the measure
  // The other case's chains stopped far from their end, checkpointed (and still loadable).
  ASSERT_TRUE(HasChainCheckpoints(other, 2));
  const std::uint64_t steps =
      CheckpointedSteps(options.scenes[1], options.sensors[0], options, other);
  EXPECT_GE(steps, 2u * 1000u);
  EXPECT_LT(steps, 2u * kLongHalf);
  // The damaged case's other chain is untouched.
  EXPECT_TRUE(fs::exists(ChainCheckpointPath(damaged, 1)));
}

// Here the second case is damaged while the first runs (it needs two threads): the first's
// chains stop through the failure of the second.
TEST(StudySession, ADamagedCheckpointFailsTheSonarStudyAndStopsTheOtherCase) {
  if (tbb::this_task_arena::max_concurrency() < 2)
    GTEST_SKIP() << "the cases run one after the other on one thread";
  SonarStudyOptions options = SmallSonarStudy({"square", "l-room"});
  options.mapping.burn_in = kLongHalf;
  options.mapping.samples = kLongHalf;
  testing::TempDir dir;
  ASSERT_FALSE(RunSonarStudy(options, StoppingAfter(dir.path(), 500, false)).complete);
  const fs::path damaged = dir / "l-room-pioneer16" / "checkpoints";
  const fs::path other = dir / "square-pioneer16" / "checkpoints";
  ASSERT_TRUE(HasChainCheckpoints(damaged, 2));
  ASSERT_TRUE(HasChainCheckpoints(other, 2));
  testing::WriteAll(ChainCheckpointPath(damaged, 0), std::string(4096, '\x5a'));

  const auto start = Clock::now();
  EXPECT_THROW((void)RunSonarStudy(options, StoppingAfter(dir.path(), 0, true)), BinaryFormatError);
  EXPECT_LT(SecondsSince(start), 20.0);  // a loose bound: the steps below are the measure
  ASSERT_TRUE(HasChainCheckpoints(other, 2));
  const std::uint64_t steps = CheckpointedSteps(options.scenes[0], options, other);
  EXPECT_GE(steps, 2u * 500u);
  EXPECT_LT(steps, 2u * kLongHalf);
}

// Within one run: a chain that throws (its checkpoint cannot be written, a directory being in
// its place) stops the run's other chain at its next chunk, rather than let it run to its end
// before the exception reaches the caller.
TEST(StudySession, AChainThatThrowsStopsTheOtherChainOfItsRun) {
  if (tbb::this_task_arena::max_concurrency() < 2)
    GTEST_SKIP() << "the chains run one after the other on one thread";
  MapStudyOptions options = SmallMapStudy();
  options.mapping.burn_in = kLongHalf;
  options.mapping.samples = kLongHalf;
  options.mapping.anneal_steps = 0;
  options.mapping.chunk = 5000;
  testing::TempDir dir;
  fs::create_directories(ChainCheckpointPath(dir.path(), 1));  // chain 1's checkpoints fail
  const auto start = Clock::now();
  EXPECT_THROW((void)RunMapStudyCase(options.scenes[0], options.sensors[0], options,
                                     {.checkpoint_directory = dir.path(), .checkpoint_every_s = 0}),
               IoError);
  EXPECT_LT(SecondsSince(start), 20.0);  // a loose bound: the steps below are the measure
  // Chain 0 checkpointed where it stopped; chain 1 (no checkpoint now) starts afresh.
  ASSERT_TRUE(fs::exists(ChainCheckpointPath(dir.path(), 0)));
  fs::remove(ChainCheckpointPath(dir.path(), 1));
  const std::uint64_t steps =
      CheckpointedSteps(options.scenes[0], options.sensors[0], options, dir.path());
  EXPECT_GE(steps, 5000u);
  EXPECT_LT(steps, kLongHalf);
}

TEST(StudySession, ResumingWithAnotherSeedIsRefused) {
  MapStudyOptions options = SmallMapStudy();
  options.scenes = {*BuiltinScene("square")};
  testing::TempDir dir;
  ASSERT_FALSE(RunMapStudy(options, StoppingAfter(dir.path(), 500, false)).complete);
  options.seed += 1;
  EXPECT_THROW((void)RunMapStudy(options, StoppingAfter(dir.path(), 0, true)), BinaryFormatError);

  const SonarStudyOptions sonar = SmallSonarStudy({"square"});
  ASSERT_FALSE(RunSonarStudy(sonar, StoppingAfter(dir.path(), 500, false)).complete);
  SonarStudyOptions reseeded = sonar;
  reseeded.seed += 1;
  EXPECT_THROW((void)RunSonarStudy(reseeded, StoppingAfter(dir.path(), 0, true)),
               BinaryFormatError);
}

}  // namespace
}  // namespace priormap::prf
