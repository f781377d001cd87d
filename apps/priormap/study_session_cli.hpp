#pragma once
// What `prf study` and `prf sonar-study` share to be stopped and resumed: the session options,
// the checks of the output directory, the status line and the end of a stopped study.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
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
void RunStoppableStudy(const std::function<void()>& run);

// After a study that stopped before its end: says how to continue it and, when a signal stopped
// it, exits with 128 + the signal.
void EndStoppedStudy(const std::filesystem::path& dir, const std::vector<std::string>& folders);

// After the study's outputs are written: removes the cases' checkpoints (megabytes per chain),
// the case folders they leave empty, and the record of the study in progress.
void FinishStudy(const std::filesystem::path& dir, const std::vector<std::string>& folders);

// "resumed 1.2M steps from the checkpoints" on stderr, when the study resumed any.
void ReportResumedSteps(std::uint64_t steps);

}  // namespace priormap::app
