// The journal of `scan --all` (apps/priormap/scan_journal.hpp) against a second run on the same
// output: refused while the first holds the journal, its records untouched.
#include "scan_journal.hpp"

#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "cli_support.hpp"
#include "testing/temp_dir.hpp"

namespace priormap::app {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

constexpr std::uint64_t kFingerprint = 42;

// The refusal of a second run on the journal at `path`, with --resume or without.
std::string RefusalOfSecondRun(const std::filesystem::path& path, bool resume) {
  try {
    const ScanJournal second(path, kFingerprint, 4, resume);
  } catch (const UserError& e) {
    return e.what();
  }
  return "";
}

std::string RefusalOfResume(const std::filesystem::path& path) {
  return RefusalOfSecondRun(path, true);
}

TEST(ScanJournal, ASecondRunOnTheSameOutputIsRefusedWhileTheFirstRuns) {
  const testing::TempDir dir;
  const std::filesystem::path path = dir / "scans.jsonl.partial";
  {
    ScanJournal first(path, kFingerprint, 4, false);
    first.Append(2, R"({"scan_index":2})");
    EXPECT_THAT(RefusalOfResume(path),
                HasSubstr(path.string() + ": another priormap scan --all is running"));
    // The refusal left the first run's journal as it was: its next record lands in it.
    first.Append(0, R"({"scan_index":0})");
  }
  const ScanJournal resumed(path, kFingerprint, 4, true);
  EXPECT_EQ(resumed.Restored(), 2u);
  EXPECT_EQ(resumed.Record(0), R"({"scan_index":0})");
  EXPECT_EQ(resumed.Record(2), R"({"scan_index":2})");
}

// Without --resume too, the second run is told that the first is running, not that a stopped
// run's journal is in its way.
TEST(ScanJournal, ANewRunOnTheSameOutputIsToldTheFirstIsRunningNotStopped) {
  const testing::TempDir dir;
  const std::filesystem::path path = dir / "scans.jsonl.partial";
  ScanJournal first(path, kFingerprint, 4, false);
  first.Append(1, R"({"scan_index":1})");
  const std::string refusal = RefusalOfSecondRun(path, false);
  EXPECT_THAT(refusal, HasSubstr(path.string() + ": another priormap scan --all is running"));
  EXPECT_THAT(refusal, Not(HasSubstr("stopped scan --all")));
  first.Append(3, R"({"scan_index":3})");
  EXPECT_EQ(first.Record(3), R"({"scan_index":3})");
}

TEST(ScanJournal, AJournalRemovedByItsRunIsNotResumed) {
  const testing::TempDir dir;
  const std::filesystem::path path = dir / "scans.jsonl.partial";
  ScanJournal first(path, kFingerprint, 4, false);
  first.Remove();
  EXPECT_FALSE(std::filesystem::exists(path));
  EXPECT_THAT(RefusalOfResume(path), HasSubstr("--resume: no " + path.string()));
}

}  // namespace
}  // namespace priormap::app
