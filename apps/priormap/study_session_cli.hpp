#pragma once
// What `prf study` and `prf sonar-study` share to be stopped and resumed: the session options,
// the checks of the output directory, the status line and the end of a stopped study; and the
// checks of the options they share.

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <priormap/prf/study_session.hpp>

#include "directory_lock.hpp"

namespace priormap::app {

struct StudySessionCliOptions {
  bool resume = false;
  double checkpoint_every_s = 5.0;
  std::uint64_t stop_after_steps = 0;
};

void AddStudySessionOptions(CLI::App& cmd, StudySessionCliOptions& o);

// --samples (after StepCount()): at least one, P(black) being their mean.
[[nodiscard]] CLI::Validator StudySamples();
// --resolution: within the bounds of the study's rasters (prf::StudyResolutionProblem's).
[[nodiscard]] CLI::Validator StudyResolution();
// Throws UsageError when an entry of `option` is given twice ("--scenes: scene 'square' is given
// twice"): the option's own value. Different entries of one name (a file and a built-in scene)
// are the study's check, once the scenes are loaded.
void RefuseRepeatedEntries(const std::vector<std::string>& entries, const std::string& option,
                           const std::string& what);

// Every figure a case of either study writes in its folder (prf study's, prf sonar-study's).
inline constexpr std::array<const char*, 6> kStudyCaseFigures = {
    "truth.png", "grid.png", "posterior.png", "map.png", "grid-errors.png", "posterior-errors.png"};

// Before a study in `dir` whose cases have the folders `folders` and whose options are `options`
// (its summary's "options"): refuses a new study over a stopped one's checkpoints (it would start
// those cases afresh and lose their progress), and --resume where no case has any, or with other
// cases or options than the stopped study's (naming them); then creates `dir` and records the
// cases and options in DIR/study-in-progress.json. A new study removes an earlier study's results:
// its summary and table, and the figures of its cases that this study does not have (with their
// folders, when that empties them), which would otherwise stand beside this study's numbers.
// The study holds `dir` locked until the lock returned goes: a second study there is refused.
[[nodiscard]] DirectoryLock BeginStudy(const std::filesystem::path& dir,
                                       const std::vector<std::string>& folders,
                                       const nlohmann::json& options, bool resume);

// The session of a study in `dir` that Ctrl-C and SIGTERM stop (with a StopOnSignals alive), its
// progress shown on stderr.
[[nodiscard]] prf::StudySession MakeStudySession(const std::filesystem::path& dir,
                                                 const StudySessionCliOptions& o);

// The run of the study in `dir` of the cases `folders`, with Ctrl-C and SIGTERM stopping it; a
// checkpoint it cannot resume from, and a failed write (a full disk), turned into the user's error
// with what to do.
void RunStoppable(const std::filesystem::path& dir, const std::vector<std::string>& folders,
                  const std::function<void()>& run);

// After a study that stopped before its end: says how to continue it and, when a signal stopped
// it, exits with 128 + the signal.
void EndStoppedStudy(const std::filesystem::path& dir, const std::vector<std::string>& folders);

// "resumed 1.2M steps from the checkpoints" on stderr, when the study resumed any.
void ReportResumedSteps(std::uint64_t steps);

// Runs a study in `dir` (run(session) gives its result: RunMapStudy, RunSonarStudy) that Ctrl-C
// and SIGTERM stop, and reports the steps it resumed. The result when the study reached its end;
// else the study is ended as stopped (EndStoppedStudy) and there is none.
template <typename RunStudy>
[[nodiscard]] auto RunStoppableStudy(const std::filesystem::path& dir,
                                     const std::vector<std::string>& folders,
                                     const StudySessionCliOptions& o, const RunStudy& run)
    -> std::optional<std::invoke_result_t<const RunStudy&, const prf::StudySession&>> {
  std::invoke_result_t<const RunStudy&, const prf::StudySession&> result;
  RunStoppable(dir, folders, [&] { result = run(MakeStudySession(dir, o)); });
  std::uint64_t resumed = 0;
  for (const auto& c : result.cases) resumed += c.prf.resumed_steps;
  ReportResumedSteps(resumed);
  if (!result.complete) {
    EndStoppedStudy(dir, folders);
    return std::nullopt;
  }
  return result;
}

// Writes a study's outputs (`write`: its summary, table and figures), then removes the cases'
// checkpoints (megabytes per chain), the case folders they leave empty, and the record of the
// study in progress. A write that fails (a full disk) leaves the checkpoints, and says that the
// same command with --resume writes the outputs once it can.
void FinishStudy(const std::filesystem::path& dir, const std::vector<std::string>& folders,
                 const std::function<void()>& write);

}  // namespace priormap::app
