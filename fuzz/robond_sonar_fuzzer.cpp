// libFuzzer harness for the RoboND sonar reader (two files: the input up to its first NUL byte
// is measurement.txt, the rest poses.txt). Besides crashes and sanitizer reports it checks that
// a rejected pair gets one diagnostic located inside the file it names, and that an accepted
// pair is a consistent log of sonar rings that our JSON writes and reads back unchanged.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include <priormap/core/json_io.hpp>
#include <priormap/core/robond_sonar_io.hpp>

#include "fuzz_check.hpp"

using priormap::fuzz::Check;
using priormap::fuzz::CheckLocated;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  const std::size_t split = input.find('\0');
  const std::string_view measurements = input.substr(0, split);
  const std::string_view poses =
      split == std::string_view::npos ? std::string_view() : input.substr(split + 1);
  const priormap::Result<priormap::Log> log =
      priormap::ParseRoboNdSonar(measurements, "measurement.txt", poses, "poses.txt");
  if (!log.ok()) {
    Check(log.diagnostics().size() == 1, "a failed read has one diagnostic");
    const priormap::Diagnostic& d = log.diagnostics()[0];
    CheckLocated(log.diagnostics(), d.file == "poses.txt" ? poses : measurements, d.file);
    return 0;
  }
  const std::vector<std::string> problems = log.value().Problems();
  Check(problems.empty(), "an accepted log is consistent",
        problems.empty() ? "" : problems.front());
  for (const priormap::Scan& ring : log.value().scans)
    Check(ring.sonar.has_value() && ring.size() == 8, "every ring has its cone and 8 readings");
  const std::string json = priormap::FormatJsonLog(log.value());
  const priormap::Result<priormap::Log> again = priormap::ParseJsonLog(json, "again.json");
  Check(again.ok(), "written JSON is read back", again.ok() ? json : again.error());
  Check(priormap::FormatJsonLog(again.value()) == json, "JSON round trip keeps the log", json);
  return 0;
}
