#pragma once
/// Format-independent entry points: read any supported log, write by file extension.

#include <filesystem>
#include <optional>
#include <string_view>

#include <priormap/core/carmen_io.hpp>
#include <priormap/core/csm_io.hpp>
#include <priormap/core/json_io.hpp>

namespace priormap {

/// kCsm (CSM's laser_data JSON) is read only.
enum class LogFormat : std::uint8_t { kCarmen, kJson, kCsm };

[[nodiscard]] const char* ToString(LogFormat format);
[[nodiscard]] std::optional<LogFormat> LogFormatFromString(std::string_view name);

/// The format of a file's content: when its first non-blank byte is '{', CSM laser_data if that
/// object has "nrays" and "readings" members (LooksLikeCsmLog), else priormap JSON; else CARMEN.
[[nodiscard]] LogFormat SniffLogFormat(std::string_view text);
/// The format implied by a file name, in any letter case and with or without .gz: .json is JSON;
/// .log, .clf, .carmen and .txt are CARMEN; anything else (a figure's name, say) is nullopt, so
/// that a mistyped output name is not silently written as CARMEN.
[[nodiscard]] std::optional<LogFormat> LogFormatFromPath(const std::filesystem::path& path);

/// Reads a log in any supported format (`format` forces one, else SniffLogFormat). CARMEN options
/// apply to CARMEN only; CSM laser_data is read with the default CsmReadOptions. `read_as`, when
/// given, receives the format the file was read as. The reader's warnings (scans stamped out of
/// time order) come with the log (Result::warnings).
[[nodiscard]] Result<Log> ReadLog(const std::filesystem::path& path,
                                  std::optional<LogFormat> format = std::nullopt,
                                  const CarmenReadOptions& carmen_options = {},
                                  LogFormat* read_as = nullptr);

/// Writes `log` in `format`, atomically. There is no CSM writer: kCsm throws IoError.
void WriteLog(const Log& log, const std::filesystem::path& path, LogFormat format);

}  // namespace priormap
