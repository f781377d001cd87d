// Prior maps as GeoJSON (RFC 7946; docs/formats.md): a FeatureCollection whose features are the
// buildings, each a LineString, MultiLineString, Polygon or MultiPolygon of wall segments.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <optional>

#include <fmt/format.h>

#include <priormap/core/check.hpp>
#include <priormap/core/file_io.hpp>
#include <priormap/slam/slam_io.hpp>

#include "../core/json_document.hpp"

namespace priormap::slam {
namespace {

namespace json = priormap::detail;
using json::JsonNode;
using json::OrderedJson;

constexpr const char* kSupportedTypes = "LineString, MultiLineString, Polygon or MultiPolygon";

// A member that is present and not null (null stands for "not given", as GIS tools write it).
std::optional<JsonNode> GivenMember(const JsonNode& object, const char* key) {
  std::optional<JsonNode> member = json::OptionalMember(object, key);
  if (member && member->value.is_null()) return std::nullopt;
  return member;
}

double Std(const JsonNode& node, std::string_view what) {
  const double std_value = json::FiniteNumber(node, what);
  if (!(std_value > 0.0))
    json::Fail(node, fmt::format("expected {} > 0 m, got {}", what, std_value));
  if (!IsValidPriorStd(std_value)) {
    json::Fail(node, fmt::format("expected {} of at most {:.0e} m, the world's bound, got {}", what,
                                 kMaxPriorStd, std_value));
  }
  return std_value;
}

// [x, y] or [x, y, z] (the altitude is ignored); no reprojection, the frame is local and metric.
Vec2 Position(const JsonNode& node) {
  const std::size_t n = json::ArraySize(node, "a position [x, y]");
  if (n != 2 && n != 3) {
    json::Fail(node, fmt::format("expected a position [x, y] or [x, y, z], got an array of {} "
                                 "elements",
                                 n));
  }
  // Metres in a local frame, bounded as every position priormap reads: beyond the bound the
  // map's extent (max - min) could overflow to infinity.
  const Vec2 p{json::WorldCoordinate(json::Element(node, 0), "x"),
               json::WorldCoordinate(json::Element(node, 1), "y")};
  if (n == 3) (void)json::FiniteNumber(json::Element(node, 2), "z");
  return p;
}

// The segments of one building, in the order of its geometry's positions.
struct Walls {
  std::vector<std::pair<Vec2, Vec2>> segments;
};

// A LineString's positions or a Polygon's ring: segments between consecutive positions.
void AddLine(const JsonNode& node, bool ring, Walls& walls) {
  const std::size_t n = json::ArraySize(node, ring ? "a linear ring" : "a line's positions");
  const std::size_t minimum = ring ? 4 : 2;
  if (n < minimum) {
    json::Fail(node, ring ? fmt::format("a Polygon ring needs at least 4 positions (3 corners, "
                                        "then the first again), got {}",
                                        n)
                          : fmt::format("a line needs at least 2 positions, got {}", n));
  }
  std::vector<Vec2> points(n);
  for (std::size_t i = 0; i < n; ++i) points[i] = Position(json::Element(node, i));
  if (ring && points.front() != points.back()) {
    json::Fail(json::Element(node, n - 1),
               fmt::format("a Polygon ring must end at its first position ({}, {}), as RFC 7946 "
                           "(3.1.6) requires",
                           points.front().x(), points.front().y()));
  }
  for (std::size_t i = 1; i < n; ++i) {
    if (points[i] == points[i - 1]) {
      json::Fail(json::Element(node, i),
                 fmt::format("zero-length segment: position {} repeats position {} ({}, {})", i,
                             i - 1, points[i].x(), points[i].y()));
    }
    walls.segments.emplace_back(points[i - 1], points[i]);
  }
}

void AddPolygon(const JsonNode& node, Walls& walls) {
  const std::size_t rings = json::ArraySize(node, "the rings of a Polygon");
  if (rings == 0) json::Fail(node, "a Polygon needs at least one ring (its outline)");
  // The outer ring is the building's outline; holes (courtyards) are walls too.
  for (std::size_t i = 0; i < rings; ++i) AddLine(json::Element(node, i), true, walls);
}

Walls ReadGeometry(const JsonNode& feature) {
  const JsonNode geometry = json::Member(feature, "geometry");
  if (geometry.value.is_null()) {
    json::Fail(geometry,
               fmt::format("the feature has no geometry (null); expected {}", kSupportedTypes));
  }
  json::RequireObject(geometry, "a geometry");
  const JsonNode type_node = json::Member(geometry, "type");
  const std::string type = json::String(type_node, "the geometry type");
  if (type == "Point" || type == "MultiPoint" || type == "GeometryCollection") {
    json::Fail(type_node, fmt::format("unsupported geometry type \"{}\": a prior map holds walls "
                                      "({})",
                                      type, kSupportedTypes));
  }
  if (type != "LineString" && type != "MultiLineString" && type != "Polygon" &&
      type != "MultiPolygon") {
    json::Fail(type_node,
               fmt::format("unknown geometry type \"{}\"; expected {}", type, kSupportedTypes));
  }
  const JsonNode coordinates = json::Member(geometry, "coordinates");
  Walls walls;
  if (type == "LineString") {
    AddLine(coordinates, false, walls);
  } else if (type == "MultiLineString") {
    const std::size_t n = json::ArraySize(coordinates, "the lines of a MultiLineString");
    for (std::size_t i = 0; i < n; ++i) AddLine(json::Element(coordinates, i), false, walls);
  } else if (type == "Polygon") {
    AddPolygon(coordinates, walls);
  } else {
    const std::size_t n = json::ArraySize(coordinates, "the polygons of a MultiPolygon");
    for (std::size_t i = 0; i < n; ++i) AddPolygon(json::Element(coordinates, i), walls);
  }
  return walls;
}

// properties.name, else properties.id, else the feature's id (RFC 7946, 3.2), else "feature K".
std::string BuildingName(const JsonNode& feature, const std::optional<JsonNode>& properties,
                         std::size_t index) {
  if (properties) {
    if (const auto name = GivenMember(*properties, "name"))
      return json::String(*name, "the building name");
  }
  for (const auto& owner : {properties, std::optional<JsonNode>(feature)}) {
    if (!owner) continue;
    if (const auto id = GivenMember(*owner, "id")) {
      if (id->value.is_string()) return id->value.get<std::string>();
      if (!id->value.is_number()) json::Fail(*id, "expected the feature id (a string or a number)");
      return id->value.dump();
    }
  }
  return fmt::format("feature {}", index);
}

// Adds feature `index` (one building) to `map`.
void ReadFeature(const JsonNode& feature, std::size_t index, double collection_std, PriorMap& map) {
  json::RequireObject(feature, "a GeoJSON Feature");
  const JsonNode type_node = json::Member(feature, "type");
  const std::string type = json::String(type_node, "the feature type");
  if (type != "Feature")
    json::Fail(type_node, fmt::format("expected a GeoJSON Feature, got a \"{}\"", type));
  std::optional<JsonNode> properties = GivenMember(feature, "properties");
  if (properties) json::RequireObject(*properties, "the feature's properties (or null)");

  const Walls walls = ReadGeometry(feature);
  double std_value = collection_std;
  std::vector<double> segment_std;
  if (properties) {
    if (const auto node = GivenMember(*properties, "std")) std_value = Std(*node, "\"std\"");
    if (const auto node = GivenMember(*properties, "segment_std")) {
      const std::size_t n = json::ArraySize(*node, "\"segment_std\"");
      if (n != walls.segments.size()) {
        json::Fail(*node, fmt::format("expected one \"segment_std\" per segment of the feature "
                                      "({}), got {}",
                                      walls.segments.size(), n));
      }
      for (std::size_t i = 0; i < n; ++i)
        segment_std.push_back(Std(json::Element(*node, i), "an element of \"segment_std\""));
    }
  }

  const int building = static_cast<int>(map.buildings.size());
  map.buildings.push_back(BuildingName(feature, properties, index));
  for (std::size_t i = 0; i < walls.segments.size(); ++i) {
    const auto& [a, b] = walls.segments[i];
    map.segments.push_back({a, b, segment_std.empty() ? std_value : segment_std[i], building});
  }
}

PriorMap ReadPriorMap(const JsonNode& root, double default_std) {
  json::RequireObject(root, "a GeoJSON FeatureCollection");
  const JsonNode type_node = json::Member(root, "type");
  const std::string type = json::String(type_node, "the GeoJSON type");
  if (type != "FeatureCollection") {
    json::Fail(type_node, fmt::format("expected a GeoJSON FeatureCollection (of buildings), got a "
                                      "\"{}\"",
                                      type));
  }
  // "std" is a foreign member of the collection (RFC 7946, 6.1): the default of its features.
  double collection_std = default_std;
  if (const auto node = GivenMember(root, "std")) collection_std = Std(*node, "\"std\"");
  const JsonNode features = json::Member(root, "features");
  const std::size_t n = json::ArraySize(features, "\"features\"");
  PriorMap map;
  for (std::size_t i = 0; i < n; ++i)
    ReadFeature(json::Element(features, i), i, collection_std, map);
  if (map.empty()) json::Fail(features, "prior map has no segments");
  return map;
}

// As JsonDocument::Diagnose, but located at the nearest enclosing value that can be found
// (LocateJsonPointer does not decode escapes in keys), so that every diagnostic has a place.
Diagnostic Diagnose(std::string_view text, const std::string& name,
                    const json::JsonSchemaError& error) {
  // JsonDocument::Parse skips a byte order mark; the locator must see the same text.
  if (text.starts_with(kUtf8ByteOrderMark)) text.remove_prefix(kUtf8ByteOrderMark.size());
  json::JsonPointer pointer = error.pointer;
  std::optional<std::size_t> offset = json::LocateJsonPointer(text, pointer);
  while (!offset && !pointer.empty()) {
    pointer = pointer.parent_pointer();
    offset = json::LocateJsonPointer(text, pointer);
  }
  const TextPosition where = detail::PositionInText(text, offset.value_or(0));
  std::string message = error.message;
  if (!error.pointer.empty()) message += fmt::format(" (at {})", error.pointer.to_string());
  return {name, where.line, where.col, std::move(message)};
}

bool SameBits(const Vec2& p, const Vec2& q) {
  return std::bit_cast<std::uint64_t>(p.x()) == std::bit_cast<std::uint64_t>(q.x()) &&
         std::bit_cast<std::uint64_t>(p.y()) == std::bit_cast<std::uint64_t>(q.y());
}

// What ReadPriorMap would reject (a bug of the caller).
void CheckWritable(const PriorMap& map) {
  PRIORMAP_CHECK(!map.empty(), "a prior map without segments cannot be written");
  for (const PriorSegment& s : map.segments) {
    PRIORMAP_CHECK(
        0 <= s.building && s.building < static_cast<int>(map.buildings.size()),
        fmt::format("segment of building {} (the map has {})", s.building, map.buildings.size()));
    PRIORMAP_CHECK(s.a.allFinite() && s.b.allFinite() && s.a != s.b,
                   fmt::format("segment ({}, {})-({}, {})", s.a.x(), s.a.y(), s.b.x(), s.b.y()));
    PRIORMAP_CHECK(IsValidPriorStd(s.std), fmt::format("segment std {}", s.std));
    for (int other : s.shared_with) {
      PRIORMAP_CHECK(0 <= other && other < static_cast<int>(map.buildings.size()),
                     fmt::format("segment shared with building {} (the map has {})", other,
                                 map.buildings.size()));
    }
  }
}

// Whether `segment` is a wall of `building`: its own, or one it shares (a merged map's).
bool IsWallOf(const PriorSegment& segment, int building) {
  return segment.building == building ||
         std::find(segment.shared_with.begin(), segment.shared_with.end(), building) !=
             segment.shared_with.end();
}

OrderedJson PositionToJson(const Vec2& p) {
  return {p.x(), p.y()};
}

// One building: its segments as lines, joining each segment to the previous one when it starts
// exactly where that one ends, and the std of each. A wall it shares with others is written in
// each of their features too: GeoJSON holds a shared wall once per footprint, so written once, the
// other footprints would read back open.
OrderedJson FeatureToJson(const PriorMap& map, int building) {
  OrderedJson lines = OrderedJson::array();
  std::vector<double> stds;
  const PriorSegment* previous = nullptr;
  for (const PriorSegment& s : map.segments) {
    if (!IsWallOf(s, building)) continue;
    if (previous == nullptr || !SameBits(previous->b, s.a))
      lines.push_back(OrderedJson::array({PositionToJson(s.a)}));
    lines.back().push_back(PositionToJson(s.b));
    stds.push_back(s.std);
    previous = &s;
  }
  OrderedJson properties;
  properties["name"] = map.buildings[static_cast<std::size_t>(building)];
  const bool one_std = std::all_of(stds.begin(), stds.end(), [&](double v) {
    return std::bit_cast<std::uint64_t>(v) == std::bit_cast<std::uint64_t>(stds.front());
  });
  if (!stds.empty() && one_std) properties["std"] = stds.front();
  if (!one_std) properties["segment_std"] = stds;
  OrderedJson feature;
  feature["type"] = "Feature";
  feature["properties"] = std::move(properties);
  feature["geometry"] = {{"type", "MultiLineString"}, {"coordinates", std::move(lines)}};
  return feature;
}

}  // namespace

Result<PriorMap> ParsePriorMapGeoJson(std::string_view text, const std::string& name,
                                      double default_std) {
  PRIORMAP_CHECK(IsValidPriorStd(default_std), fmt::format("default std {}", default_std));
  Result<json::JsonDocument> document = json::JsonDocument::Parse(text, name);
  if (!document) return document.diagnostics();
  try {
    return ReadPriorMap(document.value().root(), default_std);
  } catch (const json::JsonSchemaError& error) {
    return Diagnose(text, name, error);
  }
}

std::string FormatPriorMapGeoJson(const PriorMap& map) {
  CheckWritable(map);
  std::string out = "{\"type\": \"FeatureCollection\", \"features\": [\n";
  for (std::size_t b = 0; b < map.buildings.size(); ++b) {
    out += json::Dump(FeatureToJson(map, static_cast<int>(b)));
    out += b + 1 < map.buildings.size() ? ",\n" : "\n";
  }
  return out + "]}\n";
}

Result<PriorMap> ReadPriorMapGeoJson(const std::filesystem::path& path, double default_std) {
  Result<std::string> text = ReadFileText(path);
  if (!text) return text.diagnostics();
  return ParsePriorMapGeoJson(text.value(), path.string(), default_std);
}

void WritePriorMapGeoJson(const PriorMap& map, const std::filesystem::path& path) {
  WriteTextFileAtomically(path, FormatPriorMapGeoJson(map));
}

}  // namespace priormap::slam
