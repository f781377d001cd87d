#include "in_process.hpp"

#include <chrono>
#include <cstdio>
#include <exception>
#include <fcntl.h>
#include <unistd.h>

#include <fmt/format.h>

#include "cli_support.hpp"
#include "commands.hpp"

namespace priormap::app {
namespace {

// Points the process's stdout and stderr at a file for its lifetime, then back; a command's
// progress bars and tables go to the demo's log instead of burying the demo's own lines.
class RedirectedOutput {
 public:
  explicit RedirectedOutput(const std::filesystem::path& file) {
    std::fflush(stdout);
    std::fflush(stderr);
    const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
    if (fd < 0) throw UserError(fmt::format("cannot open {} for writing", file.string()));
    saved_out_ = ::dup(STDOUT_FILENO);
    saved_err_ = ::dup(STDERR_FILENO);
    ::dup2(fd, STDOUT_FILENO);
    ::dup2(fd, STDERR_FILENO);
    ::close(fd);
  }
  RedirectedOutput(const RedirectedOutput&) = delete;
  RedirectedOutput& operator=(const RedirectedOutput&) = delete;
  ~RedirectedOutput() {
    std::fflush(stdout);
    std::fflush(stderr);
    ::dup2(saved_out_, STDOUT_FILENO);
    ::dup2(saved_err_, STDERR_FILENO);
    ::close(saved_out_);
    ::close(saved_err_);
  }

 private:
  int saved_out_ = -1;
  int saved_err_ = -1;
};

}  // namespace

InProcessRunner::InProcessRunner(std::filesystem::path log) : log_(std::move(log)) {}

std::string InProcessRunner::CommandLine(const std::vector<std::string>& args) {
  std::string line = "priormap";
  for (const std::string& arg : args) {
    const bool plain = !arg.empty() && arg.find_first_of(" \t'\"$\\*?;&|<>()") == std::string::npos;
    line += plain ? " " + arg : " '" + arg + "'";
  }
  return line;
}

double InProcessRunner::Run(const std::vector<std::string>& args) {
  const auto start = std::chrono::steady_clock::now();
  // A fresh app per command: CLI11 keeps parsed values in the app's options.
  CLI::App app{"priormap", "priormap"};
  app.require_subcommand(1);
  AddAllCommands(app);
  std::vector<std::string> argv_strings{"priormap"};
  argv_strings.insert(argv_strings.end(), args.begin(), args.end());
  std::vector<const char*> argv;
  for (const std::string& s : argv_strings) argv.push_back(s.c_str());
  std::string failure;
  {
    const RedirectedOutput redirected(log_);
    fmt::print("\n$ {}\n", CommandLine(args));
    std::fflush(stdout);  // before the command's stderr, which is not buffered
    try {
      app.parse(static_cast<int>(argv.size()), argv.data());
    } catch (const CLI::ParseError& e) {
      failure = e.what();
    } catch (const std::exception& e) {
      failure = e.what();
    }
    if (!failure.empty()) fmt::print(stderr, "failed: {}\n", failure);
  }
  if (!failure.empty())
    throw UserError(fmt::format("demo step failed: {}\n{}\n(the output of every step is in {})",
                                CommandLine(args), failure, log_.string()));
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace priormap::app
