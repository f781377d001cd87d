// libFuzzer harness for the sonar model reader (priormap.sonar_model). Besides crashes and
// sanitizer reports it checks that a rejected document gets diagnostics located inside the text,
// that an accepted model is usable (Problem() empty), and that writing it and reading it again
// gives the same model bit for bit, and the same text.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include <priormap/prf/sonar_model_io.hpp>

#include "fuzz_check.hpp"

using priormap::fuzz::Check;
using priormap::fuzz::CheckLocated;
using priormap::fuzz::SameBits;
using priormap::prf::SonarModel;

namespace {

bool SameModel(const SonarModel& a, const SonarModel& b) {
  for (const auto& [name, member] : priormap::prf::kSonarModelParameters)
    if (!SameBits(a.*member, b.*member)) return false;
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const priormap::Result<SonarModel> model = priormap::prf::ParseSonarModel(text, "fuzz.json");
  if (!model.ok()) {
    CheckLocated(model.diagnostics(), text, "fuzz.json");
    return 0;
  }
  const std::string problem = model.value().Problem();
  Check(problem.empty(), "an accepted model is usable", problem);

  const std::string json = priormap::prf::FormatSonarModel(model.value());
  const priormap::Result<SonarModel> again = priormap::prf::ParseSonarModel(json, "again.json");
  Check(again.ok(), "a written model is read back", again.ok() ? json : again.error());
  Check(SameModel(again.value(), model.value()), "the round trip keeps the model", json);
  Check(priormap::prf::FormatSonarModel(again.value()) == json, "written JSON is a fixpoint", json);
  return 0;
}
