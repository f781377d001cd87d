#include <algorithm>

#include <priormap/core/file_io.hpp>
#include <priormap/core/log_io.hpp>

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
  Result<std::string> text = ReadFileText(path);
  if (!text) return text.diagnostics();
  switch (format.value_or(SniffLogFormat(text.value()))) {
    case LogFormat::kJson:
      return ParseJsonLog(text.value(), path.string());
    case LogFormat::kCarmen:
      return ParseCarmenLog(text.value(), path.string(), carmen_options);
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
