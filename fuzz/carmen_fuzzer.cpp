// libFuzzer harness for the CARMEN reader. Besides crashes and sanitizer reports it checks that
// an accepted log is consistent and is written back (as CARMEN and as JSON) so that reading it
// again gives the same log.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include <priormap/core/carmen_io.hpp>
#include <priormap/core/json_io.hpp>

#include "fuzz_check.hpp"

using priormap::fuzz::Check;

namespace {

bool IsUtf8(const std::string& text) {
  try {
    (void)nlohmann::json(text).dump();
    return true;
  } catch (const nlohmann::json::type_error&) {
    return false;
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  priormap::CarmenReadOptions options;
  options.max_diagnostics = 5;
  priormap::CarmenReadStats stats;
  const priormap::Result<priormap::Log> log =
      priormap::ParseCarmenLog(text, "fuzz.log", options, &stats);
  if (!log.ok()) {
    Check(!log.diagnostics().empty(), "a failed read has diagnostics");
    return 0;
  }
  const std::vector<std::string> problems = log.value().Problems();
  Check(problems.empty(), "an accepted log is consistent",
        problems.empty() ? "" : problems.front());

  // CARMEN -> CARMEN: the text is a fixpoint after one round.
  const std::string carmen = priormap::FormatCarmenLog(log.value());
  const priormap::Result<priormap::Log> again = priormap::ParseCarmenLog(carmen, "again.log");
  Check(again.ok(), "written CARMEN is read back", again.ok() ? carmen : again.error());
  Check(priormap::FormatCarmenLog(again.value()) == carmen, "CARMEN round trip keeps the log",
        carmen);
  const std::string json = priormap::FormatJsonLog(log.value());
  Check(priormap::FormatJsonLog(again.value()) == json, "CARMEN round trip keeps every field",
        json);

  // CARMEN -> JSON -> the same log (JSON replaces bytes that are not UTF-8 with U+FFFD).
  const priormap::Result<priormap::Log> from_json = priormap::ParseJsonLog(json, "fuzz.json");
  Check(from_json.ok(), "written JSON is read back", from_json.ok() ? json : from_json.error());
  Check(priormap::FormatJsonLog(from_json.value()) == json, "JSON round trip keeps the log", json);
  if (IsUtf8(carmen)) {
    Check(priormap::FormatCarmenLog(from_json.value()) == carmen, "JSON round trip keeps CARMEN",
          json);
  }
  return 0;
}
