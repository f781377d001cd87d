// libFuzzer harness for the GeoJSON prior-map reader of `priormap slam run`. Besides crashes and
// sanitizer reports it checks that a rejected document gets diagnostics located inside the text,
// that an accepted map is usable (segments of finite, distinct endpoints, std > 0, of existing
// buildings, grouped by building), and that it is written back so that reading it again gives the
// same map bit for bit, and the same text. Merged (MergeSameWalls), it is written with every wall
// in each building that holds it: read back, each building has as many walls as it had merged.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <priormap/slam/same_walls.hpp>
#include <priormap/slam/slam_io.hpp>

#include "fuzz_check.hpp"

using priormap::fuzz::Check;
using priormap::fuzz::CheckLocated;
using priormap::fuzz::SameBits;
using priormap::slam::PriorMap;
using priormap::slam::PriorSegment;

namespace {

// Per building, its walls: its own and those it shares (a merged map's).
std::vector<std::size_t> WallsPerBuilding(const PriorMap& map) {
  std::vector<std::size_t> walls(map.buildings.size(), 0);
  for (const PriorSegment& s : map.segments) {
    std::vector<int> of = s.shared_with;
    of.push_back(s.building);
    std::sort(of.begin(), of.end());
    of.erase(std::unique(of.begin(), of.end()), of.end());
    for (int b : of) ++walls[static_cast<std::size_t>(b)];
  }
  return walls;
}

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

  const PriorMap merged = priormap::slam::MergeSameWalls(read).map;
  const std::string merged_json = priormap::slam::FormatPriorMapGeoJson(merged);
  const auto merged_again =
      priormap::slam::ParsePriorMapGeoJson(merged_json, "merged.geojson", 1.0);
  Check(merged_again.ok(), "a merged map's GeoJSON is read back",
        merged_again.ok() ? merged_json : merged_again.error());
  Check(WallsPerBuilding(merged_again.value()) == WallsPerBuilding(merged),
        "a merged map's GeoJSON keeps each building's walls, shared ones included", merged_json);
  return 0;
}
