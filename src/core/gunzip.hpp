#pragma once
// Whole-file reading for the log readers: the file in one read, and gzip data inflated in one
// call per member by libdeflate (under half of zlib's time on a CARMEN log), with ReadFileText's
// contract and diagnostics. Without libdeflate at build time, ReadFileText (zlib) does it.

#include <filesystem>
#include <string>
#include <string_view>

#include <priormap/core/diagnostic.hpp>

#include "byte_buffer.hpp"

namespace priormap::detail {

/// The bytes of `path`, decompressed when they start with gzip's magic bytes (whatever the
/// name), as ReadFileText: concatenated members are one stream, as gzip(1) reads them; a
/// corrupt or truncated member, or bytes after the last member that do not start another one,
/// are a diagnostic (TrailingGzipData).
[[nodiscard]] Result<ByteBuffer> ReadWholeFile(const std::filesystem::path& path);

/// `bytes`, which start with a gzip member, inflated by zlib with ReadWholeFile's contract:
/// ReadFileText's inflation, and ReadWholeFile's without libdeflate.
[[nodiscard]] Result<std::string> GunzipWithZlib(std::string_view bytes, const std::string& name);

/// The diagnostic of bytes after the last gzip member of a file of `file_size` bytes that are
/// not a member, from byte `offset` (0-based: the size of what is gzip data): ignoring them
/// would hide data (a second file appended, a member whose header was damaged) or garbage.
/// The one diagnostic of ReadWholeFile and ReadFileText.
[[nodiscard]] Diagnostic TrailingGzipData(const std::string& name, std::size_t offset,
                                          std::size_t file_size);

/// "cannot open file for reading", with the system's reason when errno holds one (read at once):
/// the diagnostic of both ReadWholeFile and ReadFileText.
[[nodiscard]] Diagnostic CannotOpenForReading(const std::string& name);

}  // namespace priormap::detail
