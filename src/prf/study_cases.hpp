#pragma once
/// How RunMapStudy and RunSonarStudy run their cases: in parallel, each with its own
/// MappingSession and progress, a failure stopping the others. Internal to the library; the
/// session's options are StudySession (study_session.hpp).

#include <atomic>
#include <chrono>
#include <cstddef>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

#include <priormap/prf/mapping.hpp>
#include <priormap/prf/study_session.hpp>

namespace priormap::prf {

/// A case's scene and sensor: its folder (StudyCaseFolder) and its name in the progress.
struct StudyCaseName {
  std::string scene;
  std::string sensor;
};

/// Turns the cases' chain reports into StudyProgress calls: one per chain report and one per
/// scored case, thread-safe.
class StudyProgressTracker {
 public:
  StudyProgressTracker(const StudySession& session, int cases);

  /// The progress callback of case k's RunMapping (empty when the session has no progress).
  [[nodiscard]] std::function<void(const MappingProgress&)> ForCase(int k);
  /// Case k is scored (or stopped: `complete` false, which leaves its fraction as it stood).
  void CaseDone(int k, const std::string& name, bool complete);

 private:
  void Report(const std::string& case_done);  // under mutex_

  const StudySession& session_;
  std::mutex mutex_;
  std::vector<double> fractions_;
  int done_ = 0;
  std::chrono::steady_clock::time_point start_;
};

/// Runs a study's cases in parallel (oneTBB). A case that throws stops the cases running with it at
/// their chains' next chunk (checkpointed) and keeps the others from beginning; its exception is
/// rethrown once every case has returned.
class StudyCases {
 public:
  /// Runs case k with its chains' session and progress callback; returns whether it completed
  /// (false: the session stopped it).
  using RunCase = std::function<bool(std::size_t k, const MappingSession& mapping,
                                     const std::function<void(const MappingProgress&)>& progress)>;

  StudyCases(const StudySession& session, std::vector<StudyCaseName> names);

  /// Runs every case not skipped (Skip() when its turn comes: a case not begun is not worth
  /// its simulation); returns whether every case completed.
  bool Run(const RunCase& run_case);
  /// Whether a case not yet begun is not to begin: a stop was asked for or a case failed.
  [[nodiscard]] bool Skip() const;
  /// The MappingSession of a case's chains.
  [[nodiscard]] MappingSession CaseSession(const StudyCaseName& name) const;

 private:
  const StudySession& session_;
  std::vector<StudyCaseName> names_;
  StudyProgressTracker tracker_;
  std::atomic<bool> failed_{false};
};

}  // namespace priormap::prf
