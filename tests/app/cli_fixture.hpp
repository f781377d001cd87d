#pragma once
// The fixture of the end-to-end tests: runs the priormap binary in a fresh working directory
// (its current directory), capturing stdout and stderr in files of a separate directory, so
// that the working directory holds only what priormap wrote; a run stopped by a signal; a
// summary without what depends on the session, to compare a resumed study with an uninterrupted
// one.
#include <csignal>
#include <fcntl.h>
#include <filesystem>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <sys/types.h>
#include <sys/wait.h>
#include <system_error>
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

// Starts priormap with `args` in `work`, signals it with `signal` (`times` times, 10 ms apart)
// once `ready()` holds (polled every 25 ms for at most 30 s; `not_ready` is the failure after
// that), and waits for it.
struct SignalledRun {
  int wait_status = 0;
  std::string out;
  std::string err;
};
inline SignalledRun RunAndSignalWhen(const std::filesystem::path& work,
                                     std::vector<std::string> args,
                                     const std::function<bool()>& ready,
                                     const std::string& not_ready, int signal, int times = 1) {
  const testing::TempDir io;
  const std::string program = PRIORMAP_BINARY;
  std::vector<char*> argv = {const_cast<char*>(program.c_str())};
  for (std::string& arg : args) argv.push_back(arg.data());
  argv.push_back(nullptr);
  const int out = ::open((io / "stdout").c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  const int err = ::open((io / "stderr").c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  SignalledRun run;
  if (out < 0 || err < 0) {
    ADD_FAILURE() << "cannot create the output files";
    return run;
  }
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (::chdir(work.c_str()) != 0 || ::dup2(out, 1) < 0 || ::dup2(err, 2) < 0) ::_exit(127);
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
  for (int k = 0; k < times; ++k) {
    if (k > 0) ::usleep(10000);  // 10 ms apart: one request delivered twice
    ::kill(pid, signal);
  }
  ::waitpid(pid, &run.wait_status, 0);
  run.out = testing::ReadAll(io / "stdout");
  run.err = testing::ReadAll(io / "stderr");
  return run;
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
