// CSM laser_data JSON (docs/formats.md): a stream of JSON objects, one per scan, each read with
// the accessors of json_document.hpp; every problem is reported at file:line:col.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <climits>
#include <fmt/format.h>

#include <priormap/core/csm_io.hpp>
#include <priormap/core/file_io.hpp>

#include "json_document.hpp"
#include "scan_time_order.hpp"

namespace priormap {
namespace {

using detail::JsonNode;

constexpr double kInf = std::numeric_limits<double>::infinity();

// The pose fields of a laser_data object, in order of preference, and what each pose is.
constexpr std::array<const char*, 3> kPoseKeys = {"true_pose", "estimate", "odometry"};
constexpr std::array<PoseSource, 3> kPoseSources = {PoseSource::kGroundTruth,
                                                    PoseSource::kCorrected, PoseSource::kOdometry};
constexpr std::size_t kOdometry = 2;

// ---- finding the objects of the stream ----

bool IsBlank(char c) {
  return c == ' ' || c == '\n' || c == '\r' || c == '\t';
}

std::size_t SkipBlanks(std::string_view text, std::size_t pos) {
  while (pos < text.size() && IsBlank(text[pos])) ++pos;
  return pos;
}

// One past the closing quote of the string that starts at text[pos] == '"'; npos when the
// string does not end.
std::size_t SkipString(std::string_view text, std::size_t pos) {
  for (++pos; pos < text.size(); ++pos) {
    if (text[pos] == '\\') {
      ++pos;
    } else if (text[pos] == '"') {
      return pos + 1;
    }
  }
  return std::string_view::npos;
}

// One past the end of the object or array that starts at text[pos], found by counting brackets
// outside strings; text.size() when it does not close. Exact for valid JSON; in anything else
// the JSON parser then reports the problem within the part found.
std::size_t SkipNested(std::string_view text, std::size_t pos) {
  std::size_t depth = 0;
  while (pos < text.size()) {
    const char c = text[pos];
    if (c == '"') {
      pos = SkipString(text, pos);
      if (pos == std::string_view::npos) return text.size();
      continue;
    }
    if (c == '{' || c == '[') {
      ++depth;
    } else if ((c == '}' || c == ']') && depth > 0) {
      --depth;
    }
    ++pos;
    if (depth == 0) return pos;
  }
  return text.size();
}

// One past the end of the value that starts at text[pos] (a string, an object or array, or a
// literal); text.size() when it does not end.
std::size_t SkipValue(std::string_view text, std::size_t pos) {
  if (pos >= text.size()) return text.size();
  if (text[pos] == '"') return std::min(SkipString(text, pos), text.size());
  if (text[pos] == '{' || text[pos] == '[') return SkipNested(text, pos);
  while (pos < text.size() && !IsBlank(text[pos]) && text[pos] != ',' && text[pos] != '}' &&
         text[pos] != ']') {
    ++pos;
  }
  return pos;
}

// ---- one laser_data object ----

struct CsmScan {
  Scan scan;
  std::array<std::optional<Se2>, 3> poses;  // by kPoseKeys
  bool stamped = false;                     // has a "timestamp"
  std::size_t start = 0, end = 0;           // the object's bytes in the text
};

std::string Quoted(const char* key) {
  return fmt::format("\"{}\"", key);
}

// The size of the array `node` (member `key`), which must be `n`.
void RequireSize(const JsonNode& node, const char* key, std::size_t n) {
  const std::size_t size = detail::ArraySize(node, Quoted(key));
  if (size != n)
    detail::Fail(node, fmt::format("expected nrays = {} values in \"{}\", got {}", n, key, size));
}

// A pose member: [x, y, theta] of numbers, or unknown (absent, null, or [null, null, null], as
// CSM writes a pose it does not have).
std::optional<Se2> ReadPose(const JsonNode& object, const char* key) {
  const auto node = detail::OptionalMember(object, key);
  if (!node || node->value.is_null()) return std::nullopt;
  const std::size_t size = detail::ArraySize(*node, Quoted(key));
  if (size != 3)
    detail::Fail(*node, fmt::format("expected \"{}\" as [x, y, theta], got {} values", key, size));
  constexpr std::array<const char*, 3> kAxes = {"x", "y", "theta"};
  std::array<double, 3> v{};
  for (std::size_t k = 0; k < 3; ++k)
    v[k] = detail::Number(detail::Element(*node, k), fmt::format("\"{}\" {}", key, kAxes[k]));
  if (std::all_of(v.begin(), v.end(), [](double x) { return std::isnan(x); })) return std::nullopt;
  if (!std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); }))
    detail::Fail(*node, fmt::format("expected \"{}\" as [x, y, theta] of finite numbers, or "
                                    "[null, null, null] when unknown",
                                    key));
  for (std::size_t k = 0; k < 2; ++k)  // finite now: only the world's bound is left to check
    (void)detail::WorldCoordinate(detail::Element(*node, k),
                                  fmt::format("\"{}\" {}", key, kAxes[k]));
  return Se2(v[0], v[1], v[2]);
}

// The beam angles: "theta" when it is there and known, else evenly spaced from "min_theta" to
// "max_theta" inclusive (CSM's convention: theta[0] = min_theta, theta[n-1] = max_theta).
std::vector<double> ReadAngles(const JsonNode& object, std::size_t n) {
  if (const auto theta = detail::OptionalMember(object, "theta")) {
    RequireSize(*theta, "theta", n);
    // CSM writes the angles it does not know as null: all null means "not given".
    const bool unknown = std::all_of(theta->value.begin(), theta->value.end(),
                                     [](const detail::Json& v) { return v.is_null(); });
    if (!unknown) {
      std::vector<double> angles(n);
      for (std::size_t i = 0; i < n; ++i) {
        const JsonNode e = detail::Element(*theta, i);
        angles[i] = detail::FiniteNumber(e, "an element of \"theta\"");
        if (i > 0 && !(angles[i] > angles[i - 1]))
          detail::Fail(e, fmt::format("expected increasing angles in \"theta\", got {} after {}",
                                      angles[i], angles[i - 1]));
      }
      return angles;
    }
  }
  const auto min = detail::OptionalMember(object, "min_theta");
  const auto max = detail::OptionalMember(object, "max_theta");
  if (!min || !max) detail::Fail(object, "expected \"theta\", or \"min_theta\" and \"max_theta\"");
  const double first = detail::FiniteNumber(*min, "\"min_theta\"");
  const double last = detail::FiniteNumber(*max, "\"max_theta\"");
  if (n > 1 && !(last > first))
    detail::Fail(
        *max, fmt::format("expected \"max_theta\" above \"min_theta\" = {}, got {}", first, last));
  std::vector<double> angles = EvenlySpacedAngles(n, first, last);
  for (std::size_t i = 1; i < n; ++i) {
    if (!(angles[i] > angles[i - 1]))
      detail::Fail(*max, fmt::format("\"min_theta\" {} and \"max_theta\" {} do not give {} "
                                     "increasing beam angles",
                                     first, last, n));
  }
  return angles;
}

CsmScan ReadScan(const JsonNode& root, const CsmReadOptions& options) {
  detail::RequireObject(root, "a CSM laser_data object");
  CsmScan result;
  Scan& scan = result.scan;
  scan.channel = "CSM";
  const auto n = static_cast<std::size_t>(
      detail::IntegerInRange(detail::Member(root, "nrays"), "\"nrays\"", 1, INT_MAX));

  // Every array is checked for its length before anything of size n is allocated, so that a
  // short document with a large nrays cannot make the reader allocate gigabytes.
  const JsonNode readings = detail::Member(root, "readings");
  RequireSize(readings, "readings", n);
  scan.ranges = detail::Numbers(readings, "\"readings\"");  // null is NaN: no reading
  scan.angles = ReadAngles(root, n);

  scan.sigma.assign(n, options.sigma);
  if (const auto sigma = detail::OptionalMember(root, "readings_sigma");
      sigma && !sigma->value.is_null()) {
    RequireSize(*sigma, "readings_sigma", n);
    for (std::size_t i = 0; i < n; ++i) {
      const JsonNode e = detail::Element(*sigma, i);
      const double s = detail::Number(e, "an element of \"readings_sigma\"");
      if (std::isnan(s)) continue;  // unknown: the default
      if (!(s > 0.0 && std::isfinite(s)))
        detail::Fail(e, fmt::format("expected an element of \"readings_sigma\" (a standard "
                                    "deviation > 0, m, or null), got {}",
                                    s));
      scan.sigma[i] = s;
    }
  }

  scan.min_range = options.min_range;
  scan.max_range = options.max_range.value_or(kInf);
  scan.ClassifyAll();
  if (const auto valid = detail::OptionalMember(root, "valid")) {
    RequireSize(*valid, "valid", n);
    for (std::size_t i = 0; i < n; ++i) {
      if (detail::IntegerInRange(detail::Element(*valid, i), "an element of \"valid\"", 0, 1) == 0)
        scan.status[i] = BeamStatus::kInvalid;
    }
  }
  // At the reading, like a position beyond the world at its coordinate; only once the statuses
  // are known, as a reading flagged invalid or a no-return one is kept whatever its value.
  detail::RefuseReturnBeyondWorld(scan, readings, "an element of \"readings\"");

  if (const auto stamp = detail::OptionalMember(root, "timestamp");
      stamp && !stamp->value.is_null()) {
    if (detail::ArraySize(*stamp, "\"timestamp\"") != 2)
      detail::Fail(*stamp, "expected \"timestamp\" as [seconds, microseconds]");
    const double seconds = detail::FiniteNumber(detail::Element(*stamp, 0), "the seconds");
    const double micros = detail::FiniteNumber(detail::Element(*stamp, 1), "the microseconds");
    scan.timestamp = seconds + micros / 1e6;
    result.stamped = std::isfinite(scan.timestamp);
  }

  for (std::size_t k = 0; k < kPoseKeys.size(); ++k) result.poses[k] = ReadPose(root, kPoseKeys[k]);
  if (std::none_of(result.poses.begin(), result.poses.end(),
                   [](const std::optional<Se2>& pose) { return pose.has_value(); }))
    detail::Fail(root,
                 "no pose: expected \"true_pose\", \"estimate\" or \"odometry\" as [x, y, theta] "
                 "of finite numbers");
  scan.odom_pose = result.poses[kOdometry];
  // The pose is chosen once every scan is read; any of them gives a consistent scan.
  for (const std::optional<Se2>& pose : result.poses) {
    if (pose) {
      scan.pose = *pose;
      break;
    }
  }
  if (const std::vector<std::string> problems = scan.Problems(); !problems.empty())
    detail::Fail(root, "inconsistent scan: " + problems.front());
  return result;
}

// Diagnostics of the object that starts at byte `start` of `text`, which count lines and columns
// from that object, moved to count from the start of `text`. A diagnostic without a position
// (a value the locator could not find) is placed at the object.
std::vector<Diagnostic> InText(std::vector<Diagnostic> diagnostics, std::string_view text,
                               std::size_t start) {
  const TextPosition base = detail::PositionInText(text, start);
  for (Diagnostic& d : diagnostics) {
    if (d.line <= 0) {
      d.line = base.line;
      d.col = base.col;
      continue;
    }
    if (d.line == 1) d.col += base.col - 1;
    d.line += base.line - 1;
  }
  return diagnostics;
}

// The warnings of the scans stamped before the previous one (scan_time_order.hpp), at their
// "timestamp"; the objects, valid JSON, are searched again for it.
std::vector<Diagnostic> TimeOrderWarnings(const std::vector<CsmScan>& scans, std::string_view text,
                                          const std::string& name) {
  std::vector<detail::StampedScan> stamped;
  for (std::size_t k = 0; k < scans.size(); ++k)
    if (scans[k].stamped) stamped.push_back({k, scans[k].scan.channel, scans[k].scan.timestamp});
  return detail::TimeOrderWarnings(stamped, [&](std::span<const std::size_t> located) {
    std::vector<std::size_t> offsets;
    for (const std::size_t k : located) {
      const std::string_view object = text.substr(scans[k].start, scans[k].end - scans[k].start);
      const detail::JsonPointer timestamp("/timestamp");
      offsets.push_back(scans[k].start + detail::LocateJsonPointer(object, timestamp).value_or(0));
    }
    std::vector<Diagnostic> diagnostics;
    for (const TextPosition& at : detail::PositionsInText(text, offsets))
      diagnostics.push_back({name, at.line, at.col, ""});
    return diagnostics;
  });
}

Result<Log> Parse(std::string_view text, const std::string& name, const CsmReadOptions& options) {
  std::vector<CsmScan> scans;
  std::size_t pos = SkipBlanks(text, 0);
  if (pos == text.size()) {
    const TextPosition end = detail::PositionInText(text, pos);
    return Diagnostic{name, end.line, end.col,
                      "no CSM laser_data objects: expected one JSON object per scan"};
  }
  while (pos < text.size()) {
    if (text[pos] != '{') {
      const TextPosition where = detail::PositionInText(text, pos);
      const std::size_t line_end = std::min(text.find('\n', pos), text.size());
      return Diagnostic{name, where.line, where.col,
                        fmt::format("expected a CSM laser_data object ('{{') or the end of the "
                                    "input, got {}",
                                    QuoteForMessage(text.substr(pos, line_end - pos), 20))};
    }
    const std::size_t end = SkipNested(text, pos);
    const std::string_view object = text.substr(pos, end - pos);
    Result<detail::JsonDocument> document = detail::JsonDocument::Parse(object, name);
    if (!document) return InText(document.diagnostics(), text, pos);
    try {
      scans.push_back(ReadScan(document.value().root(), options));
    } catch (const detail::JsonSchemaError& error) {
      return InText({document.value().Diagnose(error)}, text, pos);
    }
    scans.back().start = pos;
    scans.back().end = end;
    pos = SkipBlanks(text, end);
  }

  // One kind of pose for the whole log when every scan has it.
  std::optional<std::size_t> common;
  for (std::size_t k = 0; k < kPoseKeys.size() && !common; ++k) {
    if (std::all_of(scans.begin(), scans.end(),
                    [&](const CsmScan& s) { return s.poses[k].has_value(); }))
      common = k;
  }
  std::vector<Diagnostic> warnings = TimeOrderWarnings(scans, text, name);
  Log log;
  log.pose_source = common ? kPoseSources[*common] : PoseSource::kUnknown;
  log.scans.reserve(scans.size());
  for (CsmScan& s : scans) {
    if (common) s.scan.pose = *s.poses[*common];  // else the scan's own first, set when read
    log.scans.push_back(std::move(s.scan));
  }
  return Result<Log>(std::move(log), std::move(warnings));
}

}  // namespace

Result<Log> ParseCsmLog(std::string_view text, const std::string& name,
                        const CsmReadOptions& options) {
  const double max_range = options.max_range.value_or(kInf);
  if (!(options.min_range >= 0.0) || !(max_range > options.min_range))
    return Diagnostic{"", 0, 0,
                      fmt::format("CSM reading: need 0 <= min_range < max_range (got {} and {})",
                                  options.min_range, max_range)};
  if (!(options.sigma > 0.0 && std::isfinite(options.sigma)))
    return Diagnostic{
        "", 0, 0,
        fmt::format("CSM reading: sigma must be positive and finite, got {}", options.sigma)};
  if (text.starts_with(kUtf8ByteOrderMark)) text.remove_prefix(kUtf8ByteOrderMark.size());
  return Parse(text, name, options);
}

Result<Log> ReadCsmLog(const std::filesystem::path& path, const CsmReadOptions& options) {
  Result<std::string> text = ReadFileText(path);
  if (!text) return text.diagnostics();
  return ParseCsmLog(text.value(), path.string(), options);
}

bool LooksLikeCsmLog(std::string_view text) {
  std::size_t pos = SkipBlanks(text, 0);
  if (pos >= text.size() || text[pos] != '{') return false;
  bool nrays = false, readings = false;
  for (++pos;;) {
    pos = SkipBlanks(text, pos);
    if (pos >= text.size() || text[pos] != '"') return false;
    const std::size_t key_end = SkipString(text, pos);
    if (key_end == std::string_view::npos) return false;
    const std::string_view key = text.substr(pos + 1, key_end - pos - 2);
    if (key == "format") return false;  // priormap's documents
    nrays = nrays || key == "nrays";
    readings = readings || key == "readings";
    if (nrays && readings) return true;
    pos = SkipBlanks(text, key_end);
    if (pos >= text.size() || text[pos] != ':') return false;
    pos = SkipBlanks(text, SkipValue(text, SkipBlanks(text, pos + 1)));
    if (pos >= text.size() || text[pos] != ',') return false;
    ++pos;
  }
}

}  // namespace priormap
