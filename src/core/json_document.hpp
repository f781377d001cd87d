#pragma once
// Reading priormap's JSON documents with precise diagnostics: every accessor names what it
// expected, and a failure is reported at the file:line:col of the offending value.

#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include <priormap/core/diagnostic.hpp>
#include <priormap/core/file_io.hpp>
#include <priormap/core/scan.hpp>
#include <priormap/core/se2.hpp>

namespace priormap::detail {

using Json = nlohmann::json;
using OrderedJson = nlohmann::ordered_json;  // for writing: keys in a readable order
using JsonPointer = nlohmann::json::json_pointer;

/// Line and column of byte `offset` of `text`, the column counted in characters as an editor
/// shows it (CharacterColumnInText): a "Zürich" before the offending value takes 6 columns, not 7.
TextPosition PositionInText(std::string_view text, std::size_t offset);

/// PositionInText of each of `offsets`, counting the lines in one pass along `text`.
std::vector<TextPosition> PositionsInText(std::string_view text,
                                          std::span<const std::size_t> offsets);

/// Byte offset of the value at `pointer` in the JSON `text` (which must be valid JSON).
std::optional<std::size_t> LocateJsonPointer(std::string_view text, const JsonPointer& pointer);

/// A value of a parsed document together with where it is.
struct JsonNode {
  const Json& value;
  JsonPointer pointer;
};

/// Thrown by the accessors; turned into a Diagnostic by JsonDocument::Diagnose.
struct JsonSchemaError {
  JsonPointer pointer;
  std::string message;
};

class JsonDocument {
 public:
  /// Parses `text`; syntax errors become diagnostics located at the failing character.
  static Result<JsonDocument> Parse(std::string_view text, std::string name);

  [[nodiscard]] JsonNode root() const { return {json_, JsonPointer()}; }
  /// The diagnostic for a schema error, with its line and column.
  [[nodiscard]] Diagnostic Diagnose(const JsonSchemaError& error) const;
  /// Where `member` of each element `indices[k]` (in increasing order) of the array at `array`
  /// is (nullopt where it is not), found in one pass along the array: a log's records can be
  /// many megabytes, which a search per position would read each time.
  [[nodiscard]] std::vector<std::optional<TextPosition>> LocateMembersOfElements(
      const JsonPointer& array, std::span<const std::size_t> indices,
      const std::string& member) const;
  [[nodiscard]] const std::string& name() const { return name_; }

 private:
  JsonDocument(std::string_view text, std::string name, Json json)
      : text_(text), name_(std::move(name)), json_(std::move(json)) {}
  std::string_view text_;
  std::string name_;
  Json json_;
};

// Accessors; each throws JsonSchemaError naming what was expected.
[[noreturn]] void Fail(const JsonNode& node, std::string message);
JsonNode Member(const JsonNode& object, const char* key);
std::optional<JsonNode> OptionalMember(const JsonNode& object, const char* key);
JsonNode Element(const JsonNode& array, std::size_t index);
void RequireObject(const JsonNode& node, std::string_view what);
/// Fails at the first member of `object` whose key is not in `known`, naming the nearest known
/// key when it is a likely misspelling: a typo must not be read as "absent" (a misspelt
/// max_range would make every no-return reading a wall).
void RefuseUnknownMembers(const JsonNode& object, std::span<const std::string_view> known,
                          std::string_view what);
std::size_t ArraySize(const JsonNode& node, std::string_view what);
/// A number; null is NaN and the strings "nan", "inf", "-inf" are what they say.
double Number(const JsonNode& node, std::string_view what);
double FiniteNumber(const JsonNode& node, std::string_view what);
/// A finite coordinate of the world, at most kMaxWorldCoordinate in magnitude (world_bounds.hpp).
double WorldCoordinate(const JsonNode& node, std::string_view what);
/// Fails at the element of `readings` (the scan's ranges as read) that is the scan's first return
/// longer than the world's bound, if any (Scan::FirstReturnBeyondWorld); call once the statuses
/// are set, as a no-return reading is kept whatever its value. `what` names an element.
void RefuseReturnBeyondWorld(const Scan& scan, const JsonNode& readings, std::string_view what);
long long Integer(const JsonNode& node, std::string_view what);
/// An integer in [lo, hi], so that narrowing it afterwards loses nothing.
long long IntegerInRange(const JsonNode& node, std::string_view what, long long lo, long long hi);
bool Boolean(const JsonNode& node, std::string_view what);
std::string String(const JsonNode& node, std::string_view what);
std::vector<double> Numbers(const JsonNode& node, std::string_view what);
std::vector<long long> Integers(const JsonNode& node, std::string_view what);
/// [x, y], world coordinates.
Vec2 Point(const JsonNode& node, std::string_view what);
/// [x, y, theta]: x and y world coordinates, theta finite.
Se2 Pose(const JsonNode& node, std::string_view what);
/// Checks "format" and "version" of a document.
void RequireFormat(const JsonNode& root, std::string_view format, int version);

/// The JSON form of a number, using null for NaN and strings for infinities.
OrderedJson NumberToJson(double value);
OrderedJson NumbersToJson(const std::vector<double>& values);
OrderedJson PoseToJson(const Se2& pose);

/// `value` as JSON text. Strings that are not UTF-8 (e.g. Latin-1 PARAM values of old CARMEN
/// logs) get U+FFFD for each bad byte instead of making the writer throw; indent < 0: one line.
std::string Dump(const OrderedJson& value, int indent = -1);

/// An object with one top-level member per line (arrays stay on one line): readable, diffable.
std::string DumpOneMemberPerLine(const OrderedJson& object);

}  // namespace priormap::detail
