#pragma once
// Ctrl-C and SIGTERM during a long run (prf, prf study, prf sonar-study, scan --all): the first
// stops it checkpointed at the chains' next chunk (or once the scans under way are journaled), so
// that it can be resumed; a second, a second or more after the first, ends the process at once.

#include <atomic>
#include <csignal>

namespace priormap::app {

// Set by the first SIGINT or SIGTERM while a StopOnSignals lives; the run's MappingSession or
// StudySession watches it.
[[nodiscard]] const std::atomic<bool>& StopFlag();
[[nodiscard]] bool StopRequested();

// Installs the stopping handler for SIGINT and SIGTERM while it lives, then puts back the handlers
// it replaced (main's, which remove temporary files when a signal ends the process); after a stop
// it leaves its own in place, for the process's way out.
class StopOnSignals {
 public:
  StopOnSignals();
  ~StopOnSignals();
  StopOnSignals(const StopOnSignals&) = delete;
  StopOnSignals& operator=(const StopOnSignals&) = delete;

 private:
  struct sigaction previous_int_ {};
  struct sigaction previous_term_ {};
};

// Ends a run that a signal stopped, checkpointed, with the shell's status for a command a signal
// ended (128 + its number: 130 for Ctrl-C, 143 for SIGTERM), so that a scheduler does not take it
// for finished. Stdout is flushed first; a failed flush is reported on stderr.
[[noreturn]] void ExitAsStopped();

}  // namespace priormap::app
