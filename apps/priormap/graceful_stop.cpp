#include "graceful_stop.hpp"

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>

#include <fmt/format.h>

#include <priormap/core/file_io.hpp>

namespace priormap::app {
namespace {

std::atomic<bool> g_stop_requested{false};
// The first signal, for the exit status.
std::atomic<int> g_stop_signal{0};

// When the first signal came (CLOCK_MONOTONIC, ns).
std::atomic<std::int64_t> g_first_signal_ns{0};

std::int64_t MonotonicNs() {
  timespec now{};
  clock_gettime(CLOCK_MONOTONIC, &now);  // async-signal-safe
  return static_cast<std::int64_t>(now.tv_sec) * 1000000000 + now.tv_nsec;
}

extern "C" void RequestStop(int signal) {
  // A second signal does not wait for the chains' next chunk: it ends the process at once,
  // without the checkpoints or outputs being written. One within a second of the first is taken
  // for the same request, delivered twice (a terminal's Ctrl-C to the process group and a
  // wrapper that forwards it, a scheduler's SIGTERM and SIGINT).
  if (g_stop_requested) {
    if (MonotonicNs() - g_first_signal_ns.load() < 1000000000) return;
    RemoveTemporaryFilesInProgress();
    std::signal(signal, SIG_DFL);
    std::raise(signal);
    return;
  }
  g_first_signal_ns = MonotonicNs();
  g_stop_signal = signal;
  g_stop_requested = true;
}

}  // namespace

const std::atomic<bool>& StopFlag() {
  return g_stop_requested;
}

bool StopRequested() {
  return g_stop_requested.load();
}

StopOnSignals::StopOnSignals() {
  struct sigaction action {};
  action.sa_handler = RequestStop;
  sigemptyset(&action.sa_mask);
  // The handler returns (main's does not), so a write it interrupts must go on rather than fail
  // with EINTR: the stop's message blocked on a full pipe or a paused terminal would be lost, the
  // status line cut.
  action.sa_flags = SA_RESTART;
  // An ignored signal stays ignored (nohup; a shell's background job and SIGINT), as main has it:
  // the handler is not installed at all, not even for a moment.
  sigaction(SIGINT, nullptr, &previous_int_);
  sigaction(SIGTERM, nullptr, &previous_term_);
  if (previous_int_.sa_handler != SIG_IGN) sigaction(SIGINT, &action, nullptr);
  if (previous_term_.sa_handler != SIG_IGN) sigaction(SIGTERM, &action, nullptr);
}

StopOnSignals::~StopOnSignals() {
  // A stopped run is on its way to ExitAsStopped: the same request delivered twice may come
  // after the run has stopped, and main's handler would take it for a second request, ending
  // the process by the signal with the stop's message on stdout lost. This handler still ends it
  // at once, as main's would, for a signal a second or more after the first.
  if (StopRequested()) return;
  sigaction(SIGINT, &previous_int_, nullptr);
  sigaction(SIGTERM, &previous_term_, nullptr);
}

void ExitAsStopped() {
  errno = 0;
  if (std::fflush(stdout) != 0 || std::ferror(stdout) != 0) {
    const int error = errno;
    fmt::print(stderr, "priormap: error: cannot write to standard output: {}\n",
               error != 0 ? std::strerror(error) : "write failed");
  }
  std::exit(128 + g_stop_signal.load());
}

}  // namespace priormap::app
