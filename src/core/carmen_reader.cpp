// Reader for CARMEN logs. Record layouts (fields after the record name):
//   FLASER / RLASER  n r_1..r_n x y theta odom_x odom_y odom_theta [ipc_timestamp host
//   logger_timestamp] ROBOTLASER1      laser_type start_angle fov angular_resolution max_range
//   accuracy remission_mode
//                    n r_1..r_n m e_1..e_m laser_x laser_y laser_theta robot_x robot_y robot_theta
//                    tv rv forward_safety_dist side_safety_dist turn_axis [timestamps]
//   ODOM             x y theta tv rv accel [timestamps]
//   TRUEPOS          true_x true_y true_theta odom_x odom_y odom_theta [timestamps]
//   PARAM            name value...
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/carmen_io.hpp>
#include <priormap/core/file_io.hpp>
#include <priormap/core/utf8.hpp>
#include <priormap/core/world_bounds.hpp>

#include "gunzip.hpp"
#include "number_text.hpp"
#include "scan_time_order.hpp"

namespace priormap {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct Token {
  std::string_view text;
  int col = 0;  // 1-based
};

// Fields are separated by runs of spaces, tabs and carriage returns; any other byte belongs to
// a field.
bool IsSeparator(char c) {
  // Most bytes are field bytes above ' ': one comparison settles them.
  return static_cast<unsigned char>(c) <= ' ' && (c == ' ' || c == '\t' || c == '\r');
}

void Tokenize(std::string_view line, std::vector<Token>& tokens) {
  tokens.clear();
  const char* const begin = line.data();
  const char* const end = begin + line.size();
  const char* p = begin;
  for (;;) {
    while (p != end && IsSeparator(*p)) ++p;
    if (p == end) return;
    const char* const start = p;
    while (p != end && !IsSeparator(*p)) ++p;
    tokens.push_back({std::string_view(start, static_cast<std::size_t>(p - start)),
                      static_cast<int>(start - begin) + 1});
  }
}

using detail::ParseDouble;
using detail::ParseInteger;

// A field that failed to parse: its diagnostic is already recorded.
struct FieldError {};

// Reads the fields of one record left to right, reporting the first problem precisely.
class FieldReader {
 public:
  FieldReader(const std::vector<Token>& tokens, std::string_view record, int line_length)
      : tokens_(tokens), record_(record), line_length_(line_length) {}

  std::size_t remaining() const { return tokens_.size() - next_; }
  std::size_t next_index() const { return next_; }
  const Token& token(std::size_t index) const { return tokens_[index]; }
  int next_col() const { return next_ < tokens_.size() ? tokens_[next_].col : line_length_ + 1; }

  double Number(std::string_view what) {
    const Token& t = Take(what);
    if (const auto v = ParseDouble(t.text)) return *v;
    return Fail(t.col,
                fmt::format("expected {} (a number), got {}", what, QuoteForMessage(t.text)));
  }

  double FiniteNumber(std::string_view what) {
    const std::size_t index = next_;
    const double v = Number(what);
    if (!std::isfinite(v)) {
      Fail(tokens_[index].col,
           fmt::format("{} must be finite, got {}", what, QuoteForMessage(tokens_[index].text)));
    }
    return v;
  }

  // A count of fields that follow, which must leave room for `fields_after` more fields.
  long long Count(std::string_view what, std::size_t fields_after, std::string_view after_what) {
    const Token& t = Take(what);
    const auto v = ParseInteger(t.text);
    if (!v || *v < 0) {
      Fail(t.col, fmt::format("expected {} (a non-negative integer), got {}", what,
                              QuoteForMessage(t.text)));
    }
    const std::size_t available = remaining();
    if (available < fields_after ||
        static_cast<unsigned long long>(*v) > available - fields_after) {
      Fail(t.col,
           fmt::format("{} is {}, but only {} fields follow it (expected {} values, then {})", what,
                       *v, available, *v, after_what));
    }
    return *v;
  }

  int Integer(std::string_view what) {
    const Token& t = Take(what);
    const auto v = ParseInteger(t.text);
    if (!v || *v < std::numeric_limits<int>::min() || *v > std::numeric_limits<int>::max()) {
      Fail(t.col, fmt::format("expected {} (an integer), got {}", what, QuoteForMessage(t.text)));
    }
    return static_cast<int>(*v);
  }

  // `count` numbers, every one finite when `finite`, if the next `count` fields are such; false
  // (and nothing read) otherwise, for the field-by-field path to report what is wrong. The fast
  // path of whole records.
  bool TryNumbers(double* values, std::size_t count, bool finite) {
    if (remaining() < count) return false;
    for (std::size_t k = 0; k < count; ++k) {
      const auto v = ParseDouble(tokens_[next_ + k].text);
      if (!v || (finite && !std::isfinite(*v))) return false;
      values[k] = *v;
    }
    next_ += count;
    return true;
  }

  // A pose whose position lies within the world (world_bounds.hpp): a finite but absurd x of
  // 1e300 is reported here, at its field, not later as a grid too large to make.
  Se2 Pose(std::string_view what) {
    if (std::array<double, 3> v{}; TryNumbers(v.data(), 3, true)) {
      if (IsWithinWorld(v[0]) && IsWithinWorld(v[1])) return {v[0], v[1], v[2]};
      next_ -= 3;  // read them again, one by one, to report the coordinate beyond the world
    }
    return PoseFieldByField(what);
  }

  Se2 PoseFieldByField(std::string_view what) {
    std::array<double, 3> v{};
    constexpr std::array<std::string_view, 3> kAxes{"x", "y", "theta"};
    for (std::size_t k = 0; k < 3; ++k) {
      // The label of the diagnostic is formatted only when there is one to report.
      const auto parsed = next_ < tokens_.size() ? ParseDouble(tokens_[next_].text) : std::nullopt;
      if (parsed && std::isfinite(*parsed)) {
        v[k] = *parsed;
        ++next_;
      } else {
        v[k] = FiniteNumber(fmt::format("{} {}", what, kAxes[k]));
      }
      if (k < 2 && !IsWithinWorld(v[k])) {
        const Token& t = tokens_[next_ - 1];
        Fail(t.col, ExpectedWorldCoordinate(fmt::format("{} {}", what, kAxes[k]),
                                            QuoteForMessage(t.text)));
      }
    }
    return {v[0], v[1], v[2]};
  }

  std::string_view Word(std::string_view what) { return Take(what).text; }

  // The optional "ipc_timestamp host logger_timestamp" tail, then the end of the record.
  CarmenRecordFields Timestamps(double* timestamp) {
    CarmenRecordFields fields;
    if (remaining() == 0) {
      fields.has_timestamps = false;
      *timestamp = 0.0;
      return fields;
    }
    timestamp_col_ = next_col();
    *timestamp = FiniteNumber("ipc_timestamp");
    host_ = &Take("host");
    fields.host = std::string(host_->text);
    fields.logger_timestamp = FiniteNumber("logger_timestamp");
    End();
    return fields;
  }

  void End() {
    if (remaining() > 0) {
      Fail(tokens_[next_].col, fmt::format("unexpected extra field {} at the end of the {} record",
                                           QuoteForMessage(tokens_[next_].text), record_));
    }
  }

  [[noreturn]] double Fail(int col, std::string message) {
    error_col_ = col;
    error_ = std::move(message);
    throw FieldError{};
  }

  // The host field of the timestamps read, if any.
  const Token* host() const { return host_; }
  // The byte column of the ipc_timestamp read, if any (0 otherwise).
  int timestamp_col() const { return timestamp_col_; }

  int error_col() const { return error_col_; }
  const std::string& error() const { return error_; }

 private:
  const Token& Take(std::string_view what) {
    if (next_ >= tokens_.size()) {
      Fail(line_length_ + 1, fmt::format("{} record ends early: expected {}", record_, what));
    }
    return tokens_[next_++];
  }

  const std::vector<Token>& tokens_;
  std::string_view record_;
  int line_length_;
  std::size_t next_ = 1;  // token 0 is the record name
  const Token* host_ = nullptr;
  int timestamp_col_ = 0;
  int error_col_ = 0;
  std::string error_;
};

CarmenLaserFields LaserFieldsFrom(const CarmenRecordFields& fields) {
  CarmenLaserFields laser;
  laser.has_timestamps = fields.has_timestamps;
  laser.host = fields.host;
  laser.logger_timestamp = fields.logger_timestamp;
  return laser;
}

class CarmenParser {
 public:
  CarmenParser(const std::string& name, const CarmenReadOptions& options, CarmenReadStats& stats)
      : name_(name), options_(options), stats_(stats) {}

  Result<Log> Parse(std::string_view text) {
    Reserve(text);
    int line_number = 0;
    // A UTF-8 byte order mark (some Windows editors write one) is not part of the first record.
    std::size_t start = text.starts_with(kUtf8ByteOrderMark) ? kUtf8ByteOrderMark.size() : 0;
    while (start < text.size() && !TooManyErrors()) {
      std::size_t end = text.find('\n', start);
      if (end == std::string_view::npos) end = text.size();
      std::string_view line = text.substr(start, end - start);
      // CRLF files: without the '\r', columns past the end of a line match what editors show.
      if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
      ParseLine(line, ++line_number);
      start = end + 1;
    }
    if (!diagnostics_.empty()) return diagnostics_;
    if (log_.NumRecords() == 0) {
      return Diagnostic{name_, 0, 0,
                        "no CARMEN records found: expected lines starting with FLASER, RLASER, "
                        "ROBOTLASER1, ODOM, TRUEPOS or PARAM"};
    }
    if (std::vector<Diagnostic> problems = FinishScans(); !problems.empty()) return problems;
    return Result<Log>(std::move(log_), std::move(time_order_).Warnings());
  }

 private:
  // The records' vectors sized once, from a count of the lines by their first field: each
  // reallocation of a vector of megabytes is fresh memory, whose page faults cost more than
  // this pass.
  void Reserve(std::string_view text) {
    std::size_t scans = 0, odometry = 0, true_poses = 0, params = 0;
    const auto starts = [](std::string_view line, std::string_view type) {
      return line.substr(0, type.size()) == type && line.size() > type.size() &&
             IsSeparator(line[type.size()]);
    };
    for (std::size_t start = 0; start < text.size();) {
      std::size_t end = text.find('\n', start);
      if (end == std::string_view::npos) end = text.size();
      std::string_view line = text.substr(start, end - start);
      while (!line.empty() && IsSeparator(line.front())) line.remove_prefix(1);
      if (starts(line, "ODOM")) {
        ++odometry;
      } else if (starts(line, "FLASER") || starts(line, "RLASER") || starts(line, "ROBOTLASER1")) {
        ++scans;
      } else if (starts(line, "TRUEPOS")) {
        ++true_poses;
      } else if (starts(line, "PARAM")) {
        ++params;
      }
      start = end + 1;
    }
    log_.scans.reserve(scans);
    own_max_ranges_.reserve(scans);
    scan_lines_.reserve(scans);
    log_.odometry.reserve(odometry);
    log_.true_poses.reserve(true_poses);
    log_.params.reserve(params);
    log_.order.reserve(scans + odometry + true_poses + params);
  }

  // The column of the line being parsed, in characters as an editor counts them, of its 1-based
  // byte column `byte_col` (fields are found by bytes; "Zürich" is 6 columns wide, not 7); 0,
  // unknown, stays 0.
  int Column(int byte_col) const {
    if (byte_col <= 0) return 0;
    return CharacterColumn(line_, static_cast<std::size_t>(byte_col - 1));
  }

  // At least one diagnostic is always allowed: with max_diagnostics <= 0 nothing would be read
  // and a valid log would be reported as having no records.
  bool TooManyErrors() const {
    return static_cast<int>(diagnostics_.size()) >= std::max(options_.max_diagnostics, 1);
  }

  void ParseLine(std::string_view line, int line_number) {
    line_number_ = line_number;
    line_ = line;
    Tokenize(line, tokens_);  // one buffer for every line: no allocation per line
    const std::vector<Token>& tokens = tokens_;
    if (tokens.empty()) return;
    const std::string_view type = tokens[0].text;
    if (type.front() == '#') {
      ++stats_.comment_lines;
      return;
    }
    // Most lines repeat the previous one's type: its counter is kept (map nodes do not move).
    if (type != last_type_) {
      last_type_count_ = &stats_.records[std::string(type)];
      last_type_.assign(type);
    }
    ++*last_type_count_;
    FieldReader fields(tokens, type, static_cast<int>(line.size()));
    try {
      if (type == "FLASER" || type == "RLASER") {
        ParseOldLaser(fields, type);
      } else if (type == "ROBOTLASER1") {
        ParseRobotLaser(fields);
      } else if (type == "ODOM") {
        ParseOdometry(fields);
      } else if (type == "TRUEPOS") {
        ParseTruePose(fields);
      } else if (type == "PARAM") {
        ParseParam(tokens, line);
      }
      if (const Token* host = fields.host()) NoteIfNotUtf8(host->text, host->col, "a host name");
    } catch (const FieldError&) {
      diagnostics_.push_back({name_, line_number, Column(fields.error_col()), fields.error()});
      if (TooManyErrors()) {
        diagnostics_.push_back({name_, line_number, 0, "too many errors; stopped reading"});
      }
    }
  }

  std::vector<double> Readings(FieldReader& fields, long long n) {
    const std::size_t first = fields.next_index();
    std::vector<double> ranges(static_cast<std::size_t>(n));
    if (!fields.TryNumbers(ranges.data(), ranges.size(), false))
      for (double& r : ranges) r = fields.Number("a range reading");
    NoteOverlongReadings(fields, first, ranges);
    return ranges;
  }

  // A reading longer than any return may be is an error only if it is a return, which the max
  // range, known once every scan is read, decides; until then its place is kept. A no-echo code
  // that large puts one in every no-return beam, so an entry is small: its text is a view into
  // the text being parsed. A line that fails after its readings leaves entries of a scan never
  // added, harmless as a log with errors is not finished.
  void NoteOverlongReadings(const FieldReader& fields, std::size_t first,
                            const std::vector<double>& ranges) {
    for (std::size_t i = 0; i < ranges.size(); ++i) {
      if (IsReturnWithinWorld(ranges[i]) || !std::isfinite(ranges[i])) continue;
      const Token& t = fields.token(first + i);
      overlong_.push_back({log_.scans.size(), i, line_number_, t.col, t.text, line_});
    }
  }

  void ParseOldLaser(FieldReader& fields, std::string_view type) {
    const int count_col = fields.next_col();
    const long long n = fields.Count("the number of readings", 6, "6 pose values");
    // The readings and the two poses are followed by all three timestamp fields or by none. Any
    // other number of fields means the count disagrees with the line (a reading missing or
    // extra, a truncated tail); parsing on would report that far from its cause, e.g. a host
    // name where a timestamp was expected.
    const std::size_t after = fields.remaining();
    const std::size_t expected = static_cast<std::size_t>(n) + 6;
    if (after != expected && after != expected + 3) {
      fields.Fail(count_col,
                  fmt::format("the number of readings is {}, but {} fields follow it (expected {} "
                              "values, then 6 pose values and optionally ipc_timestamp host "
                              "logger_timestamp: {} or {} fields)",
                              n, after, n, expected, expected + 3));
    }
    Scan scan;
    scan.channel = std::string(type);
    scan.ranges = Readings(fields, n);
    scan.angles = FlaserBeamAngles(scan.ranges.size(), options_.fov);
    scan.pose = fields.Pose("laser pose");
    scan.odom_pose = fields.Pose("odometry pose");
    scan.carmen = LaserFieldsFrom(fields.Timestamps(&scan.timestamp));
    AddScan(std::move(scan), std::nullopt, fields);
  }

  void ParseRobotLaser(FieldReader& fields) {
    Scan scan;
    scan.channel = "ROBOTLASER1";
    CarmenLaserFields laser;
    laser.laser_type = fields.Integer("laser_type");
    const double start_angle = fields.FiniteNumber("start_angle");
    const double fov = fields.FiniteNumber("field_of_view");
    const int resolution_col = fields.next_col();
    const double resolution = fields.FiniteNumber("angular_resolution");
    const double max_range = fields.Number("maximum_range");
    laser.accuracy = fields.Number("accuracy");
    laser.remission_mode = fields.Integer("remission_mode");
    const long long n = fields.Count("the number of readings", 12,
                                     "the remission count, 6 pose values and 5 safety values");
    if (n > 1 && !(resolution > 0.0)) {
      fields.Fail(resolution_col,
                  fmt::format("angular_resolution must be positive, got {}", resolution));
    }
    scan.angles.resize(static_cast<std::size_t>(n));
    for (std::size_t i = 0; i < scan.angles.size(); ++i) {
      scan.angles[i] = start_angle + static_cast<double>(i) * resolution;
      // A resolution below the spacing of doubles near start_angle, or one so large that the
      // angles overflow, would give a scan whose angles do not increase.
      if (!std::isfinite(scan.angles[i]) || (i > 0 && !(scan.angles[i] > scan.angles[i - 1]))) {
        fields.Fail(resolution_col,
                    fmt::format("start_angle {} and angular_resolution {} do not give {} "
                                "increasing, finite beam angles",
                                start_angle, resolution, n));
      }
    }
    scan.ranges = Readings(fields, n);
    const long long m =
        fields.Count("the number of remissions", 11, "6 pose values and 5 safety values");
    laser.remissions.resize(static_cast<std::size_t>(m));
    for (double& e : laser.remissions) e = fields.Number("a remission value");
    laser.start_angle = start_angle;
    laser.fov = fov;
    laser.angular_resolution = resolution;
    laser.maximum_range = max_range;
    scan.pose = fields.Pose("laser pose");
    scan.robot_pose = fields.Pose("robot pose");
    laser.tv = fields.Number("tv");
    laser.rv = fields.Number("rv");
    laser.forward_safety_dist = fields.Number("forward_safety_dist");
    laser.side_safety_dist = fields.Number("side_safety_dist");
    laser.turn_axis = fields.Number("turn_axis");
    const CarmenRecordFields stamps = fields.Timestamps(&scan.timestamp);
    laser.has_timestamps = stamps.has_timestamps;
    laser.host = stamps.host;
    laser.logger_timestamp = stamps.logger_timestamp;
    scan.carmen = std::move(laser);
    AddScan(std::move(scan), max_range > 0.0 ? std::optional<double>(max_range) : std::nullopt,
            fields);
  }

  void ParseOdometry(FieldReader& fields) {
    OdometryRecord odom;
    odom.pose = fields.Pose("odometry pose");
    odom.tv = fields.Number("tv");
    odom.rv = fields.Number("rv");
    odom.accel = fields.Number("accel");
    odom.carmen = fields.Timestamps(&odom.timestamp);
    log_.order.push_back({Log::RecordKind::kOdometry, log_.odometry.size()});
    log_.odometry.push_back(std::move(odom));
  }

  void ParseTruePose(FieldReader& fields) {
    TruePoseRecord record;
    record.true_pose = fields.Pose("true pose");
    record.odom_pose = fields.Pose("odometry pose");
    record.carmen = fields.Timestamps(&record.timestamp);
    log_.order.push_back({Log::RecordKind::kTruePose, log_.true_poses.size()});
    log_.true_poses.push_back(std::move(record));
  }

  void ParseParam(const std::vector<Token>& tokens, std::string_view line) {
    if (tokens.size() < 2) return;  // a PARAM without a name carries nothing
    std::string value;
    if (tokens.size() > 2) {
      value = std::string(line.substr(static_cast<std::size_t>(tokens[2].col - 1)));
      while (!value.empty() && (value.back() == '\r' || value.back() == ' ')) value.pop_back();
    }
    NoteIfNotUtf8(tokens[1].text, tokens[1].col, "a PARAM name");
    if (tokens.size() > 2) NoteIfNotUtf8(value, tokens[2].col, "a PARAM value");
    log_.order.push_back({Log::RecordKind::kParam, log_.params.size()});
    log_.params.emplace_back(std::string(tokens[1].text), std::move(value));
  }

  // Old logs may hold Latin-1 text. It is kept as read, and located for the writers that need
  // UTF-8: the first one is enough to tell the user what to re-encode.
  void NoteIfNotUtf8(std::string_view text, int col, std::string_view what) {
    if (stats_.not_utf8) return;
    const std::size_t at = FirstNotUtf8(text);
    if (at == std::string_view::npos) return;
    stats_.not_utf8 = Diagnostic{name_, line_number_, Column(col + static_cast<int>(at)),
                                 fmt::format("expected UTF-8 text in {}, got byte {}", what,
                                             QuoteForMessage(text.substr(at, 1)))};
  }

  void AddScan(Scan scan, std::optional<double> own_max_range, const FieldReader& fields) {
    // Kept as read, with a warning at its ipc_timestamp (scan_time_order.hpp).
    if (scan.carmen && scan.carmen->has_timestamps) {
      const std::size_t k = log_.scans.size();
      if (const auto previous = time_order_.Note(scan.channel, k, scan.timestamp, line_number_))
        time_order_.Warn({name_, line_number_, Column(fields.timestamp_col()), ""}, scan.channel, k,
                         scan.timestamp, *previous);
    }
    scan.sigma.assign(scan.ranges.size(), options_.sigma);
    scan.min_range = options_.min_range;
    own_max_ranges_.push_back(own_max_range);
    scan_lines_.push_back(line_number_);
    log_.order.push_back({Log::RecordKind::kScan, log_.scans.size()});
    log_.scans.push_back(std::move(scan));
  }

  // Max range, per scan: the record's own (ROBOTLASER1 carries one), else the no-return
  // sentinel detected among the scans without their own (FLASER/RLASER carry none), else none
  // (+inf); the caller's where it is shorter, or where there is none: a longer one would make
  // the no-return readings walls. Detection needs every reading, so statuses are set last, and
  // so are the returns checked against the world's bound.
  std::vector<Diagnostic> FinishScans() {
    // The scans' readings in place: a copy of them all is megabytes of fresh pages.
    std::vector<std::span<const double>> readings;
    readings.reserve(log_.scans.size());
    for (std::size_t k = 0; k < log_.scans.size(); ++k)
      if (!own_max_ranges_[k]) readings.emplace_back(log_.scans[k].ranges);
    stats_.detected_max_range = DetectMaxRangeSentinel(readings);
    for (std::size_t k = 0; k < log_.scans.size(); ++k) {
      Scan& scan = log_.scans[k];
      const double sensor = own_max_ranges_[k].value_or(stats_.detected_max_range.value_or(kInf));
      scan.max_range = std::min(options_.max_range.value_or(kInf), sensor);
      if (!(scan.max_range > scan.min_range)) {
        // A minimum range the caller chose at or beyond the sensor's reach leaves no reading
        // that could be valid; else (a caller's max range <= 0) the scan has no known reach.
        if (options_.min_range > 0.0) return {MinRangeBeyondReach(k, sensor)};
        scan.max_range = kInf;
      }
      scan.ClassifyAll();
    }
    log_.pose_source = options_.pose_source;
    return OverlongReturns();
  }

  // At scan k's record, with the max range that applies there and where it comes from, since
  // the user can change only the value that the message names.
  Diagnostic MinRangeBeyondReach(std::size_t k, double sensor) const {
    std::string source;
    if (options_.max_range && *options_.max_range <= sensor) {
      source = fmt::format("from {}", options_.max_range_name);
    } else {
      source = own_max_ranges_[k] ? "its ROBOTLASER1 record's maximum_range"
                                  : "detected from the no-return readings of the FLASER and "
                                    "RLASER lines";
      if (options_.max_range)
        source += fmt::format(" ({} {} m is longer, and can only shorten it)",
                              options_.max_range_name, *options_.max_range);
    }
    return {name_, scan_lines_[k], 0,
            fmt::format("{} {} m is not below the max range of scan {}, {} m, {}: no reading "
                        "could be valid",
                        options_.min_range_name, options_.min_range, k, log_.scans[k].max_range,
                        source)};
  }

  // At the reading, like a position beyond the world at its coordinate.
  std::vector<Diagnostic> OverlongReturns() {
    std::vector<Diagnostic> diagnostics;
    for (const OverlongReading& r : overlong_) {
      const Scan& scan = log_.scans[r.scan];
      if (!scan.IsValid(r.index)) continue;
      diagnostics.push_back(
          {name_, r.line, CharacterColumn(r.line_text, static_cast<std::size_t>(r.col - 1)),
           ExpectedReturnWithinWorld("a range reading", QuoteForMessage(r.text), scan.max_range)});
      if (static_cast<int>(diagnostics.size()) >= std::max(options_.max_diagnostics, 1)) {
        diagnostics.push_back({name_, r.line, 0, "too many errors; stopped reading"});
        break;
      }
    }
    return diagnostics;
  }

  const std::string& name_;
  const CarmenReadOptions& options_;
  CarmenReadStats& stats_;
  Log log_;
  std::vector<std::optional<double>> own_max_ranges_;
  std::vector<int> scan_lines_;  // each scan's line, for diagnostics about the whole scan
  struct OverlongReading {
    std::size_t scan, index;
    int line, col;               // col in bytes, made a column in characters when reported
    std::string_view text;       // into the text being parsed
    std::string_view line_text;  // likewise
  };
  std::vector<OverlongReading> overlong_;
  int line_number_ = 0;
  std::string_view line_;  // the line being parsed
  std::vector<Diagnostic> diagnostics_;
  detail::ScanTimeOrder time_order_;
  std::vector<Token> tokens_;
  std::string last_type_;
  int* last_type_count_ = nullptr;
};

}  // namespace

std::vector<double> FlaserBeamAngles(std::size_t n, double fov) {
  if (n == 180 || n == 360) {
    // Evaluated as first + i * step, like every evenly spaced angle set in priormap, so that
    // writers can store (first, step) and readers rebuild the same doubles.
    const double step = fov / static_cast<double>(n);
    std::vector<double> angles(n);
    for (std::size_t i = 0; i < n; ++i) angles[i] = -fov / 2 + static_cast<double>(i) * step;
    return angles;
  }
  return EvenlySpacedAngles(n, -fov / 2, fov / 2);
}

Result<Log> ParseCarmenLog(std::string_view text, const std::string& name,
                           const CarmenReadOptions& options, CarmenReadStats* stats) {
  CarmenReadStats local_stats;
  CarmenParser parser(name, options, stats ? *stats : local_stats);
  return parser.Parse(text);
}

Result<Log> ReadCarmenLog(const std::filesystem::path& path, const CarmenReadOptions& options,
                          CarmenReadStats* stats) {
  const Result<detail::ByteBuffer> bytes = detail::ReadWholeFile(path);
  if (!bytes) return bytes.diagnostics();
  return ParseCarmenLog(bytes.value().view(), path.string(), options, stats);
}

}  // namespace priormap
