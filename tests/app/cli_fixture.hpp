#pragma once
// The fixture of the end-to-end tests: runs the priormap binary in a fresh working directory
// (its current directory), capturing stdout and stderr in files of a separate directory, so
// that the working directory holds only what priormap wrote; a run stopped by a signal; a
// summary without what depends on the session, to compare a resumed study with an uninterrupted
// one.
#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstddef>
#include <fcntl.h>
#include <filesystem>
#include <functional>
#include <map>
#include <sched.h>
#include <set>
#include <string>
#include <sys/types.h>
#include <sys/wait.h>
#include <system_error>
#include <thread>
#include <unistd.h>
#include <utility>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "testing/process.hpp"
#include "testing/temp_dir.hpp"

namespace priormap::testing {

/// The file starts with the PNG signature.
inline bool IsPng(const std::string& bytes) {
  return bytes.starts_with("\x89PNG\r\n\x1a\n");
}

class CliFixture : public ::testing::Test {
 protected:
  ProcessResult Run(const std::vector<std::string>& args) const {
    return RunProgram(PRIORMAP_BINARY, work_.path(), io_.path(), args);
  }

  /// Runs `args` expecting an error on stderr and the working directory unchanged (no output
  /// file, no temporary file); the caller checks the exit status.
  ProcessResult RunFailing(const std::vector<std::string>& args) const {
    const std::set<std::string> before = WorkFiles();
    ProcessResult r = Run(args);
    EXPECT_THAT(r.err, ::testing::HasSubstr("priormap: error:"));
    EXPECT_THAT(r.err, ::testing::Not(::testing::HasSubstr("internal error")));
    EXPECT_EQ(WorkFiles(), before) << "stderr:\n" << r.err;
    return r;
  }

  /// Every file and directory under the working directory, relative to it.
  [[nodiscard]] std::set<std::string> WorkFiles() const { return FilesUnder(work_.path()); }

  [[nodiscard]] std::filesystem::path Work(const std::string& name) const { return work_ / name; }

 private:
  TempDir work_;
  TempDir io_;
};

// How RunAndSignalWhen signals the run: `times` times `signal`, `apart` apart (10 ms: one
// request delivered twice, a terminal's Ctrl-C and a wrapper that forwards it; a second or more:
// a user who insists).
struct Signalling {
  int signal = SIGTERM;
  int times = 1;
  std::chrono::milliseconds apart{10};
  // The run held to one CPU, so that it lasts as long on a machine of many cores as on one: a run
  // that `ready` catches early cannot end before the signal comes, whatever the machine.
  bool one_cpu = false;
  // The run's stdout a pipe already full, read only once the last signal has reached the run: it
  // blocks at its first write there (a stopped run's message, written once it has stopped), so
  // that a later signal finds it stopped but not yet ended.
  bool stdout_full = false;
};

// Starts priormap with `args` in `work`, signals it as `how` says once `ready()` holds (polled
// every 25 ms for at most 30 s; `not_ready` is the failure after that), and waits for it.
struct SignalledRun {
  int wait_status = 0;
  std::string out;
  std::string err;
  // The signals sent while it ran (fewer than `times` when an earlier one ended it).
  int signals_while_running = 0;
};
inline SignalledRun RunAndSignalWhen(const std::filesystem::path& work,
                                     std::vector<std::string> args,
                                     const std::function<bool()>& ready,
                                     const std::string& not_ready, const Signalling& how) {
  const testing::TempDir io;
  const std::string program = PRIORMAP_BINARY;
  std::vector<char*> argv = {const_cast<char*>(program.c_str())};
  for (std::string& arg : args) argv.push_back(arg.data());
  argv.push_back(nullptr);
  SignalledRun run;
  int full_pipe[2] = {-1, -1};
  std::size_t filler = 0;
  if (how.stdout_full) {
    if (::pipe2(full_pipe, O_CLOEXEC) != 0) {
      ADD_FAILURE() << "cannot make a pipe";
      return run;
    }
    // Filled without blocking, then blocking again: the flag belongs to the pipe's open file,
    // which the run shares, and its writes must wait, not fail.
    ::fcntl(full_pipe[1], F_SETFL, O_NONBLOCK);
    const std::string page(4096, 'x');
    for (ssize_t n; (n = ::write(full_pipe[1], page.data(), page.size())) > 0;)
      filler += static_cast<std::size_t>(n);
    ::fcntl(full_pipe[1], F_SETFL, 0);
  }
  const int out = how.stdout_full ? full_pipe[1]
                                  : ::open((io / "stdout").c_str(),
                                           O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  const int err = ::open((io / "stderr").c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (out < 0 || err < 0) {
    ADD_FAILURE() << "cannot create the output files";
    return run;
  }
  // The first CPU this process may use, chosen before the fork (the child only makes system
  // calls).
  cpu_set_t one_cpu;
  CPU_ZERO(&one_cpu);
  if (how.one_cpu) {
    cpu_set_t allowed;
    CPU_ZERO(&allowed);
    ::sched_getaffinity(0, sizeof allowed, &allowed);
    for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu)
      if (CPU_ISSET(cpu, &allowed)) {
        CPU_SET(cpu, &one_cpu);
        break;
      }
  }
  const bool pin = CPU_COUNT(&one_cpu) == 1;
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (::chdir(work.c_str()) != 0 || ::dup2(out, 1) < 0 || ::dup2(err, 2) < 0) ::_exit(127);
    if (pin && ::sched_setaffinity(0, sizeof one_cpu, &one_cpu) != 0) ::_exit(127);
    // A signal ignored where the tests run (nohup, a background job's SIGINT) would stay ignored
    // in priormap, which keeps ignored signals ignored, and the run would never stop.
    std::signal(SIGINT, SIG_DFL);
    std::signal(SIGTERM, SIG_DFL);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  ::close(out);
  ::close(err);
  for (int i = 0; i < 1200 && !ready(); ++i) ::usleep(25000);
  EXPECT_TRUE(ready()) << not_ready;
  bool ended = false;
  for (int k = 0; k < how.times; ++k) {
    if (k > 0) std::this_thread::sleep_for(how.apart);
    ended = ::waitpid(pid, &run.wait_status, WNOHANG) == pid;
    if (ended) break;
    ::kill(pid, how.signal);
    ++run.signals_while_running;
  }
  std::string piped;
  if (how.stdout_full) {
    // Not at once: a write that room in the pipe lets through is not interrupted, so the run must
    // see the last signal while it still waits to write. Then to the pipe's end, which comes when
    // the run ends: only then can it end.
    if (!ended) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    char buffer[4096];
    for (ssize_t n; (n = ::read(full_pipe[0], buffer, sizeof buffer)) > 0;)
      piped.append(buffer, static_cast<std::size_t>(n));
    ::close(full_pipe[0]);
  }
  if (!ended) ::waitpid(pid, &run.wait_status, 0);
  run.out = how.stdout_full ? piped.substr(std::min(filler, piped.size()))
                            : testing::ReadAll(io / "stdout");
  run.err = testing::ReadAll(io / "stderr");
  return run;
}

// The same, `times` times `signal`, 10 ms apart.
inline SignalledRun RunAndSignalWhen(const std::filesystem::path& work,
                                     std::vector<std::string> args,
                                     const std::function<bool()>& ready,
                                     const std::string& not_ready, int signal, int times = 1) {
  return RunAndSignalWhen(work, std::move(args), ready, not_ready,
                          Signalling{.signal = signal, .times = times});
}

// The same, signalled once the chains have written a checkpoint in `checkpoints` (so they run,
// under the graceful stop's handlers).
inline SignalledRun RunAndSignalOnceCheckpointed(const std::filesystem::path& work,
                                                 std::vector<std::string> args,
                                                 const std::filesystem::path& checkpoints,
                                                 int signal, int times = 1) {
  const auto checkpointed = [&] {
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator(checkpoints, ec))
      if (!entry.path().filename().string().starts_with(".")) return true;
    return false;
  };
  return RunAndSignalWhen(work, std::move(args), checkpointed, "no checkpoint after 30 s", signal,
                          times);
}

// How a process with `wait_status` ended, for a failure's message.
inline std::string HowItEnded(int wait_status) {
  if (WIFEXITED(wait_status))
    return "exited with status " + std::to_string(WEXITSTATUS(wait_status));
  if (WIFSIGNALED(wait_status)) return "ended by signal " + std::to_string(WTERMSIG(wait_status));
  return "still running";
}

// `run` ended by itself, stopped by `signal` with the shell's status for it (128 + its number),
// and printed `out`.
inline void ExpectStoppedBy(const SignalledRun& run, int signal, const std::string& out) {
  ASSERT_TRUE(WIFEXITED(run.wait_status))
      << "ended by signal " << (WIFSIGNALED(run.wait_status) ? WTERMSIG(run.wait_status) : 0)
      << "; stderr:\n"
      << run.err;
  EXPECT_EQ(WEXITSTATUS(run.wait_status), 128 + signal) << run.err;
  EXPECT_EQ(run.out, out);
}

// Every file under `dir` with its content, to see that a refused command left them as they were.
inline std::map<std::string, std::string> FilesAndContents(const std::filesystem::path& dir) {
  std::map<std::string, std::string> files;
  for (const std::string& file : FilesUnder(dir))
    if (std::filesystem::is_regular_file(dir / file)) files[file] = ReadAll(dir / file);
  return files;
}

// No write in progress left its temporary file under `dir` (a run stopped by a signal).
inline void ExpectNoTemporaryFile(const std::filesystem::path& dir) {
  for (const std::string& file : FilesUnder(dir))
    EXPECT_THAT(file, ::testing::Not(::testing::HasSubstr(".tmp-")));
}

/// `summary` without what depends on the session rather than on the study: the times (keys
/// holding "time" or "seconds"), the proposals of this session and the steps it resumed.
inline nlohmann::json WithoutSessionKeys(const nlohmann::json& summary) {
  if (summary.is_array()) {
    nlohmann::json out = nlohmann::json::array();
    for (const nlohmann::json& item : summary) out.push_back(WithoutSessionKeys(item));
    return out;
  }
  if (!summary.is_object()) return summary;
  nlohmann::json out = nlohmann::json::object();
  for (const auto& [key, value] : summary.items()) {
    if (key.find("time") != std::string::npos || key.find("seconds") != std::string::npos ||
        key == "proposals" || key == "proposals_per_second" || key == "resumed_steps")
      continue;
    out[key] = WithoutSessionKeys(value);
  }
  return out;
}

}  // namespace priormap::testing
