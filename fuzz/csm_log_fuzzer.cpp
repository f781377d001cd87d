// libFuzzer harness for the reader of CSM's laser_data JSON. Besides crashes and sanitizer
// reports it checks that a rejected stream gets one diagnostic located inside the text, and that
// an accepted one is a consistent log that our JSON writes and reads back unchanged.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include <priormap/core/csm_io.hpp>
#include <priormap/core/json_io.hpp>
#include <priormap/core/log_io.hpp>

#include "fuzz_check.hpp"

using priormap::fuzz::Check;
using priormap::fuzz::CheckLocated;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  // Sniffing looks at the first object only, and must not crash on anything.
  const priormap::LogFormat sniffed = priormap::SniffLogFormat(text);
  const priormap::Result<priormap::Log> log = priormap::ParseCsmLog(text, "fuzz.json");
  if (!log.ok()) {
    Check(log.diagnostics().size() == 1, "a failed read has one diagnostic");
    CheckLocated(log.diagnostics(), text, "fuzz.json");
    return 0;
  }
  Check(sniffed != priormap::LogFormat::kCarmen, "an accepted stream starts with an object");
  const std::vector<std::string> problems = log.value().Problems();
  Check(problems.empty(), "an accepted log is consistent",
        problems.empty() ? "" : problems.front());
  Check(!log.value().scans.empty(), "an accepted stream has scans");

  const std::string json = priormap::FormatJsonLog(log.value());
  const priormap::Result<priormap::Log> again = priormap::ParseJsonLog(json, "again.json");
  Check(again.ok(), "written JSON is read back", again.ok() ? json : again.error());
  Check(priormap::FormatJsonLog(again.value()) == json, "JSON round trip keeps the log", json);
  return 0;
}
