// Reading files whole (plain or gzip, recognised by content) and writing them atomically.
#include <atomic>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <thread>
#include <unistd.h>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <priormap/core/file_io.hpp>
#include <priormap/core/log_io.hpp>

#include "testing/ended_process.hpp"
#include "testing/temp_dir.hpp"

namespace priormap {
namespace {

namespace fs = std::filesystem;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::UnorderedElementsAre;

// Bytes of every value, several MiB: more than one read chunk.
std::string BinaryContent(std::size_t size) {
  std::string content(size, '\0');
  std::uint32_t state = 12345;
  for (char& c : content) {
    state = state * 1664525U + 1013904223U;
    c = static_cast<char>(state >> 24);
  }
  return content;
}

std::string Text(const Result<std::string>& result) {
  if (!result.ok()) ADD_FAILURE() << result.error();
  return result.ok() ? result.value() : std::string();
}

TEST(FileIo, ReadsPlainFilesByteForByte) {
  const testing::TempDir dir;
  const std::string content = std::string("line 1\r\nline 2\n\0nul\n", 20) + BinaryContent(3 << 20);
  testing::WriteAll(dir / "plain.bin", content);
  EXPECT_EQ(Text(ReadFileText(dir / "plain.bin")), content);
  testing::WriteAll(dir / "empty", "");
  EXPECT_EQ(Text(ReadFileText(dir / "empty")), "");
}

TEST(FileIo, DecompressesGzipRecognisedByItsMagicBytes) {
  const testing::TempDir dir;
  const std::string content = "FLASER 3 1 2 3 0 0 0 0 0 0\n" + BinaryContent(3 << 20);
  WriteTextFileAtomically(dir / "data.gz", content);
  const std::string compressed = testing::ReadAll(dir / "data.gz");
  ASSERT_EQ(compressed.substr(0, 2), "\x1f\x8b");
  EXPECT_EQ(Text(ReadFileText(dir / "data.gz")), content);
  // The name does not matter.
  fs::rename(dir / "data.gz", dir / "data.log");
  EXPECT_EQ(Text(ReadFileText(dir / "data.log")), content);
}

TEST(FileIo, PlainFileNamedGzIsReadAsIs) {
  const testing::TempDir dir;
  testing::WriteAll(dir / "plain.gz", "not compressed\n");
  EXPECT_EQ(Text(ReadFileText(dir / "plain.gz")), "not compressed\n");
}

TEST(FileIo, EmptyContentRoundTripsThroughGzip) {
  const testing::TempDir dir;
  WriteTextFileAtomically(dir / "empty.gz", "");
  EXPECT_EQ(testing::ReadAll(dir / "empty.gz").substr(0, 2), "\x1f\x8b");
  EXPECT_EQ(Text(ReadFileText(dir / "empty.gz")), "");
}

TEST(FileIo, ConcatenatedGzipMembersAreReadWhole) {
  const testing::TempDir dir;
  WriteTextFileAtomically(dir / "a.gz", "first\n");
  WriteTextFileAtomically(dir / "b.gz", "second\n");
  testing::WriteAll(dir / "ab.gz", testing::ReadAll(dir / "a.gz") + testing::ReadAll(dir / "b.gz"));
  EXPECT_EQ(Text(ReadFileText(dir / "ab.gz")), "first\nsecond\n");
}

TEST(FileIo, MissingFileIsADiagnostic) {
  const testing::TempDir dir;
  const Result<std::string> result = ReadFileText(dir / "missing.txt");
  ASSERT_FALSE(result.ok());
  ASSERT_EQ(result.diagnostics().size(), 1U);
  const Diagnostic& d = result.diagnostics()[0];
  EXPECT_EQ(d.file, (dir / "missing.txt").string());
  EXPECT_EQ(d.line, 0);
  EXPECT_EQ(d.col, 0);
  EXPECT_EQ(d.message, "no such file");
}

// A file that exists and cannot be opened says why. A socket is one even for root (ENXIO).
TEST(FileIo, AFileThatCannotBeOpenedSaysWhy) {
  const testing::TempDir dir;
  const std::string socket_path = (dir / "socket").string();
  const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
  ASSERT_GE(fd, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  ASSERT_LT(socket_path.size(), sizeof(address.sun_path));
  socket_path.copy(address.sun_path, socket_path.size());
  ASSERT_EQ(::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)), 0);
  for (const std::vector<Diagnostic>& diagnostics :
       {ReadFileText(socket_path).diagnostics(), ReadLog(socket_path).diagnostics()}) {
    ASSERT_EQ(diagnostics.size(), 1U);
    EXPECT_EQ(diagnostics[0].message, "cannot open file for reading: No such device or address");
  }
  ::close(fd);
}

TEST(FileIo, DirectoryIsADiagnostic) {
  const testing::TempDir dir;
  const Result<std::string> result = ReadFileText(dir.path());
  ASSERT_EQ(result.diagnostics().size(), 1U);
  EXPECT_EQ(result.diagnostics()[0].message, "is a directory, expected a file");
}

TEST(FileIo, TruncatedGzipIsADiagnostic) {
  const testing::TempDir dir;
  WriteTextFileAtomically(dir / "data.gz", BinaryContent(100000));
  const std::string compressed = testing::ReadAll(dir / "data.gz");
  for (const std::size_t keep : {compressed.size() - 4, compressed.size() / 2, std::size_t{12}}) {
    testing::WriteAll(dir / "cut.gz", compressed.substr(0, keep));
    const Result<std::string> result = ReadFileText(dir / "cut.gz");
    ASSERT_FALSE(result.ok()) << "kept " << keep << " bytes";
    EXPECT_THAT(result.diagnostics()[0].message, HasSubstr("corrupt or truncated gzip data"));
  }
}

TEST(FileIo, CorruptGzipIsADiagnostic) {
  const testing::TempDir dir;
  WriteTextFileAtomically(dir / "data.gz", std::string(100000, 'a') + "b");
  std::string compressed = testing::ReadAll(dir / "data.gz");
  compressed[compressed.size() - 6] ^= 0x40;  // the CRC of the trailer
  testing::WriteAll(dir / "bad-crc.gz", compressed);
  const Result<std::string> result = ReadFileText(dir / "bad-crc.gz");
  ASSERT_FALSE(result.ok());
  EXPECT_THAT(result.diagnostics()[0].message, HasSubstr("corrupt or truncated gzip data"));
}

// ---- writing ----

TEST(FileIo, WriteTextFileAtomicallyWritesPlainOrGzipByName) {
  const testing::TempDir dir;
  const std::string binary = BinaryContent(1 << 20);
  WriteTextFileAtomically(dir / "plain.txt", binary);
  EXPECT_EQ(testing::ReadAll(dir / "plain.txt"), binary);
  WriteTextFileAtomically(dir / "packed.txt.gz", binary);
  const std::string compressed = testing::ReadAll(dir / "packed.txt.gz");
  EXPECT_EQ(compressed.substr(0, 2), "\x1f\x8b");
  EXPECT_EQ(Text(ReadFileText(dir / "packed.txt.gz")), binary);
  EXPECT_THAT(testing::FilesIn(dir.path()), UnorderedElementsAre("plain.txt", "packed.txt.gz"));
}

TEST(FileIo, WriteReplacesAnExistingFile) {
  const testing::TempDir dir;
  testing::WriteAll(dir / "out.txt", "old content that is longer than the new one\n");
  WriteTextFileAtomically(dir / "out.txt", "new\n");
  EXPECT_EQ(testing::ReadAll(dir / "out.txt"), "new\n");
  EXPECT_THAT(testing::FilesIn(dir.path()), ElementsAre("out.txt"));
}

struct WriterFailed : std::runtime_error {
  using std::runtime_error::runtime_error;
};

TEST(FileIo, ThrowingWriterLeavesNoTemporaryAndTheTargetUntouched) {
  const testing::TempDir dir;
  testing::WriteAll(dir / "out.txt", "previous\n");
  fs::path temporary;
  EXPECT_THROW(WriteFileAtomically(dir / "out.txt",
                                   [&](const fs::path& path) {
                                     temporary = path;
                                     std::ofstream(path) << "half written";
                                     throw WriterFailed("disk on fire");
                                   }),
               WriterFailed);
  EXPECT_EQ(temporary.parent_path(), dir.path());  // a sibling, so that rename is atomic
  EXPECT_NE(temporary.filename(), "out.txt");
  EXPECT_FALSE(fs::exists(temporary));
  EXPECT_EQ(testing::ReadAll(dir / "out.txt"), "previous\n");
  EXPECT_THAT(testing::FilesIn(dir.path()), ElementsAre("out.txt"));
}

TEST(FileIo, ThrowingWriterLeavesNoFileWhenThereWasNone) {
  const testing::TempDir dir;
  EXPECT_THROW(WriteFileAtomically(dir / "out.txt",
                                   [](const fs::path& path) {
                                     std::ofstream(path) << "half written";
                                     throw WriterFailed("no");
                                   }),
               WriterFailed);
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST(FileIo, WriterThatCreatesNoFileIsAnIoError) {
  const testing::TempDir dir;
  EXPECT_THROW(WriteFileAtomically(dir / "out.txt", [](const fs::path&) {}), IoError);
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST(FileIo, WritingOverADirectoryIsAnIoErrorAndLeavesNoTemporary) {
  const testing::TempDir dir;
  fs::create_directory(dir / "taken");
  testing::WriteAll(dir / "taken" / "inside", "x");
  try {
    WriteTextFileAtomically(dir / "taken", "content");
    FAIL() << "expected IoError";
  } catch (const IoError& e) {
    EXPECT_THAT(e.what(), HasSubstr((dir / "taken").string() + ": cannot write"));
  }
  EXPECT_THAT(testing::FilesIn(dir.path()), ElementsAre("taken"));
  EXPECT_EQ(testing::ReadAll(dir / "taken" / "inside"), "x");
}

TEST(FileIo, WritingIntoAMissingDirectoryIsAnIoError) {
  const testing::TempDir dir;
  const fs::path path = dir / "no" / "such" / "dir" / "out.txt";
  try {
    WriteTextFileAtomically(path, "content");
    FAIL() << "expected IoError";
  } catch (const IoError& e) {
    EXPECT_THAT(e.what(), HasSubstr(path.string() + ": cannot write: directory " +
                                    (dir / "no" / "such" / "dir").string() + " does not exist"));
  }
  EXPECT_FALSE(fs::exists(dir / "no"));
  EXPECT_THROW(WriteFileAtomically(path, [](const fs::path&) { FAIL() << "must not be called"; }),
               IoError);
}

TEST(FileIo, ParentThatIsAFileIsAnIoError) {
  const testing::TempDir dir;
  testing::WriteAll(dir / "file", "x");
  EXPECT_THROW(WriteTextFileAtomically(dir / "file" / "out.txt", "content"), IoError);
}

// ---- positions ----

TEST(FileIo, PositionOfOffsetCountsLinesAndColumnsFromOne) {
  const std::string text = "ab\ncd\n\nxyz";
  const auto at = [&](std::size_t offset) {
    const TextPosition p = PositionOfOffset(text, offset);
    return std::pair(p.line, p.col);
  };
  EXPECT_EQ(at(0), std::pair(1, 1));
  EXPECT_EQ(at(1), std::pair(1, 2));
  EXPECT_EQ(at(2), std::pair(1, 3));  // the newline itself ends line 1
  EXPECT_EQ(at(3), std::pair(2, 1));
  EXPECT_EQ(at(5), std::pair(2, 3));
  EXPECT_EQ(at(6), std::pair(3, 1));  // an empty line
  EXPECT_EQ(at(7), std::pair(4, 1));
  EXPECT_EQ(at(9), std::pair(4, 3));
  EXPECT_EQ(at(10), std::pair(4, 4));    // one past the end
  EXPECT_EQ(at(1000), std::pair(4, 4));  // clamped to the end
  EXPECT_EQ(PositionOfOffset("", 0).line, 1);
  EXPECT_EQ(PositionOfOffset("", 5).col, 1);
}

TEST(FileIo, PositionOfOffsetCountsCarriageReturnsAndBytesAsColumns) {
  // Columns are bytes: a CR before the newline, or a multi-byte UTF-8 character, takes room.
  EXPECT_EQ(PositionOfOffset("a\r\nb", 3).line, 2);
  EXPECT_EQ(PositionOfOffset("a\r\nb", 3).col, 1);
  EXPECT_EQ(PositionOfOffset("a\r\nb", 2).col, 3);
  EXPECT_EQ(PositionOfOffset("\xc3\xa9x", 2).col, 3);
}

TEST(FileIo, WritingThroughASymbolicLinkReplacesItsTargetAndKeepsTheLink) {
  const testing::TempDir dir;
  WriteTextFileAtomically(dir / "target.txt", "old");
  std::filesystem::create_symlink("target.txt", dir / "link.txt");
  WriteTextFileAtomically(dir / "link.txt", "new");
  EXPECT_TRUE(std::filesystem::is_symlink(dir / "link.txt"));
  EXPECT_EQ(ReadFileText(dir / "target.txt").value(), "new");
}

TEST(FileIo, ALinkToAFileNotYetMadeMakesItInTheLinksDirectoryOrElsewhere) {
  const testing::TempDir dir;
  std::filesystem::create_directory(dir / "other");
  std::filesystem::create_symlink("new.txt", dir / "dangling.txt");
  std::filesystem::create_symlink("../other/elsewhere.txt", dir / "other" / "up.txt");
  WriteTextFileAtomically(dir / "dangling.txt", "a");
  WriteTextFileAtomically(dir / "other" / "up.txt", "b");
  EXPECT_TRUE(std::filesystem::is_symlink(dir / "dangling.txt"));
  EXPECT_EQ(ReadFileText(dir / "new.txt").value(), "a");
  EXPECT_TRUE(std::filesystem::is_symlink(dir / "other" / "up.txt"));
  EXPECT_EQ(ReadFileText(dir / "other" / "elsewhere.txt").value(), "b");
}

// A FIFO (or a device, /dev/stdout) is written in place, not renamed over: that would make it a
// plain file, and the reader at its other end would get nothing.
TEST(FileIo, AFifoIsWrittenInPlace) {
  const testing::TempDir dir;
  const std::filesystem::path fifo = dir / "pipe";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::string received;
  std::thread reader([&] { received = testing::ReadAll(fifo); });
  WriteTextFileAtomically(fifo, "through the pipe");
  reader.join();
  EXPECT_EQ(received, "through the pipe");
  EXPECT_TRUE(std::filesystem::is_fifo(fifo));
}

TEST(FileIo, AnUpperCaseGzExtensionCompressesToo) {
  const testing::TempDir dir;
  WriteTextFileAtomically(dir / "LOG.JSON.GZ", "text");
  EXPECT_EQ(testing::ReadAll(dir / "LOG.JSON.GZ").substr(0, 2), "\x1f\x8b");
}

TEST(FileIo, AReplacedFileKeepsItsPermissions) {
  namespace fs = std::filesystem;
  const testing::TempDir dir;
  WriteTextFileAtomically(dir / "private.txt", "old");
  fs::permissions(dir / "private.txt", fs::perms::owner_read | fs::perms::owner_write);
  WriteTextFileAtomically(dir / "private.txt", "new");
  EXPECT_EQ(fs::status(dir / "private.txt").permissions(),
            fs::perms::owner_read | fs::perms::owner_write);
  EXPECT_EQ(ReadFileText(dir / "private.txt").value(), "new");
}

TEST(FileIo, IsNumberedNameMatchesPrefixDigitsSuffixOnly) {
  EXPECT_TRUE(IsNumberedName("chain0.png", "chain", ".png", false));
  EXPECT_TRUE(IsNumberedName("chain12.png", "chain", ".png", false));
  EXPECT_FALSE(IsNumberedName("chain012.png", "chain", ".png", false));
  EXPECT_TRUE(IsNumberedName("run_007.csv", "run_", ".csv", true));
  EXPECT_FALSE(IsNumberedName("chain.png", "chain", ".png", false));    // no number
  EXPECT_FALSE(IsNumberedName("chain1a.png", "chain", ".png", false));  // not all digits
  EXPECT_FALSE(IsNumberedName("chain1.png.bak", "chain", ".png", false));
  EXPECT_FALSE(IsNumberedName("mychain1.png", "chain", ".png", false));
  EXPECT_FALSE(IsNumberedName("chain-1.png", "chain", ".png", false));
  EXPECT_FALSE(IsNumberedName("chainpng", "chain", "png", false));  // prefix and suffix only
}

// What a handler of SIGINT/SIGTERM/SIGHUP does before the signal ends the process: the
// temporary files of the writes in progress go, nested or concurrent ones too; nothing else does.
TEST(FileIo, TheSignalCleanupRemovesTheTemporaryFilesOfWritesInProgress) {
  const testing::TempDir dir;
  testing::WriteAll(dir / "a.txt", "previous a\n");
  testing::WriteAll(dir / ".b.txt.tmp-1-0", "another process's, maybe still running");
  fs::path temporary_a;
  fs::path temporary_b;
  EXPECT_THROW(WriteFileAtomically(dir / "a.txt",
                                   [&](const fs::path& path) {
                                     temporary_a = path;
                                     std::ofstream(path) << "half of a";
                                     EXPECT_THROW(WriteFileAtomically(
                                                      dir / "b.txt",
                                                      [&](const fs::path& inner) {
                                                        temporary_b = inner;
                                                        std::ofstream(inner) << "half of b";
                                                        ASSERT_TRUE(fs::exists(temporary_a));
                                                        ASSERT_TRUE(fs::exists(temporary_b));
                                                        RemoveTemporaryFilesInProgress();
                                                        EXPECT_FALSE(fs::exists(temporary_a));
                                                        EXPECT_FALSE(fs::exists(temporary_b));
                                                      }),
                                                  IoError);
                                   }),
               IoError);
  EXPECT_THAT(testing::FilesIn(dir.path()), UnorderedElementsAre("a.txt", ".b.txt.tmp-1-0"));
  EXPECT_EQ(testing::ReadAll(dir / "a.txt"), "previous a\n");
}

// A write that ended, well or not, leaves its temporary file's name unregistered: a later file of
// that name (however unlikely) is not the cleanup's to remove.
TEST(FileIo, AFinishedWriteLeavesNothingForTheSignalCleanup) {
  const testing::TempDir dir;
  std::vector<fs::path> temporaries;
  WriteFileAtomically(dir / "done.txt", [&](const fs::path& path) {
    temporaries.push_back(path);
    std::ofstream(path) << "whole";
  });
  EXPECT_THROW(WriteFileAtomically(dir / "thrown.txt",
                                   [&](const fs::path& path) {
                                     temporaries.push_back(path);
                                     std::ofstream(path) << "half";
                                     throw WriterFailed("no");
                                   }),
               WriterFailed);
  EXPECT_THROW(WriteFileAtomically(dir / "never.txt",
                                   [&](const fs::path& path) { temporaries.push_back(path); }),
               IoError);
  ASSERT_EQ(temporaries.size(), 3u);
  for (const fs::path& temporary : temporaries) testing::WriteAll(temporary, "someone else's");
  RemoveTemporaryFilesInProgress();
  for (const fs::path& temporary : temporaries) EXPECT_TRUE(fs::exists(temporary)) << temporary;
  EXPECT_EQ(testing::ReadAll(dir / "done.txt"), "whole");
}

// Writes from several threads at once: each file is whole, and no temporary file is left.
TEST(FileIo, ConcurrentWritesRegisterAndReleaseTheirTemporaryFiles) {
  const testing::TempDir dir;
  std::vector<std::thread> writers;
  for (int t = 0; t < 8; ++t) {
    writers.emplace_back([&dir, t] {
      for (int i = 0; i < 20; ++i)
        WriteTextFileAtomically(dir / ("out" + std::to_string(t) + ".txt"), std::to_string(i));
    });
  }
  for (std::thread& writer : writers) writer.join();
  RemoveTemporaryFilesInProgress();
  EXPECT_EQ(testing::FilesIn(dir.path()).size(), 8u);
  for (int t = 0; t < 8; ++t)
    EXPECT_EQ(testing::ReadAll(dir / ("out" + std::to_string(t) + ".txt")), "19");
}

// A write killed mid-way by SIGKILL (which no handler sees), or by a crash, leaves its temporary
// file. The cleanup removes those of the outputs named whose process has ended, or that an
// earlier process of this one's PID left; nothing that a running process may be writing, and no
// other file.
TEST(FileIo, StaleTemporaryFilesOfEndedWritersAreRemoved) {
  const testing::TempDir dir;
  const std::string ended = std::to_string(testing::EndedProcessId());
  const std::string ours = std::to_string(::getpid());
  const std::vector<std::string> stale = {".out.bin.tmp-" + ended + "-3",
                                          ".out.bin.tmp-" + ours + "-4000000000"};
  const std::vector<std::string> kept = {
      ".out.bin.tmp-1-0",                     // process 1 runs
      ".other.bin.tmp-" + ended + "-0",       // not an output named
      ".out.bin.tmp-0-1",                     // no process's ID
      ".out.bin.tmp-99999999999999999999-1",  // nor this
      ".out.bin.tmp-" + ended,                // no counter
      ".out.bin.tmp-" + ended + "-x",         // nor this
      "out.bin.tmp-" + ended + "-0",          // no leading dot
      ".out.bin.tmp-0" + ended + "-0",        // not as getpid() is written
      "out.bin"};
  for (const std::string& name : stale) testing::WriteAll(dir / name, "half");
  for (const std::string& name : kept) testing::WriteAll(dir / name, "kept");
  fs::create_directory(dir / (".out.bin.tmp-" + ended + "-9"));  // not a file
  const auto out = [](std::string_view name) { return name == "out.bin"; };
  EXPECT_THAT(RemoveStaleTemporaryFiles(dir.path(), out),
              UnorderedElementsAre(dir / stale[0], dir / stale[1]));
  std::vector<std::string> left = kept;
  left.push_back(".out.bin.tmp-" + ended + "-9");
  EXPECT_THAT(testing::FilesIn(dir.path()), ::testing::UnorderedElementsAreArray(left));
  EXPECT_TRUE(RemoveStaleTemporaryFiles(dir / "missing", out).empty());
}

// This process's writes in progress keep their temporary files, from the same thread or another,
// while the cleanup runs again and again: every write completes.
TEST(FileIo, TheStaleCleanupKeepsThisProcessesWritesInProgress) {
  const testing::TempDir dir;
  const auto any = [](std::string_view) { return true; };
  WriteFileAtomically(dir / "a.txt", [&](const fs::path& path) {
    std::ofstream(path) << "whole";
    EXPECT_TRUE(RemoveStaleTemporaryFiles(dir.path(), any).empty());
    EXPECT_TRUE(fs::exists(path));
  });
  EXPECT_EQ(testing::ReadAll(dir / "a.txt"), "whole");

  std::atomic<bool> writing{true};
  std::atomic<int> failures{0};
  std::thread cleaner([&] {
    while (writing)
      if (!RemoveStaleTemporaryFiles(dir.path(), any).empty()) ++failures;
  });
  std::vector<std::thread> writers;
  for (int t = 0; t < 4; ++t) {
    writers.emplace_back([&dir, &failures, t] {
      for (int i = 0; i < 100; ++i) {
        try {
          WriteTextFileAtomically(dir / ("out" + std::to_string(t) + ".txt"), std::to_string(i));
        } catch (const IoError&) {
          ++failures;
        }
      }
    });
  }
  for (std::thread& writer : writers) writer.join();
  writing = false;
  cleaner.join();
  EXPECT_EQ(failures.load(), 0);
  EXPECT_EQ(testing::FilesIn(dir.path()).size(), 5u);
}

// Outputs other than checkpoints have no session start that knows their names: writing a file
// removes the temporaries that killed writes of that same file left, and nothing else (the
// directory may hold the user's own files, and other writers' temporaries).
TEST(FileIo, AWriteRemovesTheStaleTemporariesOfItsOwnFileOnly) {
  const testing::TempDir dir;
  const std::string ended = std::to_string(testing::EndedProcessId());
  const std::string stale = ".summary.json.tmp-" + ended + "-0";
  const std::vector<std::string> kept = {
      ".summary.json.tmp-1-0",  // process 1 runs: it may be writing it
      ".summary.json.tmp-" + std::to_string(::getppid()) + "-2",  // so does this test's parent
      ".trace.csv.tmp-" + ended + "-0",  // another output's: removed when it is written
      ".notes.txt.tmp-" + ended + "-0",  // the user's
      "notes.txt"};
  testing::WriteAll(dir / stale, "half a summary");
  for (const std::string& name : kept) testing::WriteAll(dir / name, "kept");
  WriteTextFileAtomically(dir / "summary.json", "{}\n");
  std::vector<std::string> left = kept;
  left.push_back("summary.json");
  EXPECT_THAT(testing::FilesIn(dir.path()), ::testing::UnorderedElementsAreArray(left));

  // Written through a link, the file is the link's target, whose temporaries lie beside it.
  const testing::TempDir other;
  testing::WriteAll(other / stale, "half a summary");
  fs::create_symlink(other / "summary.json", dir / "linked.json");
  const std::string linked_stale = ".linked.json.tmp-" + ended + "-0";
  testing::WriteAll(dir / linked_stale, "kept: the link is never written in place");
  WriteTextFileAtomically(dir / "linked.json", "{}\n");
  EXPECT_THAT(testing::FilesIn(other.path()), ::testing::UnorderedElementsAre("summary.json"));
  EXPECT_TRUE(fs::exists(dir / linked_stale));
}

}  // namespace
}  // namespace priormap
