#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <fstream>
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

fs::path TemporarySibling(const fs::path& path) {
  static std::atomic<unsigned> counter{0};
  const std::string name =
      fmt::format(".{}.tmp-{}-{}", path.filename().string(), ::getpid(), counter++);
  return path.parent_path() / name;
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
// would leave it behind, as it did before the registry.
class TemporaryRegistration {
 public:
  explicit TemporaryRegistration(const std::string& path) {
    if (path.empty() || path.size() >= kTemporaryPathBytes) return;
    for (TemporarySlot& slot : g_temporaries) {
      bool free = false;
      if (!slot.claimed.compare_exchange_strong(free, true, std::memory_order_acquire)) continue;
      SetSlotPath(slot, path);
      slot_ = &slot;
      return;
    }
  }
  ~TemporaryRegistration() {
    if (slot_ == nullptr) return;
    SetSlotPath(*slot_, "");
    slot_->claimed.store(false, std::memory_order_release);
  }
  TemporaryRegistration(const TemporaryRegistration&) = delete;
  TemporaryRegistration& operator=(const TemporaryRegistration&) = delete;

 private:
  TemporarySlot* slot_ = nullptr;
};

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
    const unsigned version = slot.version.load(std::memory_order_acquire);
    // Odd: the slot is being registered (its file not made yet) or released (its file renamed
    // or removed already).
    if (version % 2 != 0) continue;
    std::array<char, kTemporaryPathBytes> copy;
    std::size_t length = 0;
    while (length < copy.size() &&
           (copy[length] = slot.path[length].load(std::memory_order_relaxed)) != '\0')
      ++length;
    std::atomic_thread_fence(std::memory_order_acquire);
    if (length == 0 || length == copy.size() ||
        slot.version.load(std::memory_order_relaxed) != version)
      continue;
    ::unlink(copy.data());
  }
}

Result<std::string> ReadFileText(const fs::path& path) {
  const std::string name = path.string();
  std::error_code ec;
  if (!fs::exists(path, ec)) return Diagnostic{name, 0, 0, "no such file"};
  if (fs::is_directory(path, ec)) return Diagnostic{name, 0, 0, "is a directory, expected a file"};
  // gzread reads plain files unchanged, so one code path serves both.
  errno = 0;
  gzFile file = gzopen(name.c_str(), "rb");
  if (file == nullptr) return detail::CannotOpenForReading(name);
  gzbuffer(file, 1 << 17);
  std::string text;
  std::string chunk(1 << 20, '\0');
  for (;;) {
    const int n = gzread(file, chunk.data(), static_cast<unsigned>(chunk.size()));
    if (n < 0) break;
    text.append(chunk.data(), static_cast<std::size_t>(n));
    if (n == 0) break;
  }
  int error = Z_OK;
  const char* message = gzerror(file, &error);
  const std::string error_text = message ? message : "";
  gzclose(file);
  if (error != Z_OK && error != Z_STREAM_END) {
    return Diagnostic{name, 0, 0, fmt::format("corrupt or truncated gzip data ({})", error_text)};
  }
  return text;
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
