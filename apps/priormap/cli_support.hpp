#pragma once
// Shared pieces of the subcommands: user-facing errors, option parsing, output checks.

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <mutex>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <priormap/core/diagnostic.hpp>
#include <priormap/core/log_io.hpp>
#include <priormap/core/scene.hpp>
#include <priormap/core/se2.hpp>
#include <priormap/dsl/prior_library.hpp>

namespace priormap::app {

/// An error the user can fix; main prints each line of it as "priormap: error: <line>" and
/// exits with status 1.
class UserError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A command line that does not parse, found by a command rather than by CLI11's checks (an
/// option required unless another is given, a value refused on its own where a check cannot see
/// it): printed as a UserError, but exit status 2, as README promises for every such command line.
class UsageError : public UserError {
 public:
  using UserError::UserError;
};

/// "file:line:col: message", one diagnostic per line.
[[nodiscard]] std::string DescribeDiagnostics(const std::vector<Diagnostic>& diagnostics);

/// Removes the checkpoints of a run or case whose outputs are written. One that cannot be removed
/// is a warning, not an error: the run is complete.
void RemoveFinishedCheckpoints(const std::filesystem::path& checkpoints);

/// Prints warnings on stderr, one per line: "priormap: warning: file:line:col: message".
void PrintWarnings(const std::vector<Diagnostic>& warnings);

/// The value of a successful result, its warnings (a log's scans stamped out of time order)
/// printed (PrintWarnings); otherwise throws UserError with every diagnostic.
template <typename T>
T ValueOrThrow(Result<T> result) {
  if (!result) throw UserError(DescribeDiagnostics(result.diagnostics()));
  PrintWarnings(result.warnings());
  return std::move(result).value();
}

/// As ValueOrThrow, without printing the warnings: for a file read again after a command that
/// read it has given them.
template <typename T>
T ValueOrThrowQuietly(Result<T> result) {
  if (!result) throw UserError(DescribeDiagnostics(result.diagnostics()));
  return std::move(result).value();
}

/// A check of a number-valued option: `why_not(value, text)` says why the value (as given:
/// `text`) is refused, or returns "" to accept it. Text that is not a number is refused first.
template <typename WhyNot>
[[nodiscard]] CLI::Validator NumberValidator(WhyNot why_not, std::string description) {
  return CLI::Validator(
      [why_not](std::string& text) -> std::string {
        double value = 0.0;
        if (!CLI::detail::lexical_cast(text, value)) return "'" + text + "' is not a number";
        return why_not(value, text);
      },
      std::move(description));
}

/// Checks for numeric options that say plainly what is wrong (CLI11's PositiveNumber prints
/// its range up to DBL_MAX).
[[nodiscard]] CLI::Validator PositiveValue();
[[nodiscard]] CLI::Validator NonNegativeValue();
/// A positive number at most `max` (in `unit`): for lengths and speeds whose huge values would
/// overflow the geometry they make, long after parsing.
[[nodiscard]] CLI::Validator PositiveValueUpTo(double max, const std::string& unit);
/// A probability strictly between 0 and 1, for those at whose bounds a model degenerates (0 x
/// log 0: slam's p_point_on_line).
[[nodiscard]] CLI::Validator OpenUnitInterval();

/// A probability in [0, 1].
[[nodiscard]] CLI::Validator Probability();

/// Refuses NaN and infinite values of every floating-point option of `app` and its subcommands
/// (CLI11's ranges let NaN through, as every comparison with it is false). Call it once every
/// command is added.
void RefuseNonFiniteNumbers(CLI::App& app);

/// A whole number in [0, max] for an unsigned option (`what` names it in the error: "a seed"),
/// handed on in plain decimal. CLI11 alone would read "-5" into an unsigned option as 2^64 - 5,
/// and "0100" as octal. Add it with transform(), not check(), which would not hand it on.
[[nodiscard]] CLI::Validator WholeNumber(std::uint64_t max, const std::string& what);

/// Most steps a step-count option takes: sums of a few stay far from overflowing.
inline constexpr std::uint64_t kMaxStepCount = std::uint64_t{1} << 40;
/// WholeNumber(kMaxStepCount, "a step count").
[[nodiscard]] CLI::Validator StepCount();
/// WholeNumber over all of uint64: seeds, indices.
[[nodiscard]] CLI::Validator SeedValue();
[[nodiscard]] CLI::Validator IndexValue();

/// A check that `parse` reads the option's value: for options whose form the command reads
/// itself (--pose x,y,theta, --range a:b), so that a malformed value is refused with the other
/// checks, as a command line that does not parse (status 2), before any input is read. `parse`
/// throws UserError "OPTION: why"; CLI11 writes the "OPTION: " itself.
template <typename Parse>
[[nodiscard]] CLI::Validator ParsedBy(const std::string& option, Parse parse) {
  return CLI::Validator(
      [option, parse](std::string& text) -> std::string {
        try {
          static_cast<void>(parse(text));
          return {};
        } catch (const UserError& e) {
          std::string_view why = e.what();
          if (why.starts_with(option + ": ")) why.remove_prefix(option.size() + 2);
          return std::string(why);
        }
      },
      "");
}

/// A sonar ring preset's name (pioneer8, ...).
[[nodiscard]] CLI::Validator SonarPresetName();

/// Refuses `--max-range`, which only the CARMEN reader takes, for a log read as another format
/// (whose scans carry their own max range), rather than ignore it.
void RequireCarmenForMaxRange(const std::string& input, LogFormat read_as,
                              const std::optional<double>& max_range);

/// "x,y,theta" (theta in radians).
[[nodiscard]] Se2 ParsePose(const std::string& text);

/// The prior library searched in `prior_path` (--prior-path), then PRIORMAP_PRIOR_PATH, then
/// the built-ins.
[[nodiscard]] dsl::PriorLibrary MakePriorLibrary(const std::vector<std::string>& prior_path);

/// Prints the prior's warnings (constraints that always hold, ...) on stderr, one per line:
/// "priormap: warning: file:line:col: message".
void PrintPriorWarnings(const dsl::CompiledPrior& prior);

/// The prior `name` (a name or a .prior file) of MakePriorLibrary(prior_path), its warnings
/// printed; throws UserError when it does not compile.
[[nodiscard]] dsl::CompiledPrior LoadPrior(const std::vector<std::string>& prior_path,
                                           const std::string& name);

/// A built-in scene name, or a priormap.scene JSON file; `option`, the option that names it, begins
/// the message of a name that is neither.
[[nodiscard]] Scene LoadScene(const std::string& name_or_path, std::string_view option);

/// A figure file's name: .png, .svg or .pdf.
[[nodiscard]] CLI::Validator FigurePath();

/// Throws UserError when the directory `path` would be written to does not exist, or `path` is
/// itself a directory. For commands with several outputs, so that a typo in one output fails
/// before any is written.
void RequireOutputDirectory(const std::filesystem::path& path, const std::string& option);

/// Writes `log` to `path` in `format`; when that is CARMEN, first warns on stderr of what CARMEN
/// cannot hold (CarmenLosses), so that nobody takes the file for the whole log.
void WriteLogWarningOfLosses(const Log& log, const std::filesystem::path& path, LogFormat format);

/// The format a log output is written in: `format_name` ("json" or "carmen", from --format or
/// --to) when given, else the one LogFormatFromPath reads from the name; throws UserError naming
/// `option` and `format_option` when the name implies none (out.png, say), rather than write
/// CARMEN under it.
[[nodiscard]] LogFormat OutputLogFormat(const std::optional<std::string>& format_name,
                                        const std::filesystem::path& path,
                                        const std::string& option,
                                        const std::string& format_option);

/// Throws UserError when two of the (option, path) pairs name the same file (an output would
/// overwrite the input or another output); empty paths are not given.
void RequireDistinctFiles(const std::vector<std::pair<std::string, std::string>>& files);

/// A number as docs/formats.md writes it: an infinity as "inf" or "-inf" (JSON has none, and
/// null would read as "not computed", or a check `z < 3` take it for missing), NaN as null.
[[nodiscard]] nlohmann::json NumberOrInfinityText(double value);

/// Removes the files `names` from `directory` where they exist (an earlier run's outputs that
/// this run does not write), by name only; a directory left empty is removed too.
void RemoveFiles(const std::filesystem::path& directory, std::span<const char* const> names);

/// The files of `directory` named prefix<N>suffix, an earlier run's numbered outputs
/// (chain0.png, ...), matched by name alone; none when it is not a directory.
[[nodiscard]] std::vector<std::filesystem::path> NumberedFiles(
    const std::filesystem::path& directory, std::string_view prefix, std::string_view suffix);

/// Creates `directory` (and parents) when missing; throws UserError when that fails.
void EnsureDirectory(const std::filesystem::path& directory);

/// EnsureDirectory, then removes an earlier run's `last_file` there: the file a run writes last,
/// so that a run stopped or failed while writing cannot pass its mix of old and new files off as
/// a complete set.
void EnsureDirectoryWithoutLastFile(const std::filesystem::path& directory,
                                    std::string_view last_file);

/// A progress bar on stderr, redrawn at most every percent on a terminal; elsewhere (CI logs,
/// files) a line every 10 %. Step() may be called from several threads.
class Progress {
 public:
  /// `unit`: what is counted, plural ("scans").
  Progress(std::size_t total, std::string unit);
  void Step();

 private:
  std::size_t total_;
  std::string unit_;
  bool terminal_;
  std::atomic<std::size_t> done_{0};
  std::mutex mutex_;
  std::size_t last_percent_ = 101;
};

/// "1 scan" / "3 scans".
[[nodiscard]] std::string Plural(std::size_t n, const std::string& word);

}  // namespace priormap::app
