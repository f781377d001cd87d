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

constexpr std::uint64_t kFingerprint = 42;

std::string RefusalOfResume(const std::filesystem::path& path) {
  try {
    const ScanJournal second(path, kFingerprint, 4, true);
  } catch (const UserError& e) {
    return e.what();
  }
  return "";
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
