#pragma once
/// Reading whole files (plain or gzip-compressed) and writing files atomically.

#include <filesystem>
#include <functional>
#include <stdexcept>
#include <string>
#include <string_view>

#include <priormap/core/diagnostic.hpp>

namespace priormap {

/// A file could not be written (disk full, no permission, ...).
class IoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The bytes of `path`, decompressed when it is gzip data (recognised by its magic bytes, so
/// the name need not end in .gz). Diagnostics for missing files and corrupt gzip streams.
[[nodiscard]] Result<std::string> ReadFileText(const std::filesystem::path& path);

/// Calls `write(temporary_path)`, which must create that file, then renames it to `path`, so
/// readers never see a half-written file and a failure leaves any previous `path` untouched.
/// The temporary file lives next to `path`. A `path` that is a symbolic link is written through
/// to the file it names, and a file replaced keeps its permissions. Throws IoError; exceptions
/// from `write` propagate after the temporary file is removed.
void WriteFileAtomically(const std::filesystem::path& path,
                         const std::function<void(const std::filesystem::path&)>& write);

/// WriteFileAtomically with `content` as the file's bytes; gzip-compressed when `path` ends in .gz.
void WriteTextFileAtomically(const std::filesystem::path& path, std::string_view content);

/// Removes the temporary files of the WriteFileAtomically calls in progress, for a signal handler
/// that is about to end the process (which would leave them behind). Async-signal-safe: it calls
/// only unlink(2). The writes in progress then fail, as their temporary file is gone.
void RemoveTemporaryFilesInProgress() noexcept;

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
