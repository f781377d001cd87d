#include "directory_lock.hpp"

#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>
#include <utility>

#include <fmt/format.h>

#include "cli_support.hpp"

namespace priormap::app {
namespace {

// The process that holds a flock of the file `fd` is open on, as /proc/locks lists it (Linux: "1:
// FLOCK  ADVISORY  WRITE 1234 08:01:5678 0 EOF", the device's major and minor in hexadecimal);
// none where that cannot be told (no /proc, a process of another PID namespace).
std::optional<long> LockHolder(int fd) {
  struct stat status {};
  if (::fstat(fd, &status) != 0) return std::nullopt;
  const std::string file =
      fmt::format("{:02x}:{:02x}:{}", major(status.st_dev), minor(status.st_dev), status.st_ino);
  std::ifstream locks("/proc/locks");
  for (std::string line; std::getline(locks, line);) {
    std::istringstream fields(line);
    std::string id, type, mode, access, device;
    long pid = 0;
    // A process waiting for the lock is listed as "1: -> FLOCK ...": it does not hold it.
    if (fields >> id >> type >> mode >> access >> pid >> device && type == "FLOCK" &&
        device == file && pid > 0)
      return pid;
  }
  return std::nullopt;
}

// Its command's name ("priormap"), where /proc tells it.
std::string ProcessName(long pid) {
  std::ifstream comm(fmt::format("/proc/{}/comm", pid));
  std::string name;
  std::getline(comm, name);
  return name;
}

}  // namespace

DirectoryLock::DirectoryLock(const std::filesystem::path& directory) {
  fd_ = ::open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd_ < 0)
    throw UserError(
        fmt::format("cannot open directory {}: {}", directory.string(), std::strerror(errno)));
  if (::flock(fd_, LOCK_EX | LOCK_NB) == 0) return;
  const int error = errno;
  const std::optional<long> holder = error == EWOULDBLOCK ? LockHolder(fd_) : std::nullopt;
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
  if (error == EWOULDBLOCK && holder) {
    // Named, so that a run left in the background (or stopped with Ctrl-Z) can be found.
    const std::string name = ProcessName(*holder);
    throw UserError(fmt::format(
        "-o {0}: another priormap is running there (process {2}{1} holds the directory's lock); "
        "wait for it to end or stop it (Ctrl-C where it runs, or kill -TERM {2}, stops it "
        "checkpointed; one stopped with Ctrl-Z needs kill -CONT {2} as well)",
        directory.string(), name.empty() || name == "priormap" ? "" : fmt::format(", {},", name),
        *holder));
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
