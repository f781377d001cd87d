#pragma once
// A fresh directory per test, removed afterwards; and the location of the shared real logs.

#include <filesystem>
#include <optional>
#include <string>

namespace priormap::testing {

class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  [[nodiscard]] const std::filesystem::path& path() const { return path_; }
  [[nodiscard]] std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

/// ../shared/data (PRIORMAP_SHARED_DATA_DIR) when it exists; tests then GTEST_SKIP otherwise.
std::optional<std::filesystem::path> SharedDataDir();

/// The whole content of a file (test helper; throws on failure).
std::string ReadAll(const std::filesystem::path& path);
void WriteAll(const std::filesystem::path& path, const std::string& content);

}  // namespace priormap::testing
