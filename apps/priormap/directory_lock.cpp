#include "directory_lock.hpp"

#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>
#include <utility>

#include <fmt/format.h>

#include "cli_support.hpp"

namespace priormap::app {

DirectoryLock::DirectoryLock(const std::filesystem::path& directory) {
  fd_ = ::open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd_ < 0)
    throw UserError(
        fmt::format("cannot open directory {}: {}", directory.string(), std::strerror(errno)));
  if (::flock(fd_, LOCK_EX | LOCK_NB) == 0) return;
  const int error = errno;
  ::close(fd_);
  fd_ = -1;
  // Where the file system cannot lock a directory (NFS emulates flock with POSIX locks, which
  // need a descriptor open for writing), the run goes on unlocked rather than not at all.
  if (error == EBADF || error == ENOLCK || error == EOPNOTSUPP || error == EINVAL) {
    fmt::print(stderr,
               "priormap: warning: cannot lock {} ({}): a second run there is not refused\n",
               directory.string(), std::strerror(error));
    return;
  }
  if (error == EWOULDBLOCK)
    throw UserError(fmt::format(
        "-o {}: another priormap is running there (it holds the directory's lock); wait for it "
        "to end or stop it (Ctrl-C or SIGTERM stops it checkpointed)",
        directory.string()));
  throw UserError(
      fmt::format("cannot lock directory {}: {}", directory.string(), std::strerror(error)));
}

DirectoryLock::~DirectoryLock() {
  if (fd_ >= 0) ::close(fd_);  // which releases the lock
}

DirectoryLock::DirectoryLock(DirectoryLock&& other) noexcept : fd_(std::exchange(other.fd_, -1)) {}

DirectoryLock& DirectoryLock::operator=(DirectoryLock&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = std::exchange(other.fd_, -1);
  }
  return *this;
}

DirectoryLock LockIfExists(const std::filesystem::path& directory) {
  std::error_code ec;
  if (!std::filesystem::is_directory(directory, ec)) return {};
  return DirectoryLock(directory);
}

}  // namespace priormap::app
