#pragma once
// Running a program of the build (the priormap executable) from end-to-end tests.

#include <filesystem>
#include <set>
#include <string>
#include <vector>

namespace priormap::testing {

struct ProcessResult {
  int status = -1;  ///< exit status; -1 when the process did not exit normally
  std::string out;
  std::string err;
};

/// `s` quoted for a POSIX shell.
std::string ShellQuote(const std::string& s);

/// Runs `program` with `args` in the working directory `work`, capturing stdout and stderr in
/// files of `io` (a separate directory, so that `work` holds only what the program wrote).
ProcessResult RunProgram(const std::filesystem::path& program, const std::filesystem::path& work,
                         const std::filesystem::path& io, const std::vector<std::string>& args);

/// Every file and directory under `dir`, relative to it.
std::set<std::string> FilesUnder(const std::filesystem::path& dir);

}  // namespace priormap::testing
