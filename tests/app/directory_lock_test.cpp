// The output directory's lock (apps/priormap/directory_lock.hpp): a second holder is refused with
// a message naming the holder, the lock goes with its holder, and a directory that does not exist
// is not locked.
#include "directory_lock.hpp"

#include <filesystem>
#include <string>
#include <unistd.h>
#include <utility>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "cli_support.hpp"
#include "testing/temp_dir.hpp"

namespace priormap::app {
namespace {

using ::testing::HasSubstr;

std::string RefusalOf(const std::filesystem::path& dir) {
  try {
    const DirectoryLock second(dir);
  } catch (const UserError& e) {
    return e.what();
  }
  return "";
}

TEST(DirectoryLock, ASecondHolderIsRefusedUntilTheFirstGoes) {
  const testing::TempDir dir;
  {
    const DirectoryLock first(dir.path());
    ASSERT_TRUE(first.held());
    EXPECT_THAT(RefusalOf(dir.path()),
                HasSubstr("-o " + dir.path().string() + ": another priormap is running there"));
  }
  EXPECT_EQ(RefusalOf(dir.path()), "");
}

// The holder is named (here this process, app_tests), so that a run left in the background, or
// stopped with Ctrl-Z, can be found and stopped.
TEST(DirectoryLock, TheRefusalNamesTheProcessThatHoldsTheLock) {
  if (!std::filesystem::exists("/proc/locks")) GTEST_SKIP() << "no /proc/locks to tell the holder";
  const testing::TempDir dir;
  const DirectoryLock first(dir.path());
  const std::string refusal = RefusalOf(dir.path());
  EXPECT_THAT(refusal, HasSubstr(fmt::format("another priormap is running there (process {}, ",
                                             ::getpid())));
  EXPECT_THAT(refusal, HasSubstr(fmt::format("kill -TERM {0}, stops it checkpointed; one stopped "
                                             "with Ctrl-Z needs kill -CONT {0} as well",
                                             ::getpid())));
}

TEST(DirectoryLock, AMovedLockStillHoldsAndAnUnheldOneHoldsNothing) {
  const testing::TempDir dir;
  DirectoryLock moved;
  EXPECT_FALSE(moved.held());
  {
    DirectoryLock first(dir.path());
    moved = std::move(first);
  }
  EXPECT_TRUE(moved.held());
  EXPECT_THAT(RefusalOf(dir.path()), HasSubstr("another priormap is running there"));
  moved = DirectoryLock();
  EXPECT_EQ(RefusalOf(dir.path()), "");
}

TEST(DirectoryLock, ADirectoryThatDoesNotExistIsNotLocked) {
  const testing::TempDir dir;
  EXPECT_FALSE(LockIfExists(dir / "missing").held());
  EXPECT_TRUE(LockIfExists(dir.path()).held());
  EXPECT_THROW(DirectoryLock(dir / "missing"), UserError);
}

}  // namespace
}  // namespace priormap::app
