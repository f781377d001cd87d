#pragma once
// Runs `priormap` subcommands inside this process, exactly as the command line would (the demo's
// steps), with their standard output appended to a log file.

#include <filesystem>
#include <string>
#include <vector>

namespace priormap::app {

class InProcessRunner {
 public:
  /// The commands' standard output (and error) is appended to `log`.
  explicit InProcessRunner(std::filesystem::path log);

  /// Runs `priormap <args...>`; returns its wall time in seconds. A command that fails throws
  /// UserError naming it and pointing at the log.
  double Run(const std::vector<std::string>& args);

  /// "priormap a b 'c d'", as a shell would take it.
  [[nodiscard]] static std::string CommandLine(const std::vector<std::string>& args);

 private:
  std::filesystem::path log_;
};

}  // namespace priormap::app
