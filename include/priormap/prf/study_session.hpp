#pragma once
/// How a study (map_study.hpp, sonar_study.hpp) is carried out; none of it changes the result.
/// With a directory, each case's chains checkpoint in DIR/<scene>-<sensor>/checkpoints as a
/// `priormap prf` run's do (MappingSession), so that a study stopped (by `stop` or a crash) and
/// resumed from them ends exactly as the uninterrupted study: the cases finished before the stop
/// cost only their simulation and scoring again, the others go on from their last checkpoint.

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>

namespace priormap::prf {

struct StudyProgress {
  int cases_done = 0;
  int cases_total = 0;
  /// Of the PRF steps, each case weighing the same (its steps done, chains' and annealing's,
  /// over their total, steps restored from checkpoints included, from the chains' first report
  /// this session; 1 once the case is scored).
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

}  // namespace priormap::prf
