#include "cli_support.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <system_error>
#include <unistd.h>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <priormap/core/file_io.hpp>
#include <priormap/core/json_io.hpp>
#include <priormap/core/sonar_sensor.hpp>
#include <priormap/core/world_bounds.hpp>
#include <priormap/render/figure.hpp>

namespace priormap::app {

namespace {

CLI::Validator SignCheck(bool allow_zero) {
  return NumberValidator(
      [allow_zero](double value, const std::string& text) -> std::string {
        if (!std::isfinite(value)) return text + " is not a finite number";
        if (allow_zero ? value >= 0.0 : value > 0.0) return {};
        return text + (allow_zero ? " is negative (expected a number >= 0)"
                                  : " is not positive (expected a number > 0)");
      },
      allow_zero ? "NONNEGATIVE" : "POSITIVE");
}

}  // namespace

CLI::Validator PositiveValue() {
  return SignCheck(false);
}

CLI::Validator NonNegativeValue() {
  return SignCheck(true);
}

CLI::Validator PositiveValueUpTo(double max, const std::string& unit) {
  return NumberValidator(
      [max, unit](double value, const std::string& text) -> std::string {
        if (std::isfinite(value) && value > 0.0 && value <= max) return {};
        return fmt::format("{} is not in (0, {}] {}", text, max, unit);
      },
      fmt::format("POSITIVE up to {}", max));
}

CLI::Validator OpenUnitInterval() {
  return NumberValidator(
      [](double value, const std::string& text) -> std::string {
        if (value > 0.0 && value < 1.0) return {};
        return fmt::format("{} is not in (0, 1), 0 and 1 excluded", text);
      },
      "PROBABILITY in (0, 1)");
}

CLI::Validator Probability() {
  return NumberValidator(
      [](double value, const std::string& text) -> std::string {
        if (value >= 0.0 && value <= 1.0) return {};
        return fmt::format("{} is not a probability (expected a number in [0, 1])", text);
      },
      "PROBABILITY");
}

CLI::Validator SonarPresetName() {
  return CLI::Validator(
      [](std::string& name) -> std::string {
        if (SonarSensor::Preset(name)) return {};
        return fmt::format("unknown sonar '{}' (expected one of: {})", name,
                           fmt::join(SonarSensor::PresetNames(), ", "));
      },
      "");
}

void RefuseNonFiniteNumbers(CLI::App& app) {
  const CLI::Validator finite(
      [](std::string& text) -> std::string {
        double value = 0.0;
        // Text that is no number is left to the option's own conversion, which says so.
        if (!CLI::detail::lexical_cast(text, value) || std::isfinite(value)) return {};
        return text + " is not a finite number";
      },
      "");
  for (CLI::Option* option : app.get_options()) {
    // Every floating-point option, with or without validators ("FLOAT", "FLOAT:POSITIVE").
    if (option->get_type_name().starts_with("FLOAT")) option->check(finite);
  }
  for (CLI::App* command : app.get_subcommands([](CLI::App*) { return true; }))
    RefuseNonFiniteNumbers(*command);
}

void RequireCarmenForMaxRange(const std::string& input, LogFormat read_as,
                              const std::optional<double>& max_range) {
  if (max_range && read_as != LogFormat::kCarmen)
    throw UserError(fmt::format(
        "--max-range is for CARMEN input: {} is {}, whose scans carry their own max range", input,
        ToString(read_as)));
}

CLI::Validator WholeNumber(std::uint64_t max, const std::string& what) {
  return CLI::Validator(
      [max, what](std::string& text) -> std::string {
        std::uint64_t value = 0;
        const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
        if (error == std::errc() && end == text.data() + text.size() && value <= max) {
          text = std::to_string(value);  // decimal, as CLI11 would not read "0100"
          return {};
        }
        return fmt::format("'{}' is not {} (expected a whole number from 0 to {})", text, what,
                           max);
      },
      "");
}

CLI::Validator StepCount() {
  return WholeNumber(kMaxStepCount, "a step count").description("STEPS");
}

CLI::Validator SeedValue() {
  return WholeNumber(std::numeric_limits<std::uint64_t>::max(), "a seed");
}

CLI::Validator IndexValue() {
  return WholeNumber(std::numeric_limits<std::uint64_t>::max(), "an index");
}

std::string DescribeDiagnostics(const std::vector<Diagnostic>& diagnostics) {
  std::string out;
  for (const Diagnostic& d : diagnostics) {
    if (!out.empty()) out += '\n';
    const std::string where = d.Location();
    out += where.empty() ? d.message : where + ": " + d.message;
  }
  return out;
}

Se2 ParsePose(const std::string& text) {
  double values[3];
  std::size_t start = 0;
  for (int k = 0; k < 3; ++k) {
    const std::size_t end = k < 2 ? text.find(',', start) : text.size();
    if (end == std::string::npos) break;
    const char* first = text.data() + start;
    const char* last = text.data() + end;
    const auto [ptr, ec] = std::from_chars(first, last, values[k]);
    if (ec != std::errc() || ptr != last || !std::isfinite(values[k])) {
      throw UserError(fmt::format("--pose: expected x,y,theta (three numbers), got '{}'", text));
    }
    // A pose the readers would refuse: the scan written would not read back.
    if (k < 2 && !IsWithinWorld(values[k])) {
      throw UserError("--pose: " +
                      ExpectedWorldCoordinate(k == 0 ? "x" : "y", fmt::format("{}", values[k])));
    }
    if (k == 2) return {values[0], values[1], values[2]};
    start = end + 1;
  }
  throw UserError(fmt::format("--pose: expected x,y,theta (three numbers), got '{}'", text));
}

dsl::PriorLibrary MakePriorLibrary(const std::vector<std::string>& prior_path) {
  return dsl::PriorLibrary::WithEnvironment({prior_path.begin(), prior_path.end()});
}

void RemoveFinishedCheckpoints(const std::filesystem::path& checkpoints) {
  std::error_code ec;
  std::filesystem::remove_all(checkpoints, ec);
  if (ec)
    fmt::print(stderr,
               "priormap: warning: the outputs are written, but {} could not be removed ({}): "
               "remove it by hand (a --resume would run again from what is left of it)\n",
               checkpoints.string(), ec.message());
}

void PrintWarnings(const std::vector<Diagnostic>& warnings) {
  for (const Diagnostic& d : warnings) {
    const std::string where = d.Location();
    fmt::print(stderr, "priormap: warning: {}{}\n", where.empty() ? "" : where + ": ", d.message);
  }
}

void PrintPriorWarnings(const dsl::CompiledPrior& prior) {
  PrintWarnings(prior.warnings());
}

dsl::CompiledPrior LoadPrior(const std::vector<std::string>& prior_path, const std::string& name) {
  dsl::CompiledPrior prior = ValueOrThrow(MakePriorLibrary(prior_path).Load(name));
  PrintPriorWarnings(prior);
  return prior;
}

Scene LoadScene(const std::string& name_or_path, std::string_view option) {
  if (std::optional<Scene> builtin = BuiltinScene(name_or_path)) return *std::move(builtin);
  if (std::filesystem::exists(name_or_path)) return ValueOrThrow(ReadJsonScene(name_or_path));
  throw UserError(fmt::format("{}: unknown scene '{}' (expected one of: {}; or a scene JSON file)",
                              option, name_or_path, fmt::join(BuiltinSceneNames(), ", ")));
}

CLI::Validator FigurePath() {
  return CLI::Validator(
      [](std::string& path) -> std::string {
        if (render::IsSupportedFigurePath(path)) return {};
        return fmt::format("'{}' must end in .png, .svg or .pdf", path);
      },
      "");
}

void RequireOutputDirectory(const std::filesystem::path& path, const std::string& option) {
  const std::filesystem::path directory = path.parent_path().empty() ? "." : path.parent_path();
  std::error_code ec;
  if (!std::filesystem::is_directory(directory, ec)) {
    throw UserError(fmt::format("{}: cannot write '{}': directory {} does not exist", option,
                                path.string(), directory.string()));
  }
  if (std::filesystem::is_directory(path, ec))
    throw UserError(fmt::format("{}: cannot write '{}': it is a directory", option, path.string()));
}

void WriteLogWarningOfLosses(const Log& log, const std::filesystem::path& path, LogFormat format) {
  if (format == LogFormat::kCarmen) {
    const std::vector<std::string> losses = CarmenLosses(log);
    if (!losses.empty())
      fmt::print(stderr,
                 "priormap: warning: {}: CARMEN cannot hold {}; write priormap JSON (.json) to "
                 "keep them\n",
                 path.string(), fmt::join(losses, ", "));
  }
  WriteLog(log, path, format);
}

LogFormat OutputLogFormat(const std::optional<std::string>& format_name,
                          const std::filesystem::path& path, const std::string& option,
                          const std::string& format_option) {
  if (format_name) return LogFormatFromString(*format_name).value();
  const std::optional<LogFormat> format = LogFormatFromPath(path);
  if (!format)
    throw UserError(fmt::format(
        "{} {}: no log format has this extension; use .json or .json.gz (priormap JSON), or "
        ".log or .log.gz (CARMEN), or name the format ({} json or {} carmen)",
        option, path.string(), format_option, format_option));
  return *format;
}

void RequireDistinctFiles(const std::vector<std::pair<std::string, std::string>>& files) {
  struct Seen {
    const std::string& option;
    const std::string& path;  // as given
    std::filesystem::path resolved;
  };
  std::vector<Seen> seen;
  for (const auto& [option, path] : files) {
    if (path.empty()) continue;
    std::error_code ec;  // a path that cannot be resolved is compared as given
    std::filesystem::path resolved = std::filesystem::weakly_canonical(path, ec);
    if (ec) resolved = std::filesystem::path(path).lexically_normal();
    // Both paths as given: through a link or another spelling, neither alone tells the file.
    for (const Seen& earlier : seen)
      if (earlier.resolved == resolved)
        throw UserError(
            fmt::format("{} {} and {} {} are the same file: one would overwrite the other",
                        earlier.option, earlier.path, option, path));
    seen.push_back({option, path, std::move(resolved)});
  }
}

nlohmann::json NumberOrInfinityText(double value) {
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  return value;
}

void RemoveFiles(const std::filesystem::path& directory, std::span<const char* const> names) {
  std::error_code ec;
  if (!std::filesystem::is_directory(directory, ec)) return;
  for (const char* name : names) std::filesystem::remove(directory / name, ec);
  if (std::filesystem::is_empty(directory, ec)) std::filesystem::remove(directory, ec);
}

std::vector<std::filesystem::path> NumberedFiles(const std::filesystem::path& directory,
                                                 std::string_view prefix, std::string_view suffix) {
  std::vector<std::filesystem::path> files;
  std::error_code ec;
  if (!std::filesystem::is_directory(directory, ec)) return files;
  for (const auto& entry : std::filesystem::directory_iterator(directory))
    if (IsNumberedName(entry.path().filename().string(), prefix, suffix, false))
      files.push_back(entry.path());
  return files;
}

void EnsureDirectory(const std::filesystem::path& directory) {
  if (directory.empty())
    throw UserError("expected an output directory, got an empty name (. is the current one)");
  std::error_code ec;
  if (std::filesystem::exists(directory, ec) && !std::filesystem::is_directory(directory, ec))
    throw UserError(fmt::format("{} is a file, not a directory", directory.string()));
  std::filesystem::create_directories(directory, ec);
  if (ec)
    throw UserError(
        fmt::format("cannot create directory {}: {}", directory.string(), ec.message()));
}

void EnsureDirectoryWithoutLastFile(const std::filesystem::path& directory,
                                    std::string_view last_file) {
  EnsureDirectory(directory);
  std::error_code ec;  // absent: nothing to do; unremovable: the run's writes fail there too
  std::filesystem::remove(directory / last_file, ec);
}

Progress::Progress(std::size_t total, std::string unit)
    : total_(std::max<std::size_t>(total, 1)),
      unit_(std::move(unit)),
      terminal_(isatty(fileno(stderr)) != 0) {}

void Progress::Step() {
  const std::size_t done = ++done_;
  const std::size_t percent = 100 * done / total_;
  std::lock_guard lock(mutex_);
  if (percent == last_percent_ && done != total_) return;
  if (!terminal_) {
    if (percent / 10 != last_percent_ / 10 || done == total_)
      fmt::print(stderr, "{}/{} {}\n", done, total_, unit_);
    last_percent_ = percent;
    return;
  }
  last_percent_ = percent;
  const std::size_t filled = percent * 30 / 100;
  fmt::print(stderr, "\r[{}{}] {}/{} {}", std::string(filled, '#'), std::string(30 - filled, ' '),
             done, total_, unit_);
  if (done == total_) fmt::print(stderr, "\n");
}

std::string Plural(std::size_t n, const std::string& word) {
  return fmt::format("{} {}{}", n, word, n == 1 ? "" : "s");
}

}  // namespace priormap::app
