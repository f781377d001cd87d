// libFuzzer harness for the GeoJSON prior-map reader of `priormap slam run`. Besides crashes and
// sanitizer reports it checks that a rejected document gets diagnostics located inside the text,
// that an accepted map is usable (segments of finite, distinct endpoints, std > 0, of existing
// buildings, grouped by building), and that it is written back so that reading it again gives the
// same map bit for bit, and the same text.
#include <algorithm>
#include <bit>
#include <cmath>
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
using priormap::slam::PriorMap;
using priormap::slam::PriorSegment;

namespace {

bool SameMap(const PriorMap& a, const PriorMap& b) {
  if (a.buildings != b.buildings || a.segments.size() != b.segments.size()) return false;
  for (std::size_t i = 0; i < a.segments.size(); ++i) {
    const PriorSegment& sa = a.segments[i];
    const PriorSegment& sb = b.segments[i];
    if (!SameBits(sa.a.x(), sb.a.x()) || !SameBits(sa.a.y(), sb.a.y()) ||
        !SameBits(sa.b.x(), sb.b.x()) || !SameBits(sa.b.y(), sb.b.y()) ||
        !SameBits(sa.std, sb.std) || sa.building != sb.building) {
      return false;
    }
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const auto map = priormap::slam::ParsePriorMapGeoJson(text, "fuzz.geojson", 1.0);
  if (!map.ok()) {
    CheckLocated(map.diagnostics(), text, "fuzz.geojson");
    return 0;
  }
  const PriorMap& read = map.value();
  Check(!read.empty(), "an accepted map has segments");
  int building = 0;
  for (const PriorSegment& s : read.segments) {
    Check(s.a.allFinite() && s.b.allFinite() && s.a != s.b, "segments have distinct endpoints");
    Check(std::isfinite(s.std) && s.std > 0.0, "segments have a std > 0");
    Check(building <= s.building && s.building < static_cast<int>(read.buildings.size()),
          "segments are grouped by existing buildings");
    building = s.building;
  }

  const std::string json = priormap::slam::FormatPriorMapGeoJson(read);
  const auto again = priormap::slam::ParsePriorMapGeoJson(json, "again.geojson", 2.0);
  Check(again.ok(), "written GeoJSON is read back", again.ok() ? json : again.error());
  Check(SameMap(again.value(), read), "GeoJSON round trip keeps the map", json);
  Check(priormap::slam::FormatPriorMapGeoJson(again.value()) == json,
        "written GeoJSON is a fixpoint", json);
  return 0;
}
