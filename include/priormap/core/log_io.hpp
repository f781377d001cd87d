#pragma once
/// Format-independent entry points: read any supported log, write by file extension.

#include <filesystem>
#include <optional>
#include <string_view>

#include <priormap/core/carmen_io.hpp>
#include <priormap/core/json_io.hpp>

namespace priormap {

enum class LogFormat : std::uint8_t { kCarmen, kJson };

[[nodiscard]] const char* ToString(LogFormat format);
[[nodiscard]] std::optional<LogFormat> LogFormatFromString(std::string_view name);

/// The format of a file's content: JSON when its first non-blank byte is '{', else CARMEN.
[[nodiscard]] LogFormat SniffLogFormat(std::string_view text);
/// The format implied by a file name: .json / .json.gz are JSON, everything else CARMEN.
[[nodiscard]] LogFormat LogFormatFromPath(const std::filesystem::path& path);

/// Reads a log in any supported format (`format` forces one). CARMEN options apply to CARMEN only.
[[nodiscard]] Result<Log> ReadLog(const std::filesystem::path& path,
                                  std::optional<LogFormat> format = std::nullopt,
                                  const CarmenReadOptions& carmen_options = {});

/// Writes `log` in `format`, atomically.
void WriteLog(const Log& log, const std::filesystem::path& path, LogFormat format);

}  // namespace priormap
