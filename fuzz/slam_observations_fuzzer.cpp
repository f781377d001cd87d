// libFuzzer harness for the observations CSV reader of `priormap slam run`. Besides crashes and
// sanitizer reports it checks that a rejected file gets diagnostics located inside the text, and
// that accepted frames are written back so that reading them again gives the same frames bit for
// bit, and the same text.
#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <priormap/slam/slam_io.hpp>

#include "fuzz_check.hpp"

using priormap::fuzz::Check;
using priormap::fuzz::CheckLocated;
using priormap::fuzz::SameBits;
using priormap::slam::ObservationFrame;

namespace {

bool SameFrames(const std::vector<ObservationFrame>& a, const std::vector<ObservationFrame>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t f = 0; f < a.size(); ++f) {
    if (!SameBits(a[f].time, b[f].time) || a[f].observations.size() != b[f].observations.size())
      return false;
    for (std::size_t i = 0; i < a[f].observations.size(); ++i) {
      const auto& oa = a[f].observations[i];
      const auto& ob = b[f].observations[i];
      if (oa.id != ob.id || !SameBits(oa.range, ob.range) || !SameBits(oa.bearing, ob.bearing))
        return false;
    }
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const auto frames = priormap::slam::ParseObservationsCsv(text, "fuzz.csv");
  if (!frames.ok()) {
    CheckLocated(frames.diagnostics(), text, "fuzz.csv");
    return 0;
  }
  for (std::size_t f = 1; f < frames.value().size(); ++f) {
    Check(frames.value()[f].time > frames.value()[f - 1].time, "frames are in time order");
  }

  const std::string csv = priormap::slam::FormatObservationsCsv(frames.value());
  const auto again = priormap::slam::ParseObservationsCsv(csv, "again.csv");
  Check(again.ok(), "written CSV is read back", again.ok() ? csv : again.error());
  Check(SameFrames(again.value(), frames.value()), "CSV round trip keeps the frames", csv);
  Check(priormap::slam::FormatObservationsCsv(again.value()) == csv, "written CSV is a fixpoint",
        csv);
  return 0;
}
