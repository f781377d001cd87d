#pragma once
/// How a study (map_study.hpp, sonar_study.hpp) is carried out; none of it changes the result.
/// With a directory, each case's chains checkpoint in DIR/<scene>-<sensor>/checkpoints as a
/// `priormap prf` run's do (MappingSession), so that a study stopped (by `stop` or a crash) and
/// resumed from them ends exactly as the uninterrupted study: the cases finished before the stop
/// cost only their simulation and scoring again, the others go on from their last checkpoint.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

#include <priormap/prf/mapping.hpp>

namespace priormap::prf {

struct StudyProgress {
  int cases_done = 0;
  int cases_total = 0;
  /// Of the PRF steps, each case weighing the same (its chains' steps done over their total,
  /// steps restored from checkpoints included, from the chains' first report this session; 1
  /// once the case is scored).
  double fraction = 0.0;
  double seconds = 0.0;   ///< since the study's start
  std::string case_done;  ///< the case just scored ("office/pioneer16"), else empty
};

struct StudySession {
  /// Where the cases' folders are (DIR/<scene>-<sensor>/checkpoints); empty: no checkpoints.
  std::filesystem::path directory;
  double checkpoint_every_s = 5.0;
  /// Continue each case from its checkpoints (cases without any start afresh).
  bool resume = false;
  /// Each chain of each case, and each case's annealing, stops, checkpointed, after this many of
  /// its own steps in this session (MappingSession::stop_after_steps); 0: no limit.
  std::uint64_t stop_after_steps = 0;
  /// Set from elsewhere (a signal handler) to stop every case's chains, checkpointed, at their
  /// next chunk; cases not yet begun are not begun.
  const std::atomic<bool>* stop = nullptr;
  /// Called from the cases' threads, serialized.
  std::function<void(const StudyProgress&)> progress;
};

/// The folder of a case's figures and checkpoints, below the study's directory.
[[nodiscard]] std::string StudyCaseFolder(const std::string& scene, const std::string& sensor);

/// The checkpoints of a case's chains (empty when the session keeps none).
[[nodiscard]] std::filesystem::path StudyCaseCheckpoints(const StudySession& session,
                                                         const std::string& scene,
                                                         const std::string& sensor);

/// Runs a study's cases in parallel (oneTBB). A case that throws stops the cases running with it at
/// their chains' next chunk (checkpointed) and keeps the others from beginning; its exception is
/// rethrown once every case has returned.
class StudyCases {
 public:
  explicit StudyCases(const StudySession& session) : session_(session) {}

  /// run_case(k) for k in [0, count).
  void Run(std::size_t count, const std::function<void(std::size_t)>& run_case);
  /// Whether a case not yet begun is not to begin: a stop was asked for or a case failed.
  [[nodiscard]] bool Skip() const;
  /// The MappingSession of a case's chains.
  [[nodiscard]] MappingSession CaseSession(const std::string& scene,
                                           const std::string& sensor) const;

 private:
  const StudySession& session_;
  std::atomic<bool> failed_{false};
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

}  // namespace priormap::prf
