#pragma once
// A fresh directory per test, removed afterwards; what a directory holds; and the location of the
// shared real logs.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace priormap::testing {

class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  [[nodiscard]] const std::filesystem::path& path() const { return path_; }
  [[nodiscard]] std::filesystem::path operator/(const std::string& name) const {
    return path_ / name;
  }

 private:
  std::filesystem::path path_;
};

/// The names of the entries of `dir` (not recursive), sorted.
std::vector<std::string> FilesIn(const std::filesystem::path& dir);

/// Whether `dir` holds a temporary file of an atomic write (".<name>.tmp-<suffix>") that was left
/// behind.
bool HasTemporaryFile(const std::filesystem::path& dir);

/// ../shared/data (PRIORMAP_SHARED_DATA_DIR) when it exists; tests then GTEST_SKIP otherwise.
std::optional<std::filesystem::path> SharedDataDir();

/// The whole content of a file (test helper; throws on failure).
std::string ReadAll(const std::filesystem::path& path);
void WriteAll(const std::filesystem::path& path, const std::string& content);

}  // namespace priormap::testing
