// libFuzzer harness for the priormap.scene reader. Besides crashes and sanitizer reports it
// checks that an accepted scene is usable and that its JSON is a fixpoint after one round trip.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include <priormap/core/json_io.hpp>
#include <priormap/core/scene.hpp>

#include "fuzz_check.hpp"

using priormap::fuzz::Check;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const priormap::Result<priormap::Scene> scene = priormap::ParseJsonScene(text, "fuzz.json");
  if (!scene.ok()) {
    Check(scene.diagnostics().size() == 1, "a failed read has one diagnostic");
    return 0;
  }
  const std::vector<std::string> problems = scene.value().Problems();
  Check(problems.empty(), "an accepted scene is usable", problems.empty() ? "" : problems.front());
  // Region ids are positions in Primitives(); each primitive names an existing surface.
  const std::vector<priormap::ScenePrimitive> primitives = scene.value().Primitives();
  for (std::size_t i = 0; i < primitives.size(); ++i) {
    Check(primitives[i].region == static_cast<int>(i), "region ids are primitive positions");
    Check(primitives[i].surface >= 0 &&
              primitives[i].surface < static_cast<int>(scene.value().surfaces.size()),
          "primitives name their surface");
  }
  (void)scene.value().Bounds();

  const std::string json = priormap::FormatJsonScene(scene.value());
  const priormap::Result<priormap::Scene> again = priormap::ParseJsonScene(json, "again.json");
  Check(again.ok(), "written JSON is read back", again.ok() ? json : again.error());
  Check(priormap::FormatJsonScene(again.value()) == json, "JSON round trip keeps the scene", json);
  return 0;
}
