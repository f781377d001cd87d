#include "study_cases.hpp"

#include <exception>
#include <mutex>
#include <utility>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

namespace priormap::prf {

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

StudyCases::StudyCases(const StudySession& session, std::vector<StudyCaseName> names)
    : session_(session),
      names_(std::move(names)),
      tracker_(session, static_cast<int>(names_.size())) {}

MappingSession StudyCases::CaseSession(const StudyCaseName& name) const {
  return {.checkpoint_directory = StudyCaseCheckpoints(session_, name.scene, name.sensor),
          .checkpoint_every_s = session_.checkpoint_every_s,
          .resume = session_.resume,
          .stop_after_steps = session_.stop_after_steps,
          .stop = session_.stop,
          .also_stop = &failed_};
}

bool StudyCases::Run(const RunCase& run_case) {
  // Each case's exception is caught in its own task: one escaping would cancel the loop's task
  // group, and with it, silently, the loops nested in the other cases (their chains' loading).
  std::mutex mutex;
  std::exception_ptr first;
  std::atomic<bool> all_complete{true};
  tbb::parallel_for(std::size_t{0}, names_.size(), [&](std::size_t k) {
    const StudyCaseName& name = names_[k];
    bool complete = false;
    try {
      // Isolated: a thread that waits in this case's nested loops takes none of another case's
      // chains meanwhile, which would hold this case's end (and a failure's report) until that
      // chain's end.
      if (!Skip()) {
        tbb::this_task_arena::isolate([&] {
          complete = run_case(k, CaseSession(name), tracker_.ForCase(static_cast<int>(k)));
        });
      }
      // In the try too: the report may throw (stderr closed), like the chains' reports.
      tracker_.CaseDone(static_cast<int>(k), name.scene + "/" + name.sensor, complete);
    } catch (...) {
      complete = false;
      const std::lock_guard lock(mutex);
      if (!first) first = std::current_exception();
      failed_ = true;
    }
    if (!complete) all_complete = false;
  });
  if (first) std::rethrow_exception(first);
  return all_complete;
}

bool StudyCases::Skip() const {
  return failed_.load() || (session_.stop != nullptr && session_.stop->load());
}

}  // namespace priormap::prf
