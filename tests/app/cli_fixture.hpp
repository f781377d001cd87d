#pragma once
// The fixture of the end-to-end tests: runs the priormap binary in a fresh working directory
// (its current directory), capturing stdout and stderr in files of a separate directory, so
// that the working directory holds only what priormap wrote.
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

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

}  // namespace priormap::testing
