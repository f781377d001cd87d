#pragma once
// What `prf study` and `prf sonar-study` share to be stopped and resumed: the session options,
// the checks of the output directory, the status line and the end of a stopped study; and the
// checks of the options they share.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include <CLI/CLI.hpp>

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

// Before a study in `dir` whose cases have the folders `folders`: refuses a new study over a
// stopped one's checkpoints (it would start those cases afresh and lose their progress), and
// --resume where no case has any or with other cases than the stopped study's; then creates `dir`
// and records the cases in DIR/study-in-progress.json.
// The study holds `dir` locked until the lock returned goes: a second study there is refused.
[[nodiscard]] DirectoryLock BeginStudy(const std::filesystem::path& dir,
                                       const std::vector<std::string>& folders, bool resume);

// The session of a study in `dir` that Ctrl-C and SIGTERM stop (with a StopOnSignals alive), its
// progress shown on stderr.
[[nodiscard]] prf::StudySession MakeStudySession(const std::filesystem::path& dir,
                                                 const StudySessionCliOptions& o);

// The study's run, with Ctrl-C and SIGTERM stopping it and a checkpoint it cannot resume from
// turned into the user's error.
void RunStoppable(const std::function<void()>& run);

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
  RunStoppable([&] { result = run(MakeStudySession(dir, o)); });
  std::uint64_t resumed = 0;
  for (const auto& c : result.cases) resumed += c.prf.resumed_steps;
  ReportResumedSteps(resumed);
  if (!result.complete) {
    EndStoppedStudy(dir, folders);
    return std::nullopt;
  }
  return result;
}

// After the study's outputs are written: removes the cases' checkpoints (megabytes per chain),
// the case folders they leave empty, and the record of the study in progress.
void FinishStudy(const std::filesystem::path& dir, const std::vector<std::string>& folders);

}  // namespace priormap::app
