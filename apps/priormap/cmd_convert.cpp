// priormap convert: between CARMEN logs (plain or .gz) and priormap JSON; from CSM's laser_data
// JSON and from the RoboND sonar files (a measurement file and a pose file) to either.
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/csm_io.hpp>
#include <priormap/core/file_io.hpp>
#include <priormap/core/log_io.hpp>
#include <priormap/core/robond_sonar_io.hpp>

#include "cli_support.hpp"
#include "commands.hpp"

namespace priormap::app {
namespace {

constexpr const char* kRoboNdSonar = "roboND-sonar";

struct ConvertOptions {
  std::string input;
  std::optional<std::string> robond_poses;  // the second file of --from roboND-sonar
  std::string out;
  std::optional<std::string> from, to;
  std::optional<double> max_range, min_range, fov_deg, sigma;
  std::optional<std::string> poses;
};

void RefuseMinRangeNotBelowMaxRange(const ConvertOptions& o) {
  if (o.min_range && o.max_range && !(*o.min_range < *o.max_range))
    throw UserError(
        fmt::format("--min-range {} must be below --max-range {}", *o.min_range, *o.max_range));
}

// The RoboND sonar files, converted as documented in docs/formats.md.
Log ReadRoboNd(const ConvertOptions& o) {
  if (!o.robond_poses)
    throw UserError(
        fmt::format("--from {} reads two files: measurement.txt poses.txt", kRoboNdSonar));
  if (o.fov_deg || o.sigma)
    throw UserError(fmt::format(
        "{} is for laser formats: the RoboND rings' 20 deg cones and 1 % noise are fixed",
        o.fov_deg ? "--fov" : "--sigma"));
  RoboNdSonarOptions options;
  if (o.min_range) options.min_range = *o.min_range;
  if (o.max_range) {
    // The sensor reports "no echo" as 5110 mm: a max range beyond it would make each of those
    // readings a wall at 5.11 m. A shorter one is fine: the readings beyond it become max-range.
    const double sensor_max_range = RoboNdSonarOptions{}.no_echo_mm / 1000.0;
    if (*o.max_range > sensor_max_range)
      throw UserError(
          fmt::format("--max-range {} m: with --from {} it can be at most {} m, where the sensor's "
                      "\"no echo\" readings lie",
                      *o.max_range, kRoboNdSonar, sensor_max_range));
    options.no_echo_mm = *o.max_range * 1000.0;
  }
  // Checked here, not left to the reader, whose message can only name its own fields (and not
  // say that the other limit is the sensor's, not one the user gave).
  RefuseMinRangeNotBelowMaxRange(o);
  const double max_range = options.no_echo_mm / 1000.0;
  if (o.min_range && !(*o.min_range < max_range))
    throw UserError(fmt::format(
        "--min-range {} m: with --from {} it must be below the max range, the sensor's {} m "
        "(its \"no echo\" reading)",
        *o.min_range, kRoboNdSonar, max_range));
  if (o.max_range && !(options.min_range < max_range))
    throw UserError(fmt::format(
        "--max-range {} m: with --from {} it must be above the min range, the sensor's {} m, or "
        "above a lower --min-range",
        *o.max_range, kRoboNdSonar, options.min_range));
  Log log = ValueOrThrow(ReadRoboNdSonar(o.input, *o.robond_poses, options));
  if (o.poses) log.pose_source = *PoseSourceFromString(*o.poses);
  return log;
}

// The scans' max ranges, each with its count where they differ, and where they come from: the
// records' own (ROBOTLASER1), the no-return readings detected in the others, or --max-range,
// which shortens the sensor's but never lengthens it.
std::string CarmenMaxRangeSummary(const Log& log, const CarmenReadStats& stats,
                                  const std::optional<double>& given) {
  if (log.scans.empty()) return "none (no scans)";
  constexpr double kNone = std::numeric_limits<double>::infinity();
  std::map<double, std::size_t> scans_by_range;
  for (const Scan& scan : log.scans) ++scans_by_range[scan.max_range];
  if (scans_by_range.size() == 1 && scans_by_range.contains(kNone))
    return "none detected; no reading is treated as max-range (use --max-range)";
  std::string summary;
  for (const auto& [range, scans] : scans_by_range) {
    if (!summary.empty()) summary += ", ";
    summary += std::isinf(range) ? std::string("none") : fmt::format("{} m", range);
    if (scans_by_range.size() > 1) summary += fmt::format(" ({})", Plural(scans, "scan"));
  }
  std::string sources;
  const auto add = [&](const std::string& source) {
    sources += (sources.empty() ? "" : "; ") + source;
  };
  if (given)
    add(scans_by_range.contains(*given)
            ? fmt::format("--max-range {} m where the sensor's is longer", *given)
            : fmt::format("--max-range {} m is beyond every scan's own and was not applied",
                          *given));
  if (stats.detected_max_range)
    add(fmt::format("detected: {} m, from the FLASER lines' no-return readings",
                    *stats.detected_max_range));
  if (stats.records.contains("ROBOTLASER1")) add("the ROBOTLASER1 records' own");
  if (scans_by_range.contains(kNone)) add("none: no reading of a scan without one is max-range");
  return sources.empty() ? summary : fmt::format("{} ({})", summary, sources);
}

// A JSON log carries its own ranges, limits and noise, and csm's laser_data its own field of
// view: options that the reader of the input's format would drop are refused, not ignored.
void RefuseOptionsTheFormatIgnores(const ConvertOptions& o, LogFormat from,
                                   const std::string& input) {
  std::vector<std::string> ignored;
  if (from == LogFormat::kJson) {
    if (o.max_range) ignored.emplace_back("--max-range");
    if (o.min_range) ignored.emplace_back("--min-range");
    if (o.sigma) ignored.emplace_back("--sigma");
  }
  if (from != LogFormat::kCarmen && o.fov_deg) ignored.emplace_back("--fov");
  if (!ignored.empty())
    throw UserError(fmt::format("{} {} for other formats: {} is {}, whose scans carry their own",
                                fmt::join(ignored, ", "), ignored.size() == 1 ? "is" : "are", input,
                                ToString(from)));
  RefuseMinRangeNotBelowMaxRange(o);
}

void Run(const ConvertOptions& o) {
  const bool robond = o.from && *o.from == kRoboNdSonar;
  if (!robond && o.robond_poses)
    throw UserError(
        fmt::format("convert reads one log (two files only with --from {})", kRoboNdSonar));
  // The output replaces its file only once written, but it would still replace the input: a log
  // converted onto itself loses its original bytes, and with a lossy format its data.
  RequireDistinctFiles({{"the input", o.input}, {"--out", o.out}});
  if (o.robond_poses) RequireDistinctFiles({{"the poses file", *o.robond_poses}, {"--out", o.out}});
  const std::string& input = o.input;
  const LogFormat to = OutputLogFormat(o.to, o.out, "--out", "--to");
  CarmenReadOptions carmen;
  carmen.min_range_name = "--min-range";
  carmen.max_range_name = "--max-range";
  carmen.max_range = o.max_range;
  if (o.min_range) carmen.min_range = *o.min_range;
  if (o.fov_deg) carmen.fov = DegToRad(*o.fov_deg);
  if (o.sigma) carmen.sigma = *o.sigma;
  if (o.poses) carmen.pose_source = *PoseSourceFromString(*o.poses);

  std::optional<LogFormat> from;
  CarmenReadStats stats;
  Log log;
  if (robond) {
    log = ReadRoboNd(o);
  } else {
    const std::string text = ValueOrThrow(ReadFileText(input));
    from = o.from ? *LogFormatFromString(*o.from) : SniffLogFormat(text);
    RefuseOptionsTheFormatIgnores(o, *from, input);
    switch (*from) {
      case LogFormat::kJson:
        log = ValueOrThrow(ParseJsonLog(text, input));
        break;
      case LogFormat::kCsm: {
        CsmReadOptions csm;
        if (o.min_range) csm.min_range = *o.min_range;
        csm.max_range = o.max_range;
        if (o.sigma) csm.sigma = *o.sigma;
        log = ValueOrThrow(ParseCsmLog(text, input, csm));
        break;
      }
      case LogFormat::kCarmen:
        log = ValueOrThrow(ParseCarmenLog(text, input, carmen, &stats));
        // JSON's writer would replace the bytes by U+FFFD, a loss no warning could undo.
        if (to == LogFormat::kJson && stats.not_utf8)
          throw UserError(
              DescribeDiagnostics({*stats.not_utf8}) +
              ": JSON holds only UTF-8; re-encode the log (e.g. iconv -f latin1 -t utf-8) or "
              "convert to CARMEN, which keeps the bytes");
        break;
    }
    if (from != LogFormat::kCarmen && o.poses) log.pose_source = carmen.pose_source;
  }

  const auto rings = std::count_if(log.scans.begin(), log.scans.end(),
                                   [](const Scan& scan) { return scan.sonar.has_value(); });
  // CARMEN's laser records have no cone: a ring written there would come back as a laser scan.
  if (to == LogFormat::kCarmen && rings > 0)
    throw UserError(
        fmt::format("{} holds {} sonar rings, which CARMEN cannot carry; write "
                    "priormap JSON (.json or .json.gz)",
                    input, rings));
  WriteLogWarningOfLosses(log, o.out, to);

  std::size_t valid = 0, max_range = 0, invalid = 0;
  for (const Scan& scan : log.scans) {
    for (BeamStatus s : scan.status) {
      valid += s == BeamStatus::kValid;
      max_range += s == BeamStatus::kMaxRange;
      invalid += s == BeamStatus::kInvalid;
    }
  }
  fmt::print("read {} ({}): {}{}, {} odometry, {} true poses, {} params\n",
             o.robond_poses ? fmt::format("{} {}", o.input, *o.robond_poses) : o.input,
             from ? ToString(*from) : kRoboNdSonar, Plural(log.scans.size(), "scan"),
             rings > 0 ? fmt::format(" ({} sonar rings)", rings) : "", log.odometry.size(),
             log.true_poses.size(), log.params.size());
  fmt::print("readings: {} valid, {} max-range, {} invalid\n", valid, max_range, invalid);
  if (from == LogFormat::kCarmen) {
    fmt::print("max range: {}\n", CarmenMaxRangeSummary(log, stats, o.max_range));
    std::vector<std::string> skipped;
    for (const auto& [type, count] : stats.records) {
      if (type != "FLASER" && type != "RLASER" && type != "ROBOTLASER1" && type != "ODOM" &&
          type != "TRUEPOS" && type != "PARAM") {
        skipped.push_back(fmt::format("{} {}", count, type));
      }
    }
    if (!skipped.empty()) fmt::print("skipped records: {}\n", fmt::join(skipped, ", "));
  }
  fmt::print("wrote {} ({})\n", o.out, ToString(to));
}

}  // namespace

void AddConvertCommand(CLI::App& app) {
  auto o = std::make_shared<ConvertOptions>();
  CLI::App* cmd = app.add_subcommand(
      "convert",
      "Convert a log between CARMEN (plain or .gz) and priormap JSON, or CSM laser_data JSON "
      "(--from csm) or the RoboND sonar files (--from roboND-sonar measurement.txt poses.txt) to "
      "priormap JSON");
  cmd->add_option("input", o->input, "Input log (with --from roboND-sonar: measurement.txt)")
      ->required();
  cmd->add_option("poses-file", o->robond_poses, "With --from roboND-sonar: poses.txt");
  cmd->add_option("-o,--out", o->out,
                  "Output file: .json / .json.gz (JSON) or .log / .log.gz (CARMEN; also .clf, "
                  ".carmen, .txt); .gz compresses")
      ->required();
  cmd->add_option("--from", o->from, "Input format (default: from the content)")
      ->check(CLI::IsMember({"carmen", "json", "csm", kRoboNdSonar}));
  cmd->add_option("--to", o->to, "Output format (default: from the extension)")
      ->check(CLI::IsMember({"carmen", "json"}));
  cmd->add_option("--max-range", o->max_range,
                  "CARMEN: readings at or above this are max-range, where it is shorter than "
                  "the sensor's (default: detected); csm: the same (default: none); "
                  "roboND-sonar: the same, at most the sensor's 5.11 m, its no-echo reading "
                  "(the default)")
      ->check(PositiveValue());
  cmd->add_option("--min-range", o->min_range,
                  "CARMEN, csm and roboND-sonar: readings below this are invalid (roboND "
                  "default: 0.17 m)")
      ->check(NonNegativeValue());
  cmd->add_option("--fov", o->fov_deg,
                  "CARMEN: field of view of FLASER/RLASER lines, degrees (default 180)")
      ->check(CLI::Range(0.01, 360.0));
  cmd->add_option("--sigma", o->sigma,
                  "CARMEN: range noise standard deviation given to every reading, m; csm: to "
                  "readings without their own readings_sigma")
      ->check(PositiveValue());
  cmd->add_option("--poses", o->poses,
                  "What the scan poses are: unknown, odometry, corrected, ground_truth")
      ->check(CLI::IsMember({"unknown", "odometry", "corrected", "ground_truth"}));
  cmd->callback([o] { Run(*o); });
}

}  // namespace priormap::app
