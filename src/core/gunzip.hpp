#pragma once
// Whole-file reading for the log readers: the file in one read, and gzip data inflated in one
// call per member by libdeflate (under half of zlib's time on a CARMEN log), with ReadFileText's
// contract and diagnostics. Without libdeflate at build time, ReadFileText (zlib) does it.

#include <filesystem>
#include <string>

#include <priormap/core/diagnostic.hpp>

#include "byte_buffer.hpp"

namespace priormap::detail {

/// The bytes of `path`, decompressed when they start with gzip's magic bytes (whatever the
/// name), as ReadFileText: concatenated members are read whole, anything after the last member
/// that is not a gzip member is ignored (as zlib's gzread does), and a corrupt or truncated
/// member is a diagnostic.
[[nodiscard]] Result<ByteBuffer> ReadWholeFile(const std::filesystem::path& path);

/// "cannot open file for reading", with the system's reason when errno holds one (read at once):
/// the diagnostic of both ReadWholeFile and ReadFileText.
[[nodiscard]] Diagnostic CannotOpenForReading(const std::string& name);

}  // namespace priormap::detail
