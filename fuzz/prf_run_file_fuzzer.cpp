// libFuzzer harness for the run.json of a `priormap prf` run (ReadRunFile, apps/priormap), which
// `priormap prf --resume DIR` and `priormap prf rhat` read. Besides crashes and sanitizer reports
// it checks that
//  - a refused file is a UserError that names it (what main prints), never another exception;
//  - a run read keeps the session's settings of the base it is read over;
//  - RunJson writes a run read (with a log: a run without one stops before anything is written)
//    to a run.json that reads back to the same run: the same RunJson, the same text, and the
//    same orientation in radians, which the checkpoints' fingerprint hashes (run.json holds
//    degrees). The first round trip may make the log's and sonar model's paths absolute.
#include <cstddef>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "cli_support.hpp"
#include "fuzz_check.hpp"
#include "fuzz_scratch.hpp"
#include "prf_run_file.hpp"

using priormap::app::MappingCliOptions;
using priormap::fuzz::Check;
using priormap::fuzz::SameBits;

namespace {

// What run.json does not hold: a session's settings, here none of them the default.
MappingCliOptions Base() {
  MappingCliOptions base;
  base.out = "base-out";
  base.resume = "base-resume";
  base.checkpoint_every_s = 7.5;
  base.stop_after_steps = 9;
  return base;
}

// The run in the run.json at `path`, or nullopt when ReadRunFile refuses it as it should.
std::optional<MappingCliOptions> Read(const std::filesystem::path& path) {
  try {
    return priormap::app::ReadRunFile(path, Base());
  } catch (const priormap::app::UserError& e) {
    const std::string_view message = e.what();
    Check(message.starts_with(path.string()) && message.size() > path.string().size(),
          "a refused run file is a UserError that names it", message);
    return std::nullopt;
  } catch (const std::exception& e) {
    Check(false, "ReadRunFile throws UserError only", e.what());
  }
  return std::nullopt;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const priormap::fuzz::ScratchDirectory& scratch = priormap::fuzz::Scratch();
  const std::optional<MappingCliOptions> run = Read(scratch.Write("run.json", text));
  if (!run) return 0;
  const MappingCliOptions base = Base();
  Check(run->out == base.out && run->resume == base.resume &&
            SameBits(run->checkpoint_every_s, base.checkpoint_every_s) &&
            run->stop_after_steps == base.stop_after_steps,
        "a run read keeps the session's settings");
  if (run->log.empty()) return 0;

  const nlohmann::json json = priormap::app::RunJson(*run);
  const std::string written = json.dump(2) + "\n";
  const std::optional<MappingCliOptions> again = Read(scratch.Write("again.json", written));
  Check(again.has_value(), "a written run file is read back", written);
  const nlohmann::json json_again = priormap::app::RunJson(*again);
  Check(json_again == json && json_again.dump(2) + "\n" == written,
        "the round trip keeps the run file", written + "\nread back as\n" + json_again.dump(2));
  Check(SameBits(again->mapping.sampler.orientation.angle, run->mapping.sampler.orientation.angle),
        "the round trip keeps the orientation in radians (the checkpoints' fingerprint)", written);
  return 0;
}
