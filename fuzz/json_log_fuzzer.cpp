// libFuzzer harness for the priormap.log / priormap.scan reader. Besides crashes and sanitizer
// reports it checks that an accepted log is consistent, that its JSON is a fixpoint after one
// round trip, and that the CARMEN writer either refuses the log or writes one that reads back.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include <priormap/core/carmen_io.hpp>
#include <priormap/core/file_io.hpp>
#include <priormap/core/json_io.hpp>

#include "fuzz_check.hpp"

using priormap::fuzz::Check;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const priormap::Result<priormap::Log> log = priormap::ParseJsonLog(text, "fuzz.json");
  if (!log.ok()) {
    Check(log.diagnostics().size() == 1, "a failed read has one diagnostic");
    return 0;
  }
  const std::vector<std::string> problems = log.value().Problems();
  Check(problems.empty(), "an accepted log is consistent",
        problems.empty() ? "" : problems.front());

  const std::string json = priormap::FormatJsonLog(log.value());
  const priormap::Result<priormap::Log> again = priormap::ParseJsonLog(json, "again.json");
  Check(again.ok(), "written JSON is read back", again.ok() ? json : again.error());
  Check(priormap::FormatJsonLog(again.value()) == json, "JSON round trip keeps the log", json);

  // A log without records is written as a CARMEN file that the reader rejects ("no CARMEN
  // records found"), deliberately: such a file is more likely not CARMEN at all.
  if (log.value().NumRecords() == 0) return 0;
  std::string carmen;
  try {
    carmen = priormap::FormatCarmenLog(log.value());
  } catch (const priormap::IoError&) {
    return 0;  // not representable in CARMEN (uneven angles, ...): refused, fine
  }
  const priormap::Result<priormap::Log> from_carmen = priormap::ParseCarmenLog(carmen, "fuzz.log");
  Check(from_carmen.ok(), "written CARMEN is read back",
        from_carmen.ok() ? carmen : from_carmen.error());
  return 0;
}
