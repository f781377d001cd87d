#pragma once
/// Reading whole files (plain or gzip-compressed) and writing files atomically.

#include <filesystem>
#include <functional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <priormap/core/diagnostic.hpp>

namespace priormap {

/// A file could not be written (disk full, no permission, ...).
class IoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The bytes of `path`, decompressed when it is gzip data (recognised by its magic bytes, so
/// the name need not end in .gz). Concatenated gzip members are one stream, as gzip(1) reads
/// them. Diagnostics for missing files, corrupt or truncated gzip members, and bytes after the
/// last member that do not start another (at their byte offset).
[[nodiscard]] Result<std::string> ReadFileText(const std::filesystem::path& path);

/// Calls `write(temporary_path)`, which must create that file, then renames it to `path`, so
/// readers never see a half-written file and a failure leaves any previous `path` untouched.
/// The temporary file lives next to `path`. A `path` that is a symbolic link is written through
/// to the file it names, and a file replaced keeps its permissions. First removes the stale
/// temporary files of earlier writes of that file (RemoveStaleTemporaryFiles), and only those.
/// Throws IoError; exceptions from `write` propagate after the temporary file is removed.
void WriteFileAtomically(const std::filesystem::path& path,
                         const std::function<void(const std::filesystem::path&)>& write);

/// WriteFileAtomically with `content` as the file's bytes; gzip-compressed when `path` ends in .gz.
void WriteTextFileAtomically(const std::filesystem::path& path, std::string_view content);

/// Removes the temporary files of the WriteFileAtomically calls in progress, for a signal handler
/// that is about to end the process (which would leave them behind). Async-signal-safe: it calls
/// only unlink(2). The writes in progress then fail, as their temporary file is gone.
void RemoveTemporaryFilesInProgress() noexcept;

/// Removes the temporary files that WriteFileAtomically left behind in `directory` (named
/// ".NAME.tmp-PID-N") for outputs whose NAME `is_output` accepts, when their writer can no longer
/// be writing them: process PID is gone (it was killed mid-write: SIGKILL, a crash, a power loss),
/// or PID is this process's and none of its writes has that file in progress (an earlier process
/// had the same PID). The temporaries of a running process are kept, as is every other file: the
/// directory need not be locked against other writers. (A process of another PID namespace or
/// host writing there is not seen as running.) Best effort: errors are ignored. Returns the files
/// removed.
std::vector<std::filesystem::path> RemoveStaleTemporaryFiles(
    const std::filesystem::path& directory,
    const std::function<bool(std::string_view name)>& is_output);

/// The UTF-8 byte order mark some editors put at the start of a text file; readers skip it.
inline constexpr std::string_view kUtf8ByteOrderMark = "\xef\xbb\xbf";

/// 1-based line and column of byte `offset` in `text`.
struct TextPosition {
  int line = 1;
  int col = 1;
};
[[nodiscard]] TextPosition PositionOfOffset(std::string_view text, std::size_t offset);

/// Whether `name` is `prefix`, one or more decimal digits, then `suffix`: a file of a numbered
/// series that a command writes (and may remove before writing another). Unless
/// `allow_leading_zeros`, the number has no leading zero ("chain0.png", "chain12.png", not
/// "chain012.png").
[[nodiscard]] bool IsNumberedName(std::string_view name, std::string_view prefix,
                                  std::string_view suffix, bool allow_leading_zeros);

}  // namespace priormap
