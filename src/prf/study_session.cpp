#include <exception>
#include <mutex>

#include <fmt/format.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <priormap/prf/study_session.hpp>

namespace priormap::prf {

std::string StudyCaseFolder(const std::string& scene, const std::string& sensor) {
  return fmt::format("{}-{}", scene, sensor);
}

std::filesystem::path StudyCaseCheckpoints(const StudySession& session, const std::string& scene,
                                           const std::string& sensor) {
  if (session.directory.empty()) return {};
  return session.directory / StudyCaseFolder(scene, sensor) / "checkpoints";
}

MappingSession StudyCases::CaseSession(const std::string& scene, const std::string& sensor) const {
  return {.checkpoint_directory = StudyCaseCheckpoints(session_, scene, sensor),
          .checkpoint_every_s = session_.checkpoint_every_s,
          .resume = session_.resume,
          .stop_after_steps = session_.stop_after_steps,
          .stop = session_.stop,
          .also_stop = &failed_};
}

void StudyCases::Run(std::size_t count, const std::function<void(std::size_t)>& run_case) {
  // Each case's exception is caught in its own task: one escaping would cancel the loop's task
  // group, and with it, silently, the loops nested in the other cases (their chains' loading).
  std::mutex mutex;
  std::exception_ptr first;
  tbb::parallel_for(std::size_t{0}, count, [&](std::size_t k) {
    try {
      // Isolated: a thread that waits in this case's nested loops takes none of another case's
      // chains meanwhile, which would hold this case's end (and a failure's report) until that
      // chain's end.
      tbb::this_task_arena::isolate([&] { run_case(k); });
    } catch (...) {
      const std::lock_guard lock(mutex);
      if (!first) first = std::current_exception();
      failed_ = true;
    }
  });
  if (first) std::rethrow_exception(first);
}

bool StudyCases::Skip() const {
  return failed_.load() || (session_.stop != nullptr && session_.stop->load());
}

StudyProgressTracker::StudyProgressTracker(const StudySession& session, int cases)
    : session_(session),
      fractions_(static_cast<std::size_t>(cases), 0.0),
      start_(std::chrono::steady_clock::now()) {}

std::function<void(const MappingProgress&)> StudyProgressTracker::ForCase(int k) {
  if (!session_.progress) return {};
  return [this, k](const MappingProgress& p) {
    const std::lock_guard lock(mutex_);
    fractions_[static_cast<std::size_t>(k)] =
        p.steps_total == 0 ? 0.0
                           : static_cast<double>(p.steps_done) / static_cast<double>(p.steps_total);
    Report({});
  };
}

void StudyProgressTracker::CaseDone(int k, const std::string& name, bool complete) {
  if (!session_.progress || !complete) return;
  const std::lock_guard lock(mutex_);
  fractions_[static_cast<std::size_t>(k)] = 1.0;
  ++done_;
  Report(name);
}

void StudyProgressTracker::Report(const std::string& case_done) {
  double sum = 0.0;
  for (const double f : fractions_) sum += f;
  session_.progress(
      {.cases_done = done_,
       .cases_total = static_cast<int>(fractions_.size()),
       .fraction = fractions_.empty() ? 1.0 : sum / static_cast<double>(fractions_.size()),
       .seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(),
       .case_done = case_done});
}

}  // namespace priormap::prf
