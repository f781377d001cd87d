#include "study_session_cli.hpp"

#include <algorithm>
#include <cstdio>
#include <system_error>
#include <unistd.h>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include <priormap/core/binary_io.hpp>
#include <priormap/core/file_io.hpp>
#include <priormap/prf/map_study.hpp>

#include "cli_support.hpp"
#include "graceful_stop.hpp"

namespace priormap::app {
namespace {

// What a study writes when it begins and removes when it ends: its cases' folders, which a
// resume must match.
constexpr const char* kInProgress = "study-in-progress.json";

// The case folders in a record of a study in progress; none when there is no record or it is not
// one (a record is only a check of --resume, which the checkpoints' fingerprints back).
std::vector<std::string> RecordedCases(const std::filesystem::path& record) {
  std::error_code ec;
  if (!std::filesystem::exists(record, ec)) return {};
  const Result<std::string> text = ReadFileText(record);
  if (!text.ok()) return {};
  const nlohmann::json j = nlohmann::json::parse(text.value(), nullptr, false);
  std::vector<std::string> cases;
  if (!j.is_object() || !j.contains("cases") || !j["cases"].is_array()) return {};
  for (const nlohmann::json& c : j["cases"])
    if (c.is_string()) cases.push_back(c.get<std::string>());
  return cases;
}

// The cases' checkpoint folders that hold something.
std::vector<std::filesystem::path> StoppedCases(const std::filesystem::path& dir,
                                                const std::vector<std::string>& folders) {
  std::vector<std::filesystem::path> stopped;
  for (const std::string& folder : folders) {
    const std::filesystem::path checkpoints = dir / folder / "checkpoints";
    if (std::error_code ec; std::filesystem::is_directory(checkpoints, ec) &&
                            !std::filesystem::is_empty(checkpoints, ec))
      stopped.push_back(checkpoints);
  }
  return stopped;
}

// One status line: redrawn in place on a terminal, every 10 % elsewhere; a line per scored case.
class StudyStatus {
 public:
  StudyStatus() : terminal_(isatty(fileno(stderr)) != 0) {}
  void operator()(const prf::StudyProgress& p) {
    const auto percent = static_cast<int>(100.0 * p.fraction);
    const bool last = p.cases_done == p.cases_total;
    if (p.case_done.empty()) {
      if (percent == last_percent_ || (!terminal_ && percent / 10 == last_percent_ / 10)) return;
    }
    last_percent_ = percent;
    const std::string line = fmt::format("{:3d}% of the PRF steps, {}/{} cases done, {:.0f} s",
                                         percent, p.cases_done, p.cases_total, p.seconds);
    if (!p.case_done.empty()) {
      if (terminal_) fmt::print(stderr, "\r\x1b[K");
      fmt::print(stderr, "case {} done\n", p.case_done);
    }
    if (terminal_)
      fmt::print(stderr, "\r{}\x1b[K{}", line, last ? "\n" : "");
    else
      fmt::print(stderr, "{}\n", line);
  }

 private:
  bool terminal_;
  int last_percent_ = -1;
};

}  // namespace

CLI::Validator StudySamples() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        if (text != "0") return {};  // in decimal, as StepCount() hands it on
        return "expected at least one sample per chain (P(black) is their mean), got 0";
      },
      "");
}

CLI::Validator StudyResolution() {
  return NumberValidator(
      [](double value, const std::string& text) -> std::string {
        if (value >= prf::kFinestStudyResolution && value <= prf::kCoarsestStudyResolution)
          return {};
        return fmt::format(
            "expected at least {} m (finer, the scenes' rasters would not fit) and at most {} m "
            "(coarser, a room is a cell or two), got {}",
            prf::kFinestStudyResolution, prf::kCoarsestStudyResolution, text);
      },
      "");
}

void RefuseRepeatedEntries(const std::vector<std::string>& entries, const std::string& option,
                           const std::string& what) {
  if (const auto entry = prf::RepeatedName(entries, [](const std::string& e) { return e; }))
    throw UsageError(
        fmt::format("{}: {} '{}' is given twice (each case runs once)", option, what, *entry));
}

void AddStudySessionOptions(CLI::App& cmd, StudySessionCliOptions& o) {
  cmd.add_flag("--resume", o.resume,
               "Continue the study stopped in -o DIR (Ctrl-C, SIGTERM, --stop-after-steps or a "
               "crash) from its cases' checkpoints; give the options it was started with. The "
               "result is that of the uninterrupted study");
  cmd.add_option("--checkpoint-every", o.checkpoint_every_s,
                 "Seconds between a chain's checkpoints (in -o DIR/<scene>-<sensor>/checkpoints)")
      ->check(PositiveValue())
      ->capture_default_str();
  cmd.add_option("--stop-after-steps", o.stop_after_steps,
                 "Stop each case's chains (and annealing), checkpointed, after this many steps in "
                 "this session, to split a long study into sessions; 0: no limit")
      ->transform(StepCount())
      ->capture_default_str();
}

DirectoryLock BeginStudy(const std::filesystem::path& dir, const std::vector<std::string>& folders,
                         bool resume) {
  // Before the directory's contents are judged: a running study's checkpoints are not a stopped
  // one's.
  DirectoryLock lock = LockIfExists(dir);
  const std::filesystem::path record = dir / kInProgress;
  const std::vector<std::string> recorded = RecordedCases(record);
  std::vector<std::string> all = folders;
  for (const std::string& folder : recorded)
    if (std::find(all.begin(), all.end(), folder) == all.end()) all.push_back(folder);
  const std::vector<std::filesystem::path> stopped = StoppedCases(dir, all);
  if (!resume && !stopped.empty())
    throw UserError(fmt::format(
        "-o {}: it holds a stopped study ({}); continue it with the same command and --resume, "
        "or remove the cases' checkpoints folders to start a new study there",
        dir.string(), stopped.front().string()));
  if (resume && stopped.empty())
    throw UserError(fmt::format(
        "--resume: -o {} holds no stopped study of these cases (no {}/checkpoints); run "
        "without --resume to start one",
        dir.string(), (dir / folders.front()).string()));
  // Cases without checkpoints start afresh, so a resume with other cases would run a study the
  // stopped one is not, leaving that one's checkpoints behind.
  if (resume && !recorded.empty() && recorded != folders)
    throw UserError(fmt::format(
        "--resume: the study stopped in {} has the cases {}; these options give {} (give the "
        "scenes and sensors it was started with)",
        dir.string(), fmt::join(recorded, ", "), fmt::join(folders, ", ")));
  EnsureDirectory(dir);
  if (!lock.held()) lock = DirectoryLock(dir);
  // An earlier study's results would stand beside a new study stopped before its own.
  if (!resume)
    for (const char* file : {"summary.json", "table.md"}) std::filesystem::remove(dir / file);
  if (!resume)
    WriteTextFileAtomically(
        record,
        nlohmann::json{{"format", "priormap.study_in_progress"}, {"version", 1}, {"cases", folders}}
                .dump(2) +
            "\n");
  return lock;
}

prf::StudySession MakeStudySession(const std::filesystem::path& dir,
                                   const StudySessionCliOptions& o) {
  return {.directory = dir,
          .checkpoint_every_s = o.checkpoint_every_s,
          .resume = o.resume,
          .stop_after_steps = o.stop_after_steps,
          .stop = &StopFlag(),
          .progress = StudyStatus()};
}

void RunStoppable(const std::function<void()>& run) {
  const StopOnSignals stop_on_signals;
  try {
    run();
  } catch (const BinaryFormatError& e) {
    throw UserError(fmt::format(
        "cannot resume: {}; give the options the study was started with (a damaged checkpoint: "
        "remove it, and its chain starts afresh)",
        e.what()));
  }
}

void EndStoppedStudy(const std::filesystem::path& dir, const std::vector<std::string>& folders) {
  const std::vector<std::filesystem::path> stopped = StoppedCases(dir, folders);
  // On a terminal the status line has no line break yet.
  if (isatty(fileno(stderr)) != 0) fmt::print(stderr, "\n");
  if (stopped.empty()) {
    fmt::print(
        "stopped before any case was checkpointed; run the same command again (without "
        "--resume)\n");
    if (StopRequested()) ExitAsStopped();
    return;
  }
  fmt::print(
      "stopped and checkpointed in {} of {} cases ({}{}); continue with the same command and "
      "--resume\n",
      stopped.size(), folders.size(), stopped.empty() ? dir.string() : stopped.front().string(),
      stopped.size() > 1 ? ", ..." : "");
  if (StopRequested()) ExitAsStopped();
}

void FinishStudy(const std::filesystem::path& dir, const std::vector<std::string>& folders) {
  for (const std::string& folder : folders) {
    std::filesystem::remove_all(dir / folder / "checkpoints");
    // Only when empty (--no-figures): a folder the study made for its checkpoints alone.
    std::error_code ec;
    if (std::filesystem::is_empty(dir / folder, ec)) std::filesystem::remove(dir / folder, ec);
  }
  std::filesystem::remove(dir / kInProgress);
}

void ReportResumedSteps(std::uint64_t steps) {
  if (steps > 0) fmt::print(stderr, "resumed {} steps from the cases' checkpoints\n", steps);
}

}  // namespace priormap::app
