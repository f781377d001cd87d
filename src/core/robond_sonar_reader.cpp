// The RoboND sonar files (docs/formats.md): two whitespace-separated text files, read line by
// line in step, every problem reported at its file:line:col.
#include <algorithm>
#include <charconv>
#include <cmath>

#include <fmt/format.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/file_io.hpp>
#include <priormap/core/robond_sonar_io.hpp>
#include <priormap/core/utf8.hpp>
#include <priormap/core/world_bounds.hpp>

namespace priormap {
namespace {

struct Token {
  std::string_view text;
  int col = 0;  // 1-based, in characters as an editor counts them
};

// One non-blank line of a file, split at spaces and tabs.
struct Line {
  int number = 0;   // 1-based
  int end_col = 0;  // one past the last character, where a missing field is reported
  std::vector<Token> tokens;
};

std::vector<Line> SplitLines(std::string_view text) {
  std::vector<Line> lines;
  int number = 0;
  // A UTF-8 byte order mark (some Windows editors write one) is not part of the first line's
  // time field: it is skipped, as the other readers skip it, and columns count from after it.
  std::size_t start = text.starts_with(kUtf8ByteOrderMark) ? kUtf8ByteOrderMark.size() : 0;
  while (start < text.size()) {
    ++number;
    std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(start, end - start);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    Line parsed{.number = number, .end_col = CharacterColumn(line, line.size()), .tokens = {}};
    ColumnCounter columns(line);
    std::size_t i = 0;
    while (i < line.size()) {
      if (line[i] == ' ' || line[i] == '\t') {
        ++i;
        continue;
      }
      const std::size_t token_start = i;
      while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
      parsed.tokens.push_back({line.substr(token_start, i - token_start), columns.At(token_start)});
    }
    if (!parsed.tokens.empty()) lines.push_back(std::move(parsed));
    start = end + 1;
  }
  return lines;
}

// Thrown with the diagnostic of the first problem; caught at the entry point.
struct ParseFailure {
  Diagnostic diagnostic;
};

[[noreturn]] void Fail(const std::string& file, int line, int col, std::string message) {
  throw ParseFailure{{file, line, col, std::move(message)}};
}

// The fields of one line, each a finite number.
class Fields {
 public:
  Fields(const std::string& file, const Line& line, std::size_t expected, const char* layout)
      : file_(file), line_(line) {
    if (line.tokens.size() > expected)
      Fail(file, line.number, line.tokens[expected].col,
           fmt::format("expected {} fields ({}), found more: {}", expected, layout,
                       QuoteForMessage(line.tokens[expected].text)));
    if (line.tokens.size() < expected)
      Fail(file, line.number, line.end_col,
           fmt::format("expected {} fields ({}), got {}", expected, layout, line.tokens.size()));
  }

  [[nodiscard]] double Number(std::size_t i, const char* what) const {
    const Token& t = line_.tokens[i];
    std::string_view text = t.text;
    if (text.size() > 1 && text.front() == '+' && text[1] != '-') text.remove_prefix(1);
    double value = 0.0;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (error != std::errc() || end != text.data() + text.size() || !std::isfinite(value))
      Fail(file_, line_.number, t.col,
           fmt::format("expected {} (a finite number), got {}", what, QuoteForMessage(t.text)));
    return value;
  }
  // A coordinate of the world written in mm, in metres: within the bound of world_bounds.hpp.
  [[nodiscard]] double WorldMillimetres(std::size_t i, const char* what) const {
    const double mm = Number(i, what);
    if (!IsWithinWorld(mm / 1000.0))
      Fail(file_, line_.number, col(i),
           fmt::format("expected {} at most {:.0e} in magnitude (priormap's bound of {:.0e} m on "
                       "world coordinates), got {}",
                       what, kMaxWorldCoordinate * 1000.0, kMaxWorldCoordinate,
                       QuoteForMessage(line_.tokens[i].text)));
    return mm / 1000.0;
  }
  [[nodiscard]] int col(std::size_t i) const { return line_.tokens[i].col; }

 private:
  const std::string& file_;
  const Line& line_;
};

constexpr std::size_t kRingSize = 8;

Log Parse(std::string_view measurements, const std::string& measurements_name,
          std::string_view poses, const std::string& poses_name,
          const RoboNdSonarOptions& options) {
  const std::vector<Line> z_lines = SplitLines(measurements);
  const std::vector<Line> pose_lines = SplitLines(poses);
  if (z_lines.empty()) Fail(measurements_name, 1, 1, "no measurement lines (t_ms z_0 .. z_7)");
  // The lines are read in step before their counts are compared, so that a line split in two,
  // two lines joined or a line lost in the middle of one file is reported where the files go
  // out of step (a field count or a time that differs), not as a count at the end.
  const std::size_t rings = std::min(z_lines.size(), pose_lines.size());
  Log log;
  log.pose_source = PoseSource::kGroundTruth;
  const double max_range = options.no_echo_mm / 1000.0;
  double previous_t = 0.0;  // ms, the previous line's
  for (std::size_t k = 0; k < rings; ++k) {
    const Fields z(measurements_name, z_lines[k], 1 + kRingSize, "t_ms and 8 ranges in mm");
    const Fields p(poses_name, pose_lines[k], 4, "t_ms, x_mm, y_mm, theta in tenths of a degree");
    const double t_z = z.Number(0, "a time in ms");
    // The rings are a time series: a repeated or earlier time is a line copied or moved in the
    // file (the real files' times increase strictly, 205 to 428 ms apart), not a second ring at the
    // same instant. Checked before the poses' time, so that a line repeated in the
    // measurements alone is reported there, not as the poses' time that differs.
    if (k > 0 && !(t_z > previous_t))
      Fail(measurements_name, z_lines[k].number, z.col(0),
           fmt::format("expected a time after the previous line's {} ms ({}:{}), got {} ms",
                       previous_t, measurements_name, z_lines[k - 1].number, t_z));
    const double t_pose = p.Number(0, "a time in ms");
    if (t_pose != t_z)
      Fail(poses_name, pose_lines[k].number, p.col(0),
           fmt::format("time {} ms differs from the {} ms of {}:{} (line {} of each file must be "
                       "the same ring)",
                       t_pose, t_z, measurements_name, z_lines[k].number, k + 1));
    previous_t = t_z;
    Scan scan;
    scan.channel = "SONAR";
    scan.timestamp = t_z / 1000.0;
    scan.pose = Se2(p.WorldMillimetres(1, "x in mm"), p.WorldMillimetres(2, "y in mm"),
                    WrapAngle(DegToRad(p.Number(3, "theta in tenths of a degree") / 10.0)));
    scan.angles = options.bearings;
    scan.min_range = options.min_range;
    scan.max_range = max_range;
    for (std::size_t i = 0; i < kRingSize; ++i) {
      const double mm = z.Number(1 + i, "a range in mm");
      if (mm < 0.0)
        Fail(measurements_name, z_lines[k].number, z.col(1 + i),
             fmt::format("expected a range in mm >= 0, got {}", mm));
      // As read, like the laser readers: ClassifyAll makes those at or beyond the max range
      // max-range readings.
      const double range = mm / 1000.0;
      scan.ranges.push_back(range);
      scan.sigma.push_back(std::max(options.sigma_min, options.sigma_relative * range));
    }
    scan.ClassifyAll();
    scan.sonar.emplace().spread = options.spread;
    // At the reading, like a position beyond the world at its coordinate (a caller's no-echo
    // value beyond the bound lets a return be that long).
    if (const std::optional<std::size_t> i = scan.FirstReturnBeyondWorld())
      Fail(measurements_name, z_lines[k].number, z.col(1 + *i),
           ExpectedReturnWithinWorld("a range", fmt::format("{} mm", scan.ranges[*i] * 1000.0),
                                     scan.max_range));
    log.scans.push_back(std::move(scan));
  }
  if (z_lines.size() != pose_lines.size()) {
    const bool fewer_poses = pose_lines.size() < z_lines.size();
    const std::string& name = fewer_poses ? poses_name : measurements_name;
    const Line& unmatched = fewer_poses ? z_lines[rings] : pose_lines[rings];
    Fail(fewer_poses ? measurements_name : poses_name, unmatched.number, 1,
         fmt::format("this is line {} with data, but {} has {} (one pose per measurement line)",
                     rings + 1, name, rings));
  }
  return log;
}

}  // namespace

std::vector<double> RoboNdSonarOptions::RoboNdBearings() {
  std::vector<double> bearings;
  for (double degrees : {-90.0, -37.5, -22.5, -7.5, 7.5, 22.5, 37.5, 90.0})
    bearings.push_back(DegToRad(degrees));
  return bearings;
}

Result<Log> ParseRoboNdSonar(std::string_view measurements, const std::string& measurements_name,
                             std::string_view poses, const std::string& poses_name,
                             const RoboNdSonarOptions& options) {
  if (options.bearings.size() != kRingSize)
    return Diagnostic{"", 0, 0,
                      fmt::format("the RoboND ring has {} transducers; {} bearings given",
                                  kRingSize, options.bearings.size())};
  // Checked here, not per ring: with no reading able to be valid, every scan would fail the
  // log's own check, and only when the written log was read back.
  if (!(options.min_range >= 0.0 && options.min_range < options.no_echo_mm / 1000.0))
    return Diagnostic{"", 0, 0,
                      fmt::format("need 0 <= min range < max range (got {} m and {} m)",
                                  options.min_range, options.no_echo_mm / 1000.0)};
  try {
    return Parse(measurements, measurements_name, poses, poses_name, options);
  } catch (const ParseFailure& failure) {
    return failure.diagnostic;
  }
}

Result<Log> ReadRoboNdSonar(const std::filesystem::path& measurements,
                            const std::filesystem::path& poses, const RoboNdSonarOptions& options) {
  Result<std::string> z = ReadFileText(measurements);
  if (!z) return z.diagnostics();
  Result<std::string> p = ReadFileText(poses);
  if (!p) return p.diagnostics();
  return ParseRoboNdSonar(z.value(), measurements.string(), p.value(), poses.string(), options);
}

}  // namespace priormap
