#include <algorithm>
#include <cctype>
#include <string>

#include <fmt/format.h>

#include <priormap/core/file_io.hpp>
#include <priormap/core/log_io.hpp>

#include "gunzip.hpp"

namespace priormap {

const char* ToString(LogFormat format) {
  switch (format) {
    case LogFormat::kCarmen:
      return "carmen";
    case LogFormat::kJson:
      return "json";
    case LogFormat::kCsm:
      return "csm";
  }
  return "?";
}

std::optional<LogFormat> LogFormatFromString(std::string_view name) {
  if (name == "carmen") return LogFormat::kCarmen;
  if (name == "json") return LogFormat::kJson;
  if (name == "csm") return LogFormat::kCsm;
  return std::nullopt;
}

LogFormat SniffLogFormat(std::string_view text) {
  if (text.starts_with(kUtf8ByteOrderMark)) text.remove_prefix(kUtf8ByteOrderMark.size());
  const auto first = std::find_if(text.begin(), text.end(), [](char c) {
    return c != ' ' && c != '\n' && c != '\r' && c != '\t';
  });
  // A CARMEN line starts with a record's name; JSON that is not an object goes to the JSON reader,
  // which says what it expected where, rather than to CARMEN's "no records found".
  if (first != text.end() && *first == '[') return LogFormat::kJson;
  if (first == text.end() || *first != '{') return LogFormat::kCarmen;
  return LooksLikeCsmLog(text) ? LogFormat::kCsm : LogFormat::kJson;
}

std::optional<LogFormat> LogFormatFromPath(const std::filesystem::path& path) {
  const auto lower = [](std::string text) {
    std::ranges::transform(text, text.begin(), [](unsigned char c) { return std::tolower(c); });
    return text;
  };
  std::filesystem::path p = path;
  if (lower(p.extension().string()) == ".gz") p = p.stem();
  const std::string extension = lower(p.extension().string());
  if (extension == ".json") return LogFormat::kJson;
  if (extension == ".log" || extension == ".clf" || extension == ".carmen" || extension == ".txt")
    return LogFormat::kCarmen;
  return std::nullopt;
}

Result<Log> ReadLog(const std::filesystem::path& path, std::optional<LogFormat> format,
                    const CarmenReadOptions& carmen_options, LogFormat* read_as) {
  const Result<detail::ByteBuffer> bytes = detail::ReadWholeFile(path);
  if (!bytes) return bytes.diagnostics();
  const std::string_view text = bytes.value().view();
  const LogFormat chosen = format.value_or(SniffLogFormat(text));
  if (read_as) *read_as = chosen;
  switch (chosen) {
    case LogFormat::kJson:
      return ParseJsonLog(text, path.string());
    case LogFormat::kCarmen:
      return ParseCarmenLog(text, path.string(), carmen_options);
    case LogFormat::kCsm:
      return ParseCsmLog(text, path.string());
  }
  return Diagnostic{path.string(), 0, 0, "unknown log format"};
}

void WriteLog(const Log& log, const std::filesystem::path& path, LogFormat format) {
  switch (format) {
    case LogFormat::kJson:
      return WriteJsonLog(log, path);
    case LogFormat::kCarmen:
      return WriteCarmenLog(log, path);
    case LogFormat::kCsm:
      throw IoError(
          fmt::format("{}: cannot write CSM laser_data (priormap reads it only); write "
                      "priormap JSON or CARMEN",
                      path.string()));
  }
}

}  // namespace priormap
