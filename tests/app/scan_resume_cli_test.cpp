// End-to-end tests of `priormap scan --all --resume`: a run stopped by a signal keeps every
// finished scan in the journal OUT.partial and exits with the shell's status for the signal; the
// same command with --resume does only the scans the journal lacks and writes what the
// uninterrupted run writes (times aside); a journal of another run, a damaged one, a missing one
// and a new run over one are refused without touching it. The log is simulated by the app itself.
#include <chrono>
#include <csignal>
#include <cstddef>
#include <fcntl.h>
#include <filesystem>
#include <regex>
#include <set>
#include <string>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_fixture.hpp"
#include "testing/temp_dir.hpp"

namespace priormap {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using priormap::testing::ReadAll;
using priormap::testing::WriteAll;
using ::testing::HasSubstr;
using ::testing::MatchesRegex;
using ::testing::Not;
using ::testing::StartsWith;

constexpr const char* kOut = "scans.jsonl";
constexpr const char* kJournal = "scans.jsonl.partial";

/// The complete lines of `text` (each ended by a newline), without their newlines.
std::vector<std::string> CompleteLines(const std::string& text) {
  std::vector<std::string> lines;
  for (std::size_t begin = 0, end; (end = text.find('\n', begin)) != std::string::npos;
       begin = end + 1)
    lines.push_back(text.substr(begin, end - begin));
  return lines;
}

/// A scan's record as the uninterrupted run would write it, times aside: the keys of "stats"
/// starting with "seconds" removed.
json WithoutSeconds(const std::string& line) {
  json record = json::parse(line);
  if (record.contains("stats")) {
    json stats = json::object();
    for (const auto& [key, value] : record["stats"].items())
      if (!key.starts_with("seconds")) stats[key] = value;
    record["stats"] = stats;
  }
  return record;
}

class ScanResumeCli : public priormap::testing::CliFixture {
 protected:
  void SetUp() override {
    // 237 scans of 181 beams: scan --all takes about 1.5 s. The signalled runs are held to one
    // CPU, so that it lasts as long on many cores: one signalled after its first records cannot
    // have ended by then.
    const auto r = Run({"simulate", "--log", "--rate", "8", "--beams", "181", "-o", "run.json"});
    ASSERT_EQ(r.status, 0) << r.err;
    std::smatch m;
    ASSERT_TRUE(std::regex_search(r.out, m, std::regex(R"(: (\d+) scans of)"))) << r.out;
    scans_ = std::stoul(m[1]);
    ASSERT_GT(scans_, 100u);
  }

  /// `priormap scan --all` of the log, with `extra` options.
  static std::vector<std::string> Command(const std::vector<std::string>& extra = {}) {
    std::vector<std::string> args = {"scan",     "--prior", "polygonal", "-i",
                                     "run.json", "--all",   "-o",        kOut};
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
  }

  /// The run (`extra` options) signalled as `how` says, on one CPU, once its journal holds
  /// `records` records more than `before` (mid-run: the handlers of the graceful stop are in
  /// place once a record is journaled).
  testing::SignalledRun Signalled(testing::Signalling how, std::size_t records = 10,
                                  const std::vector<std::string>& extra = {},
                                  std::size_t before = 0) const {
    const fs::path journal = Work(kJournal);
    how.one_cpu = true;
    return testing::RunAndSignalWhen(
        Work("."), Command(extra),
        [&] {
          std::error_code ec;
          if (!fs::exists(journal, ec)) return false;
          return CompleteLines(ReadAll(journal)).size() >= before + records + 1;
        },
        fmt::format("{} records not journaled after 30 s", records), how);
  }

  /// The run stopped by `signal` once its journal holds `records` records.
  testing::SignalledRun Stop(int signal, std::size_t records = 10) const {
    return Signalled({.signal = signal}, records);
  }

  /// The uninterrupted run's records (written to ref/all.jsonl, reading the same run.json).
  std::vector<std::string> Reference() const {
    fs::create_directory(Work("ref"));
    std::vector<std::string> args = Command();
    args.back() = "ref/all.jsonl";
    const auto r = Run(args);
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_FALSE(fs::exists(Work("ref/all.jsonl.partial")));
    std::vector<std::string> lines = CompleteLines(ReadAll(Work("ref/all.jsonl")));
    EXPECT_EQ(lines.size(), scans_);
    fs::remove_all(Work("ref"));
    return lines;
  }

  /// OUT holds the reference's records in scan order, times aside; the journal is gone.
  void ExpectOutputIsTheReference(const std::vector<std::string>& reference) const {
    EXPECT_FALSE(fs::exists(Work(kJournal)));
    const std::vector<std::string> out = CompleteLines(ReadAll(Work(kOut)));
    ASSERT_EQ(out.size(), reference.size());
    std::size_t differing = 0;
    for (std::size_t k = 0; k < out.size(); ++k) {
      const json record = WithoutSeconds(out[k]);
      EXPECT_EQ(record["scan_index"], k);
      if (record != WithoutSeconds(reference[k]) && ++differing <= 3)
        ADD_FAILURE() << "scan " << k << " differs from the uninterrupted run's";
    }
    EXPECT_EQ(differing, 0u);
  }

  /// The journal's header, from a run stopped by SIGTERM (which the caller's journal then
  /// replaces).
  std::string RealHeader() const {
    const testing::SignalledRun stopped = Stop(SIGTERM, 1);
    EXPECT_TRUE(WIFEXITED(stopped.wait_status) && WEXITSTATUS(stopped.wait_status) == 143)
        << stopped.err;
    const std::vector<std::string> lines = CompleteLines(ReadAll(Work(kJournal)));
    EXPECT_FALSE(lines.empty());
    return lines.empty() ? std::string() : lines.front();
  }

  std::size_t scans_ = 0;
};

// SIGTERM mid-run: the finished scans are kept in the journal (a header and one line per scan),
// no output and no temporary file is left, and the exit status is the shell's for SIGTERM. The
// same command with --resume does only the others and writes what the uninterrupted run writes,
// the kept records as they were, in scan order; the journal goes.
TEST_F(ScanResumeCli, SigtermKeepsTheFinishedScansAndResumeWritesWhatAnUninterruptedRunWrites) {
  const testing::SignalledRun stopped = Stop(SIGTERM);
  ASSERT_TRUE(WIFEXITED(stopped.wait_status))
      << "ended by signal "
      << (WIFSIGNALED(stopped.wait_status) ? WTERMSIG(stopped.wait_status) : 0) << "; stderr:\n"
      << stopped.err;
  EXPECT_EQ(WEXITSTATUS(stopped.wait_status), 128 + SIGTERM) << stopped.err;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(
      stopped.out, m,
      std::regex(R"(^stopped: (\d+) of (\d+) scans done, kept in scans\.jsonl\.partial; )"
                 R"(continue with the same command and --resume\n$)")))
      << stopped.out;
  const std::size_t done = std::stoul(m[1]);
  EXPECT_EQ(std::stoul(m[2]), scans_);
  EXPECT_GE(done, 10u);
  EXPECT_LT(done, scans_) << "the run ended before the signal: make the log longer";
  EXPECT_FALSE(fs::exists(Work(kOut)));
  EXPECT_FALSE(testing::HasTemporaryFile(Work(".")));
  EXPECT_EQ(WorkFiles(), (std::set<std::string>{"run.json", kJournal}));

  const std::string journal = ReadAll(Work(kJournal));
  ASSERT_TRUE(journal.ends_with('\n'));
  const std::vector<std::string> lines = CompleteLines(journal);
  ASSERT_EQ(lines.size(), done + 1);
  const json header = json::parse(lines[0]);
  EXPECT_EQ(header["format"], "priormap.scan_journal");
  EXPECT_EQ(header["version"], 1);
  EXPECT_THAT(header["fingerprint"].get<std::string>(), MatchesRegex("[0-9a-f]{16}"));
  EXPECT_EQ(header["scans"], scans_);
  std::set<std::size_t> kept;
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const json record = json::parse(lines[i]);
    EXPECT_EQ(record["format"], "priormap.map_scan");
    EXPECT_FALSE(record.contains("error"));
    const std::size_t k = record["scan_index"].get<std::size_t>();
    EXPECT_LT(k, scans_);
    EXPECT_TRUE(kept.insert(k).second) << "scan " << k << " journaled twice";
  }

  const auto resumed = Run(Command({"--resume"}));
  ASSERT_EQ(resumed.status, 0) << resumed.err;
  EXPECT_EQ(resumed.out, fmt::format("wrote scans.jsonl ({} scans)\n", scans_));
  EXPECT_THAT(resumed.err, StartsWith(fmt::format(
                               "resumed {} of {} scans from scans.jsonl.partial\n", done, scans_)));
  EXPECT_EQ(WorkFiles(), (std::set<std::string>{"run.json", kOut}));
  // The kept records as they were (their times too): those scans were not done again.
  const std::vector<std::string> out = CompleteLines(ReadAll(Work(kOut)));
  ASSERT_EQ(out.size(), scans_);
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const std::size_t k = json::parse(lines[i])["scan_index"].get<std::size_t>();
    EXPECT_EQ(out[k], lines[i]) << "scan " << k;
  }
  const std::vector<std::string> reference = Reference();
  ASSERT_FALSE(reference.empty());
  ASSERT_TRUE(json::parse(reference[0])["stats"].contains("seconds"));
  ExpectOutputIsTheReference(reference);
}

// A resumed run stopped again keeps the scans of both sessions (the journal rewritten on resume
// keeps the first session's records); resumed once more it completes with every record kept.
TEST_F(ScanResumeCli, AResumedRunStoppedAgainKeepsTheScansOfBothSessions) {
  const testing::SignalledRun first = Stop(SIGTERM);
  ASSERT_TRUE(WIFEXITED(first.wait_status) && WEXITSTATUS(first.wait_status) == 143) << first.err;
  const std::vector<std::string> first_lines = CompleteLines(ReadAll(Work(kJournal)));
  const std::size_t first_done = first_lines.size() - 1;

  const testing::SignalledRun second = Signalled({.signal = SIGTERM}, 10, {"--resume"}, first_done);
  ASSERT_TRUE(WIFEXITED(second.wait_status) && WEXITSTATUS(second.wait_status) == 143)
      << second.err;
  EXPECT_THAT(second.err, StartsWith(fmt::format("resumed {} of {} scans", first_done, scans_)));
  const std::vector<std::string> second_lines = CompleteLines(ReadAll(Work(kJournal)));
  EXPECT_THAT(second.out, StartsWith(fmt::format("stopped: {} of {} scans done",
                                                 second_lines.size() - 1, scans_)));
  ASSERT_GE(second_lines.size(), first_lines.size() + 10);
  EXPECT_LT(second_lines.size(), scans_ + 1) << "the run ended before the signal";
  EXPECT_EQ(second_lines[0], first_lines[0]);
  const std::set<std::string> kept(second_lines.begin() + 1, second_lines.end());
  for (std::size_t i = 1; i < first_lines.size(); ++i)
    EXPECT_TRUE(kept.contains(first_lines[i]))
        << "the record of scan " << json::parse(first_lines[i])["scan_index"] << " was lost";

  const auto resumed = Run(Command({"--resume"}));
  ASSERT_EQ(resumed.status, 0) << resumed.err;
  EXPECT_THAT(resumed.err,
              StartsWith(fmt::format("resumed {} of {} scans", second_lines.size() - 1, scans_)));
  const std::vector<std::string> out = CompleteLines(ReadAll(Work(kOut)));
  ASSERT_EQ(out.size(), scans_);
  for (std::size_t k = 0; k < scans_; ++k) EXPECT_EQ(json::parse(out[k])["scan_index"], k);
  for (std::size_t i = 1; i < second_lines.size(); ++i) {
    const std::size_t k = json::parse(second_lines[i])["scan_index"].get<std::size_t>();
    EXPECT_EQ(out[k], second_lines[i]) << "scan " << k;
  }
  EXPECT_EQ(WorkFiles(), (std::set<std::string>{"run.json", kOut}));
}

// Ctrl-C stops it the same way, with 130. Its progress (stderr a file: a line every 10 %) counts
// the scans done, never those skipped once it stopped.
TEST_F(ScanResumeCli, SigintStopsTheRunWithItsExitStatus) {
  const testing::SignalledRun stopped = Stop(SIGINT);
  ASSERT_TRUE(WIFEXITED(stopped.wait_status)) << stopped.err;
  EXPECT_EQ(WEXITSTATUS(stopped.wait_status), 128 + SIGINT) << stopped.err;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(stopped.out, m, std::regex(R"(^stopped: (\d+) of )")))
      << stopped.out;
  const std::size_t done = std::stoul(m[1]);
  EXPECT_LT(done, scans_) << "the run ended before the signal: make the log longer";
  const std::regex progress_line(R"((\d+)/(\d+) scans\n)");
  for (auto it = std::sregex_iterator(stopped.err.begin(), stopped.err.end(), progress_line);
       it != std::sregex_iterator(); ++it) {
    EXPECT_EQ(std::stoul((*it)[2]), scans_) << it->str();
    EXPECT_LE(std::stoul((*it)[1]), done) << "progress past the " << done << " scans done";
  }
  EXPECT_EQ(WorkFiles(), (std::set<std::string>{"run.json", kJournal}));
}

// The same request delivered twice, the second after the scans have stopped (the run waiting to
// write its message): still one request, the message written, the status SIGTERM's.
TEST_F(ScanResumeCli, ASignalDeliveredTwiceIsOneRequestEvenOnceTheScansHaveStopped) {
  using namespace std::chrono_literals;
  // Its stdout full, the stopped run waits to write its message, past the scans and the scope of
  // their StopOnSignals, until the second signal has come: 500 ms later, long enough for the
  // scans under way to end, within the second of one request.
  const testing::SignalledRun stopped =
      Signalled({.signal = SIGTERM, .times = 2, .apart = 500ms, .stdout_full = true});
  EXPECT_EQ(stopped.signals_while_running, 2);
  ASSERT_TRUE(WIFEXITED(stopped.wait_status))
      << testing::HowItEnded(stopped.wait_status) << "; stderr:\n"
      << stopped.err;
  EXPECT_EQ(WEXITSTATUS(stopped.wait_status), 128 + SIGTERM) << stopped.err;
  const std::size_t done = CompleteLines(ReadAll(Work(kJournal))).size() - 1;
  EXPECT_EQ(stopped.out, fmt::format("stopped: {} of {} scans done, kept in scans.jsonl.partial; "
                                     "continue with the same command and --resume\n",
                                     done, scans_));
  EXPECT_THAT(stopped.err, Not(HasSubstr("error")));
  EXPECT_EQ(WorkFiles(), (std::set<std::string>{"run.json", kJournal}));
}

// A new run would replace a stopped run's journal: refused, the journal untouched.
TEST_F(ScanResumeCli, ANewRunOverAStoppedRunsJournalIsRefused) {
  const std::string journal = "{\"format\":\"priormap.scan_journal\"}\nwhatever\n";
  WriteAll(Work(kJournal), journal);
  const auto r = RunFailing(Command());
  EXPECT_EQ(r.status, 1);
  EXPECT_THAT(r.err, HasSubstr("scans.jsonl.partial holds a stopped scan --all of this output; "
                               "continue it with the same command and --resume"));
  EXPECT_EQ(ReadAll(Work(kJournal)), journal);
}

// While a run holds its journal (locked, as a running run does), a second run on the same output
// is told that one is running, with --resume or without: not that a stopped run's journal is
// there to continue.
TEST_F(ScanResumeCli, ASecondRunWhileTheFirstRunsIsToldItRunsWithOrWithoutResume) {
  const std::string journal = "{\"format\":\"priormap.scan_journal\"}\n";
  WriteAll(Work(kJournal), journal);
  const int fd = ::open(Work(kJournal).c_str(), O_RDWR | O_CLOEXEC);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0);
  for (const std::vector<std::string>& args : {Command(), Command({"--resume"})}) {
    const auto r = RunFailing(args);
    EXPECT_EQ(r.status, 1);
    EXPECT_THAT(r.err, HasSubstr("scans.jsonl.partial: another priormap scan --all is running on "
                                 "this output"));
    EXPECT_THAT(r.err, Not(HasSubstr("stopped scan --all")));
  }
  ::close(fd);
  EXPECT_EQ(ReadAll(Work(kJournal)), journal);
}

// --resume with no journal to continue, and --resume of one scan.
TEST_F(ScanResumeCli, ResumeWithoutAJournalOrWithoutAllIsRefused) {
  EXPECT_THAT(RunFailing(Command({"--resume"})).err,
              HasSubstr("--resume: no scans.jsonl.partial (no stopped scan --all of this output "
                        "to continue)"));
  const std::vector<std::string> one = {"scan",     "--prior", "polygonal", "-i",      "run.json",
                                        "--resume", "-o",      kOut,        "--index", "3"};
  EXPECT_THAT(RunFailing(one).err, HasSubstr("--resume continues a stopped --all run"));
  // With a journal there too, which it leaves as it is.
  const std::string journal = "{}\n";
  WriteAll(Work(kJournal), journal);
  EXPECT_THAT(RunFailing(one).err, HasSubstr("--resume continues a stopped --all run"));
  EXPECT_EQ(ReadAll(Work(kJournal)), journal);
}

// The journal of a run with another prior, --beta, --no-refine or log bytes is refused, untouched;
// with the same ones it resumes.
TEST_F(ScanResumeCli, ResumeOfAnotherRunsJournalIsRefused) {
  const testing::SignalledRun stopped = Stop(SIGTERM);
  ASSERT_TRUE(WIFEXITED(stopped.wait_status)) << stopped.err;
  ASSERT_EQ(WEXITSTATUS(stopped.wait_status), 143) << stopped.err;
  const std::string journal = ReadAll(Work(kJournal));
  const std::string another =
      "--resume: scans.jsonl.partial is a stopped run of another prior, "
      "log or options";
  std::vector<std::string> rectangular = Command({"--resume"});
  rectangular[2] = "rectangular";
  EXPECT_THAT(RunFailing(rectangular).err, HasSubstr(another));
  EXPECT_THAT(RunFailing(Command({"--resume", "--beta", "0.9"})).err, HasSubstr(another));
  EXPECT_THAT(RunFailing(Command({"--resume", "--no-refine"})).err, HasSubstr(another));
  EXPECT_EQ(ReadAll(Work(kJournal)), journal);
  // The log of another seed under the same name, then the log again.
  const std::vector<std::string> simulate = {"simulate", "--log", "--rate", "8",
                                             "--beams",  "181",   "-o",     "run.json"};
  std::vector<std::string> seed2 = simulate;
  seed2.insert(seed2.end(), {"--seed", "2"});
  ASSERT_EQ(Run(seed2).status, 0);
  EXPECT_THAT(RunFailing(Command({"--resume"})).err, HasSubstr(another));
  EXPECT_EQ(ReadAll(Work(kJournal)), journal);
  ASSERT_EQ(Run(simulate).status, 0);
  const auto resumed = Run(Command({"--resume"}));
  EXPECT_EQ(resumed.status, 0) << resumed.err;
  EXPECT_TRUE(fs::exists(Work(kOut)));
  EXPECT_FALSE(fs::exists(Work(kJournal)));
}

// A record a crash cut short (the last line, without its newline) is not taken: that scan is done
// again. A journal holding every record only writes the output.
TEST_F(ScanResumeCli, AJournalWhoseLastLineIsCutShortResumesAndDoesThatScanAgain) {
  const std::string header = RealHeader();
  const std::vector<std::string> reference = Reference();
  ASSERT_EQ(reference.size(), scans_);
  std::string kept = header + "\n";
  // Every scan but the last three; then half of the third from the end's record.
  for (std::size_t k = 0; k + 3 < scans_; ++k) kept += reference[k] + "\n";
  const std::string& torn = reference[scans_ - 3];
  WriteAll(Work(kJournal), kept + torn.substr(0, torn.size() / 2));
  auto r = Run(Command({"--resume"}));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.err, StartsWith(fmt::format("resumed {} of {} scans", scans_ - 3, scans_)));
  ExpectOutputIsTheReference(reference);
  // The kept ones as they were; the torn one done again, whole.
  std::vector<std::string> out = CompleteLines(ReadAll(Work(kOut)));
  ASSERT_EQ(out.size(), scans_);
  for (std::size_t k = 0; k + 3 < scans_; ++k) EXPECT_EQ(out[k], reference[k]) << "scan " << k;
  EXPECT_EQ(WithoutSeconds(out[scans_ - 3]), WithoutSeconds(torn));

  // A whole record without its newline is cut short too (the newline is written after it).
  fs::remove(Work(kOut));
  WriteAll(Work(kJournal), kept + torn);
  r = Run(Command({"--resume"}));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.err, StartsWith(fmt::format("resumed {} of {} scans", scans_ - 3, scans_)));
  ExpectOutputIsTheReference(reference);

  // Every record (a crash after the last scan): the output, exactly the journal's records.
  fs::remove(Work(kOut));
  std::string all = header + "\n";
  for (std::size_t k = scans_; k-- > 0;) all += reference[k] + "\n";  // in another order
  WriteAll(Work(kJournal), all);
  r = Run(Command({"--resume"}));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.err, StartsWith(fmt::format("resumed {} of {} scans", scans_, scans_)));
  out = CompleteLines(ReadAll(Work(kOut)));
  EXPECT_TRUE(out == reference);
  EXPECT_EQ(WorkFiles(), (std::set<std::string>{"run.json", kOut}));
}

// A damaged line is reported at OUT.partial:LINE:1, the journal untouched; so is a journal
// without a header.
TEST_F(ScanResumeCli, ADamagedJournalLineIsReportedWithItsLineNumber) {
  const std::string header = RealHeader();
  const std::string record0 = R"({"format":"priormap.map_scan","scan_index":0})";
  const std::string record1 = R"({"format":"priormap.map_scan","scan_index":1})";
  const struct {
    std::string journal;
    std::string error;
  } cases[] = {
      {header + "\n" + record0 + "\n{\"scan_index\": 2,\n" + record1 + "\n",
       "scans.jsonl.partial:3:1: expected a JSON object on this line"},
      {header + "\n" + record0 + "\n\n" + record1 + "\n",
       "scans.jsonl.partial:3:1: expected a JSON object on this line"},
      {header + "\n" + record0 + "\n" + record1 + "\n" +
           fmt::format(R"({{"scan_index":{}}})", scans_) + "\n" + record1 + "\n",
       fmt::format("scans.jsonl.partial:4:1: expected a scan record with a scan_index below {}",
                   scans_)},
      {header + "\n" + record0 + "\n{\"scan_index\":-1}\n",
       "scans.jsonl.partial:3:1: expected a scan record with a scan_index below"},
      {header + "\n{\"scan_index\":\"1\"}\n" + record1 + "\n",
       "scans.jsonl.partial:2:1: expected a scan record with a scan_index below"},
      {header + "\n[1]\n" + record1 + "\n",
       "scans.jsonl.partial:2:1: expected a JSON object on this line"},
      {record0 + "\n" + header + "\n",
       "scans.jsonl.partial:1:1: expected the header of a priormap.scan_journal (version 1)"},
      {header, "scans.jsonl.partial:1:1: expected the header of a priormap.scan_journal"},
      {"", "scans.jsonl.partial:1:1: expected the header of a priormap.scan_journal"},
  };
  for (const auto& c : cases) {
    WriteAll(Work(kJournal), c.journal);
    const auto r = RunFailing(Command({"--resume"}));
    EXPECT_EQ(r.status, 1);
    EXPECT_THAT(r.err, HasSubstr(c.error)) << c.journal.substr(0, 300);
    EXPECT_EQ(ReadAll(Work(kJournal)), c.journal);
  }
  // Another scan count in the header is another run.
  json other = json::parse(header);
  other["scans"] = scans_ + 1;
  WriteAll(Work(kJournal), other.dump() + "\n" + record0 + "\n");
  EXPECT_THAT(RunFailing(Command({"--resume"})).err,
              HasSubstr("scans.jsonl.partial is a stopped run of another prior, log or options"));
}

}  // namespace
}  // namespace priormap
