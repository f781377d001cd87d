#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <fstream>
#include <limits>
#include <memory>
#include <optional>
#include <unistd.h>

#include <fmt/format.h>
#include <zlib.h>

#include <priormap/core/file_io.hpp>

#include "gunzip.hpp"

namespace priormap {
namespace fs = std::filesystem;
namespace {

bool EndsWithGz(const fs::path& path) {
  std::string extension = path.extension().string();
  std::ranges::transform(extension, extension.begin(),
                         [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension == ".gz";
}

// The file `path` names once its links are followed, even a link to a file not yet made (which
// weakly_canonical would leave as the link itself). A loop of links is an error.
fs::path FollowLinks(const fs::path& path) {
  fs::path target = path;
  std::error_code ec;
  for (int hops = 0; fs::is_symlink(target, ec); ++hops) {
    if (hops == 40)
      throw IoError(fmt::format("{}: cannot write: too many levels of links", path.string()));
    const fs::path next = fs::read_symlink(target, ec);
    if (ec) throw IoError(fmt::format("{}: cannot write: {}", path.string(), ec.message()));
    target = next.is_absolute() ? next : target.parent_path() / next;
  }
  return target;
}

constexpr std::string_view kTemporaryMarker = ".tmp-";

fs::path TemporarySibling(const fs::path& path) {
  static std::atomic<unsigned> counter{0};
  const std::string name =
      fmt::format(".{}{}{}-{}", path.filename().string(), kTemporaryMarker, ::getpid(), counter++);
  return path.parent_path() / name;
}

// What a name made by TemporarySibling says: the output's name and the writing process.
struct TemporaryName {
  std::string_view output;
  pid_t pid = 0;
};

std::optional<TemporaryName> ParseTemporaryName(std::string_view name) {
  const std::size_t marker = name.rfind(kTemporaryMarker);
  if (!name.starts_with('.') || marker == std::string_view::npos || marker < 2) return {};
  const std::string_view numbers = name.substr(marker + kTemporaryMarker.size());
  const std::size_t dash = numbers.find('-');
  if (dash == std::string_view::npos) return {};
  const std::string_view pid = numbers.substr(0, dash);
  const std::string_view counter = numbers.substr(dash + 1);
  if (!IsNumberedName(pid, "", "", false) || !IsNumberedName(counter, "", "", false)) return {};
  // Only the PIDs getpid() gives: kill() of 0 or of a negative number would name groups.
  long long value = 0;
  const std::from_chars_result parsed = std::from_chars(pid.data(), pid.data() + pid.size(), value);
  if (parsed.ec != std::errc() || value < 1 || value > std::numeric_limits<pid_t>::max()) return {};
  return TemporaryName{name.substr(1, marker - 1), static_cast<pid_t>(value)};
}

// Whether process `pid` exists (one of another user's too).
bool ProcessRuns(pid_t pid) {
  return ::kill(pid, 0) == 0 || errno == EPERM;
}

// The temporary files being written, for RemoveTemporaryFilesInProgress, which a signal handler
// calls: fixed storage and atomics only, as a handler may neither lock nor allocate, and may run
// on any thread while others register and release slots.
constexpr std::size_t kTemporarySlots = 64;
constexpr std::size_t kTemporaryPathBytes = 4096;  // Linux's PATH_MAX

struct TemporarySlot {
  std::atomic<bool> claimed{false};
  // A sequence lock: odd while `path` changes. The handler unlinks a copy of `path` only when it
  // saw the same even version before and after copying, so never a half-written path.
  std::atomic<unsigned> version{0};
  std::array<std::atomic<char>, kTemporaryPathBytes> path{};
};
static_assert(std::atomic<bool>::is_always_lock_free &&
              std::atomic<unsigned>::is_always_lock_free && std::atomic<char>::is_always_lock_free);

std::array<TemporarySlot, kTemporarySlots> g_temporaries;
// Writes in progress whose temporary file found no slot: RemoveStaleTemporaryFiles cannot tell
// this process's files apart while there are any.
std::atomic<int> g_unregistered{0};

void SetSlotPath(TemporarySlot& slot, std::string_view path) {
  const unsigned version = slot.version.load(std::memory_order_relaxed);
  slot.version.store(version + 1, std::memory_order_relaxed);
  std::atomic_thread_fence(std::memory_order_release);
  for (std::size_t i = 0; i < path.size(); ++i)
    slot.path[i].store(path[i], std::memory_order_relaxed);
  slot.path[path.size()].store('\0', std::memory_order_relaxed);
  slot.version.store(version + 2, std::memory_order_release);
}

// Holds `path` in the registry while it lives. Registered before the file exists and released
// after it is renamed or removed, so a signal in between finds it. Without a free slot (more than
// kTemporarySlots writes at once) or for a longer path, the file is not registered: a signal
// would leave it behind, as it did before the registry; it is counted instead, so that
// RemoveStaleTemporaryFiles spares this process's temporaries meanwhile.
class TemporaryRegistration {
 public:
  explicit TemporaryRegistration(const std::string& path) {
    if (!path.empty() && path.size() < kTemporaryPathBytes) {
      for (TemporarySlot& slot : g_temporaries) {
        bool free = false;
        if (!slot.claimed.compare_exchange_strong(free, true, std::memory_order_acquire)) continue;
        SetSlotPath(slot, path);
        slot_ = &slot;
        return;
      }
    }
    ++g_unregistered;
  }
  ~TemporaryRegistration() {
    if (slot_ == nullptr) {
      --g_unregistered;
      return;
    }
    SetSlotPath(*slot_, "");
    slot_->claimed.store(false, std::memory_order_release);
  }
  TemporaryRegistration(const TemporaryRegistration&) = delete;
  TemporaryRegistration& operator=(const TemporaryRegistration&) = delete;

 private:
  TemporarySlot* slot_ = nullptr;
};

// The path in `slot`, copied whole (empty when it is being changed).
std::string_view CopySlotPath(const TemporarySlot& slot,
                              std::array<char, kTemporaryPathBytes>& copy) {
  const unsigned version = slot.version.load(std::memory_order_acquire);
  if (version % 2 != 0) return {};
  std::size_t length = 0;
  while (length < copy.size() &&
         (copy[length] = slot.path[length].load(std::memory_order_relaxed)) != '\0')
    ++length;
  std::atomic_thread_fence(std::memory_order_acquire);
  if (length == copy.size() || slot.version.load(std::memory_order_relaxed) != version) return {};
  return {copy.data(), length};
}

// Whether a write of this process may have a temporary file named `name` in progress. A file
// that exists while its write is in progress has its slot registered, unchanging, from before
// the file was made until after it is renamed or removed: a slot being changed holds another.
bool MayBeWriting(std::string_view name) {
  if (g_unregistered.load() > 0) return true;
  std::array<char, kTemporaryPathBytes> copy;
  for (const TemporarySlot& slot : g_temporaries) {
    const std::string_view path = CopySlotPath(slot, copy);
    if (!path.empty() && fs::path(path).filename().native() == name) return true;
  }
  return false;
}

// Puts the bytes of `file` on the disk before it is renamed over `path`: otherwise a crash or a
// power loss shortly after the rename can leave `path` empty or truncated (the rename may reach
// the disk before the data), where the old file would at least have been whole.
void SyncFile(const fs::path& path, const fs::path& file) {
  const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    const int error = errno;
    throw IoError(fmt::format("{}: cannot write: {}", path.string(), std::strerror(error)));
  }
  const int status = ::fsync(fd);
  const int error = errno;
  ::close(fd);
  if (status != 0)
    throw IoError(fmt::format("{}: cannot write: {}", path.string(), std::strerror(error)));
}

// Makes the rename itself durable. Best effort: the file is in place already, and some file
// systems cannot sync a directory.
void SyncDirectory(const fs::path& directory) {
  const int fd = ::open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

}  // namespace

void RemoveTemporaryFilesInProgress() noexcept {
  for (TemporarySlot& slot : g_temporaries) {
    // Empty while the slot changes: it is being registered (its file not made yet) or released
    // (its file renamed or removed already).
    std::array<char, kTemporaryPathBytes> copy;
    if (!CopySlotPath(slot, copy).empty()) ::unlink(copy.data());
  }
}

std::vector<fs::path> RemoveStaleTemporaryFiles(
    const fs::path& directory, const std::function<bool(std::string_view name)>& is_output) {
  std::vector<fs::path> stale;
  std::error_code ec;
  for (fs::directory_iterator it(directory, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    const std::optional<TemporaryName> temporary = ParseTemporaryName(name);
    if (!temporary || !is_output(temporary->output)) continue;
    // Never another process's file while it runs: it may be writing it now.
    const bool ours = temporary->pid == ::getpid();
    if (ours ? MayBeWriting(name) : ProcessRuns(temporary->pid)) continue;
    std::error_code status_error;
    if (it->symlink_status(status_error).type() == fs::file_type::regular)
      stale.push_back(it->path());
  }
  // Removed after the listing, which removing entries during it might skip or repeat.
  std::vector<fs::path> removed;
  for (const fs::path& file : stale)
    if (fs::remove(file, ec)) removed.push_back(file);
  return removed;
}

namespace {

// A write of `path` killed mid-way (SIGKILL, a crash: no handler runs) left its temporary file
// beside it, named with the killed writer's PID, so that no later write replaces it; this write
// replaces what that one was writing. Only `path`'s: the directory may hold the user's files, and
// other outputs' temporaries of a writer that still runs.
void RemoveStaleTemporariesOf(const fs::path& path, const fs::path& directory) {
  const std::string name = path.filename().string();
  (void)RemoveStaleTemporaryFiles(directory,
                                  [&](std::string_view output) { return output == name; });
}

}  // namespace

Result<std::string> ReadFileText(const fs::path& path) {
  const std::string name = path.string();
  std::error_code ec;
  if (!fs::exists(path, ec)) return Diagnostic{name, 0, 0, "no such file"};
  if (fs::is_directory(path, ec)) return Diagnostic{name, 0, 0, "is a directory, expected a file"};
  errno = 0;
  const std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(name.c_str(), "rb"),
                                                             &std::fclose);
  if (!file) return detail::CannotOpenForReading(name);
  // Read to the end, whatever the file is (a pipe, a growing file): its size is no promise.
  std::string bytes;
  std::string chunk(1 << 20, '\0');
  while (const std::size_t n = std::fread(chunk.data(), 1, chunk.size(), file.get()))
    bytes.append(chunk.data(), n);
  if (std::ferror(file.get())) return Diagnostic{name, 0, 0, "cannot read the file"};
  // gzip data by its magic bytes, whatever the name.
  if (!bytes.starts_with("\x1f\x8b")) return bytes;
  return detail::GunzipWithZlib(bytes, name);
}

void WriteFileAtomically(const fs::path& named, const std::function<void(const fs::path&)>& write) {
  std::error_code ec;
  // A device, a FIFO or a socket (/dev/null, /dev/stdout, a pipe), or a link to one, is written
  // in place: there is nothing to keep whole, and renaming over it would replace it by a plain
  // file.
  if (const fs::file_status status = fs::status(named, ec);
      !ec && fs::exists(status) && !fs::is_regular_file(status) && !fs::is_directory(status)) {
    write(named);
    return;
  }
  // A link is written through, to the file it names: renaming over the link itself would
  // replace it by a plain file and leave its target stale.
  const fs::path path = FollowLinks(named);
  const fs::path directory = path.parent_path().empty() ? fs::path(".") : path.parent_path();
  if (!fs::is_directory(directory, ec)) {
    if (fs::exists(directory, ec)) {
      throw IoError(fmt::format("{}: cannot write: {} is not a directory", path.string(),
                                directory.string()));
    }
    throw IoError(fmt::format("{}: cannot write: directory {} does not exist", path.string(),
                              directory.string()));
  }
  RemoveStaleTemporariesOf(path, directory);
  const fs::path temporary = TemporarySibling(path);
  const TemporaryRegistration registration(temporary.string());
  try {
    write(temporary);
    SyncFile(path, temporary);
    // A file replaced keeps its permissions (a private log stays private).
    const fs::file_status existing = fs::status(path, ec);
    if (!ec && fs::is_regular_file(existing)) fs::permissions(temporary, existing.permissions());
    fs::rename(temporary, path);
    SyncDirectory(directory);
  } catch (const fs::filesystem_error& e) {
    fs::remove(temporary, ec);
    throw IoError(fmt::format("{}: cannot write: {}", path.string(), e.code().message()));
  } catch (...) {
    fs::remove(temporary, ec);
    throw;
  }
}

namespace {

// Why `file` (the output itself, or its temporary sibling) could not be opened.
IoError CannotOpen(const fs::path& path, const fs::path& file) {
  const int error = errno;
  const fs::path directory = file.parent_path().empty() ? fs::path(".") : file.parent_path();
  return IoError(
      file == path
          ? fmt::format("{}: cannot open for writing: {}", path.string(), std::strerror(error))
          : fmt::format("{}: cannot create a file in {} to write it: {}", path.string(),
                        directory.string(), std::strerror(error)));
}

}  // namespace

void WriteTextFileAtomically(const fs::path& path, std::string_view content) {
  WriteFileAtomically(path, [&](const fs::path& temporary) {
    errno = 0;
    if (EndsWithGz(path)) {
      gzFile file = gzopen(temporary.string().c_str(), "wb");
      if (file == nullptr) throw CannotOpen(path, temporary);
      const bool ok =
          content.empty() || gzwrite(file, content.data(), static_cast<unsigned>(content.size())) ==
                                 static_cast<int>(content.size());
      if (gzclose(file) != Z_OK || !ok) {
        throw IoError(fmt::format("{}: write failed", path.string()));
      }
      return;
    }
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) throw CannotOpen(path, temporary);
    out.write(content.data(), static_cast<std::streamsize>(content.size()));
    out.close();
    if (!out) throw IoError(fmt::format("{}: write failed (disk full?)", path.string()));
  });
}

TextPosition PositionOfOffset(std::string_view text, std::size_t offset) {
  TextPosition position;
  offset = std::min(offset, text.size());
  for (std::size_t i = 0; i < offset; ++i) {
    if (text[i] == '\n') {
      ++position.line;
      position.col = 1;
    } else {
      ++position.col;
    }
  }
  return position;
}

bool IsNumberedName(std::string_view name, std::string_view prefix, std::string_view suffix,
                    bool allow_leading_zeros) {
  if (name.size() <= prefix.size() + suffix.size() || !name.starts_with(prefix) ||
      !name.ends_with(suffix))
    return false;
  const std::string_view number =
      name.substr(prefix.size(), name.size() - prefix.size() - suffix.size());
  if (!allow_leading_zeros && number.size() > 1 && number.front() == '0') return false;
  return std::ranges::all_of(number, [](char c) { return c >= '0' && c <= '9'; });
}

}  // namespace priormap
