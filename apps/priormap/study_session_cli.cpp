#include "study_session_cli.hpp"

#include <algorithm>
#include <cstdio>
#include <exception>
#include <optional>
#include <string_view>
#include <system_error>
#include <unistd.h>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include <priormap/core/binary_io.hpp>
#include <priormap/core/file_io.hpp>
#include <priormap/prf/chain_checkpoint.hpp>
#include <priormap/prf/map_study.hpp>

#include "cli_support.hpp"
#include "graceful_stop.hpp"

namespace priormap::app {
namespace {

// What a study writes when it begins and removes when it ends: its cases' folders and its
// options, which a resume must match.
constexpr const char* kInProgress = "study-in-progress.json";

// A record of a study in progress. Version 1 (before 2026-12-01) holds no options.
struct RecordedStudy {
  std::vector<std::string> cases;
  std::optional<nlohmann::json> options;
};

// The record in `record`; empty when there is none or it is not one (a record is only a check of
// --resume, which the checkpoints' fingerprints back).
RecordedStudy ReadRecord(const std::filesystem::path& record) {
  std::error_code ec;
  if (!std::filesystem::exists(record, ec)) return {};
  const Result<std::string> text = ReadFileText(record);
  if (!text.ok()) return {};
  const nlohmann::json j = nlohmann::json::parse(text.value(), nullptr, false);
  RecordedStudy recorded;
  if (!j.is_object() || !j.contains("cases") || !j["cases"].is_array()) return {};
  for (const nlohmann::json& c : j["cases"])
    if (c.is_string()) recorded.cases.push_back(c.get<std::string>());
  if (j.contains("options") && j["options"].is_object()) recorded.options = j["options"];
  return recorded;
}

// The options a resume gives otherwise than the stopped study was started with: those of both
// records' keys whose values differ ("samples" 3000, not 4000). A key one of them lacks is left to
// the checkpoints' fingerprints (an option added since keeps its value of before by default).
std::vector<std::string> DifferentOptions(const nlohmann::json& recorded,
                                          const nlohmann::json& given) {
  // As a record reads it back: numbers of one kind, doubles as written.
  const nlohmann::json now = nlohmann::json::parse(given.dump());
  std::vector<std::string> differ;
  for (const auto& [key, value] : recorded.items()) {
    if (!now.contains(key) || now[key] == value) continue;
    const std::string was = value.dump(), is = now[key].dump();
    // A long value (the sonar model) by its name alone.
    differ.push_back(was.size() + is.size() <= 80 ? fmt::format("\"{}\" {}, not {}", key, was, is)
                                                  : fmt::format("\"{}\"", key));
  }
  return differ;
}

// Whether `name` is one folder's name, right below the study's directory.
bool IsFolderName(std::string_view name) {
  return !name.empty() && name != "." && name != ".." &&
         name.find_first_of(std::string_view("/\0", 2)) == std::string_view::npos;
}

// The case folders of the study whose summary.json is in `dir` (either study's); none without one.
std::vector<std::string> SummarizedCases(const std::filesystem::path& dir) {
  std::error_code ec;
  const std::filesystem::path summary = dir / "summary.json";
  if (!std::filesystem::exists(summary, ec)) return {};
  const Result<std::string> text = ReadFileText(summary);
  if (!text.ok()) return {};
  const nlohmann::json j = nlohmann::json::parse(text.value(), nullptr, false);
  if (!j.is_object() || !j.contains("cases") || !j["cases"].is_array()) return {};
  // A sonar study's cases share the one sensor of its options.
  const nlohmann::json* sonar = nullptr;
  if (j.contains("format") && j["format"] == "priormap.prf_sonar_study" && j.contains("options") &&
      j["options"].is_object() && j["options"].contains("sensor"))
    sonar = &j["options"]["sensor"];
  std::vector<std::string> folders;
  for (const nlohmann::json& c : j["cases"]) {
    if (!c.is_object() || !c.contains("scene") || !c["scene"].is_string()) continue;
    const nlohmann::json* sensor = sonar ? sonar : (c.contains("sensor") ? &c["sensor"] : nullptr);
    if (sensor && sensor->is_string())
      folders.push_back(
          prf::StudyCaseFolder(c["scene"].get<std::string>(), sensor->get<std::string>()));
  }
  return folders;
}

// A new study in `dir`: the figures of the earlier study's cases it does not have (found by that
// study's summary and record) go, and their folders when that empties them; only the names a study
// writes, in folders right below `dir`.
void RemoveEarlierCases(const std::filesystem::path& dir, const std::vector<std::string>& folders,
                        const std::vector<std::string>& recorded) {
  std::vector<std::string> earlier = SummarizedCases(dir);
  earlier.insert(earlier.end(), recorded.begin(), recorded.end());
  for (const std::string& folder : earlier) {
    if (!IsFolderName(folder) || std::find(folders.begin(), folders.end(), folder) != folders.end())
      continue;
    std::error_code ec;
    // Not through a link: the files it leads to are not the study's.
    if (std::filesystem::symlink_status(dir / folder, ec).type() ==
        std::filesystem::file_type::directory)
      RemoveFiles(dir / folder, kStudyCaseFigures);
  }
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
                         const nlohmann::json& options, bool resume) {
  // Before the directory's contents are judged: a running study's checkpoints are not a stopped
  // one's.
  DirectoryLock lock = LockIfExists(dir);
  const std::filesystem::path record = dir / kInProgress;
  const RecordedStudy recorded_study = ReadRecord(record);
  const std::vector<std::string>& recorded = recorded_study.cases;
  std::vector<std::string> all = folders;
  for (const std::string& folder : recorded)
    if (std::find(all.begin(), all.end(), folder) == all.end()) all.push_back(folder);
  const auto refuse_a_stopped_study = [&](const std::vector<std::filesystem::path>& stopped) {
    if (!resume && !stopped.empty())
      throw UserError(fmt::format(
          "-o {}: it holds a stopped study ({}); continue it with the same command and --resume, "
          "or remove the cases' checkpoints folders to start a new study there",
          dir.string(), stopped.front().string()));
  };
  const std::vector<std::filesystem::path> stopped = StoppedCases(dir, all);
  refuse_a_stopped_study(stopped);
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
  // Other options would make other cases, whose checkpoints are refused one by one, and only as
  // "another run": named here, before any case is simulated.
  if (resume && recorded_study.options)
    if (const std::vector<std::string> differ = DifferentOptions(*recorded_study.options, options);
        !differ.empty())
      throw UserError(fmt::format(
          "--resume: the study stopped in {} was started with other options: {} (give the "
          "options it was started with)",
          dir.string(), fmt::join(differ, "; ")));
  EnsureDirectory(dir);
  if (!lock.held()) {
    lock = DirectoryLock(dir);
    // The directory did not exist when it was judged: another study may have made it, and
    // stopped there, since.
    refuse_a_stopped_study(StoppedCases(dir, all));
  }
  // Under the lock no other study writes checkpoints here: the temporaries of checkpoint writes
  // killed mid-way are stale, whatever process their PID names now.
  if (lock.held())
    for (const std::string& folder : all)
      if (IsFolderName(folder))
        prf::RemoveCheckpointTemporariesOfEndedWriters(dir / folder / "checkpoints");
  if (!resume) {
    // An earlier study's results would stand beside a new study stopped before its own, or, of
    // cases this study does not have, beside its numbers.
    RemoveEarlierCases(dir, folders, recorded);
    for (const char* file : {"summary.json", "table.md"}) std::filesystem::remove(dir / file);
    WriteTextFileAtomically(record, nlohmann::json{{"format", "priormap.study_in_progress"},
                                                   {"version", 2},
                                                   {"cases", folders},
                                                   {"options", options}}
                                            .dump(2) +
                                        "\n");
  }
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

namespace {

// Why a study cannot resume from a checkpoint, and what to do.
UserError CannotResume(const BinaryFormatError& e) {
  const auto* mismatch = dynamic_cast<const prf::CheckpointMismatchError*>(&e);
  if (mismatch == nullptr)  // damaged
    return UserError(fmt::format(
        "cannot resume: {}; remove that file and resume again: its chain (or, for anneal.ckpt, "
        "the case's annealing) starts afresh and the study ends as it would have, only the steps "
        "the file held are lost",
        e.what()));
  switch (mismatch->reason()) {
    case prf::CheckpointMismatchError::Reason::kFormatVersion:
      return UserError(fmt::format(
          "cannot resume: {}; continue the study with the priormap that started it, or remove "
          "the cases' checkpoints folders to start it again with this one",
          e.what()));
    case prf::CheckpointMismatchError::Reason::kAnotherRun:
      return UserError(fmt::format(
          "cannot resume: {}; give the options the study was started with. If they are, the "
          "case's data differ from the stopped study's (a scene file changed since, or another "
          "version of priormap started the study): put it back, or remove that case's "
          "checkpoints folder to start the case again",
          e.what()));
    case prf::CheckpointMismatchError::Reason::kAnotherChain:
      break;
  }
  return UserError(fmt::format(
      "cannot resume: {}; put each chain's checkpoint back under its own name, or remove this "
      "one: its chain starts afresh and the study ends as it would have",
      e.what()));
}

// A write that failed (a full disk, a directory made read-only), and what to do: the checkpoints
// written stay, each replaced whole or not at all.
UserError WriteFailed(const std::exception& e, const std::filesystem::path& dir,
                      const std::vector<std::string>& folders) {
  if (StoppedCases(dir, folders).empty())
    return UserError(fmt::format(
        "{}; no case was checkpointed: once {} can be written, run the same command again",
        e.what(), dir.string()));
  return UserError(fmt::format(
      "{}; the cases' checkpoints are kept: once {} can be written, continue with the same "
      "command and --resume",
      e.what(), dir.string()));
}

}  // namespace

void RunStoppable(const std::filesystem::path& dir, const std::vector<std::string>& folders,
                  const std::function<void()>& run) {
  const StopOnSignals stop_on_signals;
  try {
    run();
  } catch (const BinaryFormatError& e) {
    throw CannotResume(e);
  } catch (const prf::CheckpointReadError& e) {
    throw UserError(fmt::format("cannot resume: {}", e.what()));
  } catch (const IoError& e) {
    throw WriteFailed(e, dir, folders);
  } catch (const std::filesystem::filesystem_error& e) {
    throw WriteFailed(e, dir, folders);
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

void FinishStudy(const std::filesystem::path& dir, const std::vector<std::string>& folders,
                 const std::function<void()>& write) {
  try {
    write();
  } catch (const IoError& e) {
    throw WriteFailed(e, dir, folders);
  } catch (const std::filesystem::filesystem_error& e) {
    throw WriteFailed(e, dir, folders);
  }
  for (const std::string& folder : folders) {
    RemoveFinishedCheckpoints(dir / folder / "checkpoints");
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
