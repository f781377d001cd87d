#pragma once
// An output directory in use: a `prf` run or a study holds its -o DIR locked (flock) while it
// runs, so that a second process there is refused instead of writing the same checkpoints and
// outputs. The kernel releases the lock when the process ends, however it ends.

#include <filesystem>

namespace priormap::app {

class DirectoryLock {
 public:
  DirectoryLock() = default;
  // Locks `directory`, which exists; throws UserError when another process holds it. Where the
  // file system has no such locks, warns and holds nothing.
  explicit DirectoryLock(const std::filesystem::path& directory);
  ~DirectoryLock();
  DirectoryLock(DirectoryLock&& other) noexcept;
  DirectoryLock& operator=(DirectoryLock&& other) noexcept;
  DirectoryLock(const DirectoryLock&) = delete;
  DirectoryLock& operator=(const DirectoryLock&) = delete;

  [[nodiscard]] bool held() const { return fd_ >= 0; }

 private:
  int fd_ = -1;
};

// The lock of `directory` when it exists (unheld otherwise): taken before a directory's contents
// are judged, so that a running process's checkpoints are not taken for a stopped one's.
[[nodiscard]] DirectoryLock LockIfExists(const std::filesystem::path& directory);

}  // namespace priormap::app
