#include "json_document.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include <fmt/format.h>

#include <priormap/core/file_io.hpp>
#include <priormap/core/utf8.hpp>
#include <priormap/core/world_bounds.hpp>

namespace priormap::detail {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// A minimal scanner over text already known to be valid JSON, used only to find where a value
// is (nlohmann::json does not keep positions).
class JsonScanner {
 public:
  explicit JsonScanner(std::string_view text) : text_(text) {}

  std::optional<std::size_t> Locate(const JsonPointer& pointer) {
    pos_ = 0;
    SkipSpace();
    std::vector<std::string> tokens;
    for (JsonPointer p = pointer; !p.empty(); p = p.parent_pointer()) tokens.push_back(p.back());
    for (auto it = tokens.rbegin(); it != tokens.rend(); ++it) {
      if (!Descend(*it)) return std::nullopt;
    }
    return pos_;
  }

  // The offsets of the elements `indices` (increasing) of the array at `array`, found in one
  // pass along it; nullopt for those not found.
  std::vector<std::optional<std::size_t>> LocateElements(const JsonPointer& array,
                                                         std::span<const std::size_t> indices) {
    std::vector<std::optional<std::size_t>> found(indices.size());
    const std::optional<std::size_t> start = Locate(array);
    if (!start || !At('[')) return found;
    ++pos_;
    std::size_t next = 0;  // of `indices`
    for (std::size_t i = 0; next < indices.size(); ++i) {
      SkipSpace();
      if (pos_ >= text_.size() || At(']')) break;
      for (; next < indices.size() && indices[next] == i; ++next) found[next] = pos_;
      SkipValue();
      SkipSpace();
      if (!At(',')) break;
      ++pos_;
    }
    return found;
  }

 private:
  bool Descend(const std::string& token) {
    if (At('{')) {
      ++pos_;
      // Of duplicate keys, nlohmann keeps the last: so must the search.
      std::optional<std::size_t> found;
      for (;;) {
        SkipSpace();
        if (!At('"')) break;
        const std::string key = ReadString();
        SkipSpace();
        if (!At(':')) break;
        ++pos_;
        SkipSpace();
        if (key == token) found = pos_;
        SkipValue();
        SkipSpace();
        if (!At(',')) break;
        ++pos_;
      }
      if (!found) return false;
      pos_ = *found;
      return true;
    }
    if (At('[')) {
      ++pos_;
      std::size_t index = 0;
      for (char c : token) {
        if (c < '0' || c > '9') return false;
        index = index * 10 + static_cast<std::size_t>(c - '0');
      }
      for (std::size_t i = 0;; ++i) {
        SkipSpace();
        if (At(']')) return false;
        if (i == index) return true;
        SkipValue();
        SkipSpace();
        if (!At(',')) return false;
        ++pos_;
      }
    }
    return false;
  }

  bool At(char c) const { return pos_ < text_.size() && text_[pos_] == c; }

  void SkipSpace() {
    while (pos_ < text_.size() && (text_[pos_] == ' ' || text_[pos_] == '\n' ||
                                   text_[pos_] == '\r' || text_[pos_] == '\t')) {
      ++pos_;
    }
  }

  // Reads a string starting at '"', as the JSON parser decodes it (escapes, \uXXXX and surrogate
  // pairs as UTF-8), so that keys written with escapes are found under their decoded names.
  std::string ReadString() {
    std::string out;
    ++pos_;
    while (pos_ < text_.size() && text_[pos_] != '"') {
      if (text_[pos_] != '\\' || pos_ + 1 >= text_.size()) {
        out += text_[pos_++];
        continue;
      }
      const char next = text_[pos_ + 1];
      pos_ += 2;
      switch (next) {
        case 'b':
          out += '\b';
          break;
        case 'f':
          out += '\f';
          break;
        case 'n':
          out += '\n';
          break;
        case 'r':
          out += '\r';
          break;
        case 't':
          out += '\t';
          break;
        case 'u':
          AppendUtf8(ReadCodePoint(), &out);
          break;
        default:
          out += next;  // ", \ and /
      }
    }
    ++pos_;
    return out;
  }

  // After "\u": four hex digits, and a low surrogate's when they are a high one.
  std::uint32_t ReadCodePoint() {
    const std::uint32_t unit = ReadHex4();
    if (unit >= 0xD800 && unit <= 0xDBFF && pos_ + 1 < text_.size() && text_[pos_] == '\\' &&
        text_[pos_ + 1] == 'u') {
      pos_ += 2;
      const std::uint32_t low = ReadHex4();
      if (low >= 0xDC00 && low <= 0xDFFF) return 0x10000 + ((unit - 0xD800) << 10) + (low - 0xDC00);
    }
    return unit;
  }

  std::uint32_t ReadHex4() {
    std::uint32_t value = 0;
    for (int k = 0; k < 4 && pos_ < text_.size(); ++k, ++pos_) {
      const char c = text_[pos_];
      const int digit = c >= '0' && c <= '9'   ? c - '0'
                        : c >= 'a' && c <= 'f' ? c - 'a' + 10
                        : c >= 'A' && c <= 'F' ? c - 'A' + 10
                                               : 0;
      value = value * 16 + static_cast<std::uint32_t>(digit);
    }
    return value;
  }

  static void AppendUtf8(std::uint32_t code, std::string* out) {
    if (code < 0x80) {
      *out += static_cast<char>(code);
    } else if (code < 0x800) {
      *out += static_cast<char>(0xC0 | (code >> 6));
      *out += static_cast<char>(0x80 | (code & 0x3F));
    } else if (code < 0x10000) {
      *out += static_cast<char>(0xE0 | (code >> 12));
      *out += static_cast<char>(0x80 | ((code >> 6) & 0x3F));
      *out += static_cast<char>(0x80 | (code & 0x3F));
    } else {
      *out += static_cast<char>(0xF0 | (code >> 18));
      *out += static_cast<char>(0x80 | ((code >> 12) & 0x3F));
      *out += static_cast<char>(0x80 | ((code >> 6) & 0x3F));
      *out += static_cast<char>(0x80 | (code & 0x3F));
    }
  }

  void SkipValue() {
    if (At('"')) {
      ReadString();
      return;
    }
    if (At('{') || At('[')) {
      int depth = 0;
      while (pos_ < text_.size()) {
        const char c = text_[pos_];
        if (c == '"') {
          ReadString();
          continue;
        }
        if (c == '{' || c == '[') ++depth;
        if (c == '}' || c == ']') --depth;
        ++pos_;
        if (depth == 0) return;
      }
      return;
    }
    while (pos_ < text_.size() && text_[pos_] != ',' && text_[pos_] != '}' && text_[pos_] != ']' &&
           text_[pos_] != ' ' && text_[pos_] != '\n' && text_[pos_] != '\r' &&
           text_[pos_] != '\t') {
      ++pos_;
    }
  }

  std::string_view text_;
  std::size_t pos_ = 0;
};

std::string Describe(const Json& value) {
  switch (value.type()) {
    case Json::value_t::null:
      return "null";
    case Json::value_t::boolean:
      return "a boolean";
    case Json::value_t::string:
      return fmt::format("the string \"{}\"", value.get_ref<const std::string&>());
    case Json::value_t::number_integer:
    case Json::value_t::number_unsigned:
    case Json::value_t::number_float:
      return fmt::format("the number {}", value.dump());
    case Json::value_t::object:
      return "an object";
    case Json::value_t::array:
      return "an array";
    default:
      return "something else";
  }
}

// Where nlohmann's parser fails, found with its SAX interface, which reports the position of
// every error.
class ParseErrorLocator : public nlohmann::json_sax<Json> {
 public:
  bool null() override { return true; }
  bool boolean(bool) override { return true; }
  bool number_integer(number_integer_t) override { return true; }
  bool number_unsigned(number_unsigned_t) override { return true; }
  bool number_float(number_float_t, const string_t&) override { return true; }
  bool string(string_t&) override { return true; }
  bool binary(binary_t&) override { return true; }
  bool start_object(std::size_t) override { return true; }
  bool key(string_t&) override { return true; }
  bool end_object() override { return true; }
  bool start_array(std::size_t) override { return true; }
  bool end_array() override { return true; }
  bool parse_error(std::size_t position, const std::string& last_token,
                   const Json::exception&) override {
    // `position` is just past the offending token: point at its first character.
    offset = position > last_token.size() ? position - last_token.size() : 0;
    return false;
  }
  std::size_t offset = 0;
};

std::size_t LocateParseError(std::string_view text) {
  ParseErrorLocator locator;
  Json::sax_parse(text.begin(), text.end(), &locator);
  return locator.offset;
}

// nlohmann's what() is "[json.exception.<kind>.<id>] " then, for syntax errors, "parse error at
// line L, column C: ", then what went wrong (which may itself contain ": ").
std::string NlohmannMessage(std::string message) {
  if (message.rfind("[json.exception.", 0) == 0) {
    if (const auto end = message.find("] "); end != std::string::npos) message.erase(0, end + 2);
  }
  if (message.rfind("parse error", 0) == 0) {
    if (const auto colon = message.find(": "); colon != std::string::npos) {
      message.erase(0, colon + 2);
    }
  }
  return message;
}

// nlohmann quotes the bytes it last read as they are: a byte that is not UTF-8, or a control
// character, would reach the terminal raw. Those are escaped (\xNN); valid UTF-8 is kept.
std::string EscapeUnprintable(std::string_view message) {
  std::string out;
  for (std::size_t at = 0; at < message.size();) {
    const std::optional<Utf8Char> c = DecodeUtf8(message, at);
    if (c && c->code >= 0x20 && c->code != 0x7F) {
      out.append(message.substr(at, c->length));
      at += c->length;
      continue;
    }
    out += fmt::format("\\x{:02x}", static_cast<unsigned char>(message[at]));
    ++at;
  }
  return out;
}

}  // namespace

TextPosition PositionInText(std::string_view text, std::size_t offset) {
  TextPosition where = PositionOfOffset(text, offset);
  where.col = CharacterColumnInText(text, offset);
  return where;
}

std::vector<TextPosition> PositionsInText(std::string_view text,
                                          std::span<const std::size_t> offsets) {
  std::vector<std::size_t> order(offsets.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::ranges::sort(order, [&](std::size_t a, std::size_t b) { return offsets[a] < offsets[b]; });
  std::vector<TextPosition> positions(offsets.size());
  std::size_t counted = 0;
  int line = 1;
  for (const std::size_t k : order) {
    const std::size_t offset = std::min(offsets[k], text.size());
    line += static_cast<int>(std::count(text.begin() + static_cast<std::ptrdiff_t>(counted),
                                        text.begin() + static_cast<std::ptrdiff_t>(offset), '\n'));
    counted = offset;
    positions[k] = {line, CharacterColumnInText(text, offset)};
  }
  return positions;
}

std::optional<std::size_t> LocateJsonPointer(std::string_view text, const JsonPointer& pointer) {
  return JsonScanner(text).Locate(pointer);
}

Result<JsonDocument> JsonDocument::Parse(std::string_view text, std::string name) {
  // A UTF-8 byte order mark (some Windows editors write one) is not part of the document: the
  // parser would skip it, but the locator of values would not, and columns count from after it.
  if (text.starts_with(kUtf8ByteOrderMark)) text.remove_prefix(kUtf8ByteOrderMark.size());
  std::size_t offset = 0;
  std::string message;
  try {
    Json json = Json::parse(text.begin(), text.end());
    return JsonDocument(text, std::move(name), std::move(json));
  } catch (const Json::parse_error& e) {
    // e.byte is 1-based and points just past the offending character.
    offset = e.byte > 0 ? e.byte - 1 : 0;
    message = e.what();
  } catch (const Json::exception& e) {
    // Other errors of the parser (a number beyond the range of double) carry no position.
    offset = LocateParseError(text);
    message = e.what();
  }
  // nlohmann reports a byte that is not UTF-8 where it saw the sequence fail, which may be the
  // byte after it (the '"' after a Latin-1 '\xe9'): the first byte that is not UTF-8 up to there
  // is the one to show.
  if (message.find("ill-formed UTF-8") != std::string::npos)
    offset = std::min(FirstNotUtf8(text), offset);
  const TextPosition where = PositionInText(text, offset);
  return Diagnostic{name, where.line, where.col,
                    "invalid JSON: " + EscapeUnprintable(NlohmannMessage(message))};
}

std::vector<std::optional<TextPosition>> JsonDocument::LocateMembersOfElements(
    const JsonPointer& array, std::span<const std::size_t> indices,
    const std::string& member) const {
  const std::vector<std::optional<std::size_t>> elements =
      JsonScanner(text_).LocateElements(array, indices);
  // The members' offsets, then their lines counted in one pass, in order of offset.
  std::vector<std::optional<std::size_t>> offsets(indices.size());
  for (std::size_t k = 0; k < indices.size(); ++k) {
    if (!elements[k]) continue;
    if (const auto at = LocateJsonPointer(text_.substr(*elements[k]), JsonPointer() / member))
      offsets[k] = *elements[k] + *at;
  }
  std::vector<std::size_t> found;
  for (const std::optional<std::size_t>& offset : offsets)
    if (offset) found.push_back(*offset);
  const std::vector<TextPosition> found_positions = PositionsInText(text_, found);
  std::vector<std::optional<TextPosition>> positions(indices.size());
  for (std::size_t k = 0, f = 0; k < indices.size(); ++k)
    if (offsets[k]) positions[k] = found_positions[f++];
  return positions;
}

Diagnostic JsonDocument::Diagnose(const JsonSchemaError& error) const {
  const std::optional<std::size_t> offset = LocateJsonPointer(text_, error.pointer);
  const TextPosition where = PositionInText(text_, offset.value_or(0));
  std::string message = error.message;
  if (!error.pointer.empty()) message += fmt::format(" (at {})", error.pointer.to_string());
  return {name_, offset ? where.line : 0, offset ? where.col : 0, std::move(message)};
}

void Fail(const JsonNode& node, std::string message) {
  throw JsonSchemaError{node.pointer, std::move(message)};
}

void RequireObject(const JsonNode& node, std::string_view what) {
  if (!node.value.is_object())
    Fail(node, fmt::format("expected {} (an object), got {}", what, Describe(node.value)));
}

namespace {

// Levenshtein distance, for suggesting the key a misspelt one was meant to be.
std::size_t EditDistance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t substitution = diagonal + (a[i - 1] == b[j - 1] ? 0 : 1);
      diagonal = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, substitution});
    }
  }
  return row[b.size()];
}

}  // namespace

void RefuseUnknownMembers(const JsonNode& object, std::span<const std::string_view> known,
                          std::string_view what) {
  for (const auto& item : object.value.items()) {
    const std::string& key = item.key();
    if (std::ranges::find(known, key) != known.end()) continue;
    std::string_view nearest;
    std::size_t nearest_distance = 3;  // at most two edits away
    for (const std::string_view candidate : known) {
      if (const std::size_t d = EditDistance(key, candidate); d < nearest_distance) {
        nearest = candidate;
        nearest_distance = d;
      }
    }
    Fail(JsonNode{item.value(), object.pointer / key},
         nearest.empty()
             ? fmt::format("unknown key \"{}\" in {}", key, what)
             : fmt::format("unknown key \"{}\" in {} (did you mean \"{}\"?)", key, what, nearest));
  }
}

JsonNode Member(const JsonNode& object, const char* key) {
  RequireObject(object, "an object");
  const auto it = object.value.find(key);
  if (it == object.value.end()) Fail(object, fmt::format("missing key \"{}\"", key));
  return {*it, object.pointer / key};
}

std::optional<JsonNode> OptionalMember(const JsonNode& object, const char* key) {
  RequireObject(object, "an object");
  const auto it = object.value.find(key);
  if (it == object.value.end()) return std::nullopt;
  return JsonNode{*it, object.pointer / key};
}

JsonNode Element(const JsonNode& array, std::size_t index) {
  return {array.value[index], array.pointer / index};
}

std::size_t ArraySize(const JsonNode& node, std::string_view what) {
  if (!node.value.is_array())
    Fail(node, fmt::format("expected {} (an array), got {}", what, Describe(node.value)));
  return node.value.size();
}

double Number(const JsonNode& node, std::string_view what) {
  const Json& v = node.value;
  if (v.is_number()) return v.get<double>();
  if (v.is_null()) return kNaN;
  if (v.is_string()) {
    const auto& s = v.get_ref<const std::string&>();
    if (s == "nan") return kNaN;
    if (s == "inf") return kInf;
    if (s == "-inf") return -kInf;
  }
  Fail(node, fmt::format("expected {} (a number), got {}", what, Describe(v)));
}

double FiniteNumber(const JsonNode& node, std::string_view what) {
  const double v = Number(node, what);
  if (!std::isfinite(v))
    Fail(node, fmt::format("expected {} (a finite number), got {}", what, Describe(node.value)));
  return v;
}

double WorldCoordinate(const JsonNode& node, std::string_view what) {
  const double v = FiniteNumber(node, what);
  if (!IsWithinWorld(v)) Fail(node, ExpectedWorldCoordinate(what, fmt::format("{}", v)));
  return v;
}

void RefuseReturnBeyondWorld(const Scan& scan, const JsonNode& readings, std::string_view what) {
  if (const std::optional<std::size_t> i = scan.FirstReturnBeyondWorld())
    Fail(Element(readings, *i),
         ExpectedReturnWithinWorld(what, fmt::format("{}", scan.ranges[*i]), scan.max_range));
}

constexpr auto kLargestInteger =
    static_cast<unsigned long long>(std::numeric_limits<long long>::max());

long long Integer(const JsonNode& node, std::string_view what) {
  const Json& v = node.value;
  // An unsigned integer beyond long long's range would wrap round to a negative one.
  if (v.is_number_unsigned() && v.get<unsigned long long>() > kLargestInteger)
    Fail(node,
         fmt::format("expected {} (an integer), got {}, which is too large", what, Describe(v)));
  if (v.is_number_integer()) return v.get<long long>();
  if (v.is_number_float()) {
    const double d = v.get<double>();
    if (std::floor(d) == d && std::abs(d) < 9e15) return static_cast<long long>(d);
  }
  Fail(node, fmt::format("expected {} (an integer), got {}", what, Describe(v)));
}

long long IntegerInRange(const JsonNode& node, std::string_view what, long long lo, long long hi) {
  const long long v = Integer(node, what);
  if (v < lo || v > hi) Fail(node, fmt::format("expected {} in [{}, {}], got {}", what, lo, hi, v));
  return v;
}

bool Boolean(const JsonNode& node, std::string_view what) {
  if (!node.value.is_boolean())
    Fail(node, fmt::format("expected {} (true or false), got {}", what, Describe(node.value)));
  return node.value.get<bool>();
}

std::string String(const JsonNode& node, std::string_view what) {
  if (!node.value.is_string())
    Fail(node, fmt::format("expected {} (a string), got {}", what, Describe(node.value)));
  return node.value.get<std::string>();
}

std::vector<double> Numbers(const JsonNode& node, std::string_view what) {
  const std::size_t n = ArraySize(node, what);
  std::vector<double> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Json& v = node.value[i];
    // The common case without building a description; Number() explains anything else.
    out[i] = v.is_number() ? v.get<double>()
                           : Number(Element(node, i), fmt::format("an element of {}", what));
  }
  return out;
}

std::vector<long long> Integers(const JsonNode& node, std::string_view what) {
  const std::size_t n = ArraySize(node, what);
  std::vector<long long> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Json& v = node.value[i];
    const bool fits = v.is_number_integer() &&
                      (!v.is_number_unsigned() || v.get<unsigned long long>() <= kLargestInteger);
    out[i] = fits ? v.get<long long>()
                  : Integer(Element(node, i), fmt::format("an element of {}", what));
  }
  return out;
}

Vec2 Point(const JsonNode& node, std::string_view what) {
  if (ArraySize(node, what) != 2) Fail(node, fmt::format("expected {} as [x, y]", what));
  return {WorldCoordinate(Element(node, 0), "x"), WorldCoordinate(Element(node, 1), "y")};
}

Se2 Pose(const JsonNode& node, std::string_view what) {
  if (ArraySize(node, what) != 3) Fail(node, fmt::format("expected {} as [x, y, theta]", what));
  return {WorldCoordinate(Element(node, 0), "x"), WorldCoordinate(Element(node, 1), "y"),
          FiniteNumber(Element(node, 2), "theta")};
}

void RequireFormat(const JsonNode& root, std::string_view format, int version) {
  RequireObject(root, fmt::format("a {} document", format));
  const JsonNode format_node = Member(root, "format");
  const std::string actual = String(format_node, "the document format");
  if (actual != format)
    Fail(format_node, fmt::format("expected format \"{}\", got \"{}\"", format, actual));
  const JsonNode version_node = Member(root, "version");
  const long long v = Integer(version_node, "the format version");
  if (v != version) {
    Fail(version_node, fmt::format("unsupported {} version {} (this priormap reads version {})",
                                   format, v, version));
  }
}

OrderedJson NumberToJson(double value) {
  if (std::isnan(value)) return nullptr;
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  return value;
}

OrderedJson NumbersToJson(const std::vector<double>& values) {
  OrderedJson array = OrderedJson::array();
  for (double v : values) array.push_back(NumberToJson(v));
  return array;
}

OrderedJson PoseToJson(const Se2& pose) {
  return {pose.x(), pose.y(), pose.theta()};
}

std::string Dump(const OrderedJson& value, int indent) {
  return value.dump(indent, ' ', false, OrderedJson::error_handler_t::replace);
}

std::string DumpOneMemberPerLine(const OrderedJson& object) {
  std::string out = "{";
  bool first = true;
  for (const auto& [key, value] : object.items()) {
    out += first ? "\n  " : ",\n  ";
    out += Dump(OrderedJson(key));
    out += ": ";
    out += Dump(value);
    first = false;
  }
  out += "\n}\n";
  return out;
}

}  // namespace priormap::detail
