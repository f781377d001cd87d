#include <algorithm>

#include <priormap/core/log_io.hpp>

#include "gunzip.hpp"

namespace priormap {

const char* ToString(LogFormat format) {
  switch (format) {
    case LogFormat::kCarmen:
      return "carmen";
    case LogFormat::kJson:
      return "json";
  }
  return "?";
}

std::optional<LogFormat> LogFormatFromString(std::string_view name) {
  if (name == "carmen") return LogFormat::kCarmen;
  if (name == "json") return LogFormat::kJson;
  return std::nullopt;
}

LogFormat SniffLogFormat(std::string_view text) {
  const auto first = std::find_if(text.begin(), text.end(), [](char c) {
    return c != ' ' && c != '\n' && c != '\r' && c != '\t';
  });
  return first != text.end() && *first == '{' ? LogFormat::kJson : LogFormat::kCarmen;
}

LogFormat LogFormatFromPath(const std::filesystem::path& path) {
  std::filesystem::path p = path;
  if (p.extension() == ".gz") p = p.stem();
  return p.extension() == ".json" ? LogFormat::kJson : LogFormat::kCarmen;
}

Result<Log> ReadLog(const std::filesystem::path& path, std::optional<LogFormat> format,
                    const CarmenReadOptions& carmen_options) {
  const Result<detail::ByteBuffer> bytes = detail::ReadWholeFile(path);
  if (!bytes) return bytes.diagnostics();
  const std::string_view text = bytes.value().view();
  switch (format.value_or(SniffLogFormat(text))) {
    case LogFormat::kJson:
      return ParseJsonLog(text, path.string());
    case LogFormat::kCarmen:
      return ParseCarmenLog(text, path.string(), carmen_options);
  }
  return Diagnostic{path.string(), 0, 0, "unknown log format"};
}

void WriteLog(const Log& log, const std::filesystem::path& path, LogFormat format) {
  switch (format) {
    case LogFormat::kJson:
      return WriteJsonLog(log, path);
    case LogFormat::kCarmen:
      return WriteCarmenLog(log, path);
  }
}

}  // namespace priormap
