// Reading log files whole (ReadLog, ReadCarmenLog, and ReadFileText beside them): gzip members
// of any size, what follows the last member, corrupt and truncated data, large files, and the
// numbers of a CARMEN log parsed exactly as std::from_chars parses them.
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <priormap/core/carmen_io.hpp>
#include <priormap/core/file_io.hpp>
#include <priormap/core/log_io.hpp>
#include <priormap/core/world_bounds.hpp>

#include "testing/diagnostic_matchers.hpp"
#include "testing/log_equality.hpp"
#include "testing/temp_dir.hpp"

namespace priormap {
namespace {

using testing::DiagnosticAt;
using ::testing::ElementsAre;

// `scans` FLASER records of 180 readings each, every one different.
std::string CarmenText(int scans, int seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> millimetres(100, 81910);
  std::string text = "PARAM robot_frontlaser_offset 0.0 nohost 0\n";
  for (int k = 0; k < scans; ++k) {
    text += "FLASER 180";
    for (int i = 0; i < 180; ++i) text += fmt::format(" {:.3f}", millimetres(rng) / 1000.0);
    text += fmt::format(" {0}.5 -2.25 0.125 {0}.5 -2.25 0.125 {0}.0625 nohost {0}.0625\n", k);
    text += fmt::format("ODOM {}.5 -2.25 0.125 0.1 0.2 0.3 {}.03 nohost {}.03\n", k, k, k);
  }
  return text;
}

// The gzip file of `text` (one member), as priormap writes it.
std::string Gzipped(const testing::TempDir& dir, const std::string& text) {
  WriteTextFileAtomically(dir / "member.gz", text);
  return testing::ReadAll(dir / "member.gz");
}

Log Parsed(const std::string& text) {
  Result<Log> log = ParseCarmenLog(text, "text");
  EXPECT_TRUE(log.ok()) << log.error();
  return std::move(log).value();
}

TEST(LogReading, GzipMembersOfAnySizeAreReadWhole) {
  const testing::TempDir dir;
  // The last member's trailer gives the room for the first: too little for the largest.
  const std::string first = CarmenText(300, 1), second = CarmenText(2, 2), third = CarmenText(1, 3);
  testing::WriteAll(dir / "log.gz",
                    Gzipped(dir, first) + Gzipped(dir, second) + Gzipped(dir, third));
  const Log expected = Parsed(first + second + third);
  for (const Result<Log>& read : {ReadLog(dir / "log.gz"), ReadCarmenLog(dir / "log.gz")}) {
    ASSERT_TRUE(read.ok()) << read.error();
    EXPECT_TRUE(testing::SameLog(read.value(), expected));
  }
}

TEST(LogReading, AnEmptyMemberAddsNothing) {
  const testing::TempDir dir;
  const std::string text = CarmenText(3, 4);
  testing::WriteAll(dir / "log.gz", Gzipped(dir, "") + Gzipped(dir, text) + Gzipped(dir, ""));
  const Result<Log> read = ReadLog(dir / "log.gz");
  ASSERT_TRUE(read.ok()) << read.error();
  EXPECT_TRUE(testing::SameLog(read.value(), Parsed(text)));
}

// Bytes after the last member that do not start another were ignored, as zlib's gzread does:
// a second file appended whole, or a member whose magic bytes were damaged, went unread without
// a word. gzip(1) warns of them; here they are an error at the offset where they start.
TEST(LogReading, WhatFollowsTheLastMemberIsAnErrorAtItsOffsetUnlessItStartsAMember) {
  const testing::TempDir dir;
  const std::string text = CarmenText(3, 5);
  const std::string gz = Gzipped(dir, text);
  const std::string name = (dir / "log.gz").string();
  for (const std::string& tail : {std::string("ODOM 1 2 3 0 0 0\n"), std::string(1000, '\0'),
                                  std::string("\x1f"), std::string("\x1f\x8c garbage")}) {
    for (const std::string& members : {gz, Gzipped(dir, "") + gz}) {
      testing::WriteAll(dir / "log.gz", members + tail);
      const std::string message = fmt::format(
          "trailing data after the last gzip member, at byte offset {} (of a {}-byte file): "
          "expected another gzip member (magic bytes 1f 8b) or the end of the file",
          members.size(), members.size() + tail.size());
      for (const std::vector<Diagnostic>& diagnostics :
           {ReadLog(dir / "log.gz").diagnostics(), ReadCarmenLog(dir / "log.gz").diagnostics(),
            ReadFileText(dir / "log.gz").diagnostics()})
        EXPECT_THAT(diagnostics, ElementsAre(DiagnosticAt(name, 0, 0, message)))
            << QuoteForMessage(tail);
    }
  }
  // A second member that is cut short is corrupt.
  testing::WriteAll(dir / "log.gz", gz + gz.substr(0, gz.size() / 2));
  EXPECT_THAT(ReadLog(dir / "log.gz").diagnostics(),
              ElementsAre(DiagnosticAt(name, 0, 0, "corrupt or truncated gzip data")));
  EXPECT_THAT(ReadFileText(dir / "log.gz").diagnostics(),
              ElementsAre(DiagnosticAt(name, 0, 0, "corrupt or truncated gzip data")));
}

// `cat a.gz b.gz c.gz` is one stream, as gzip(1) reads it, whichever reader reads it.
TEST(LogReading, ConcatenatedMembersReadAsTheConcatenationByEveryReader) {
  const testing::TempDir dir;
  const std::string a = CarmenText(2, 11), b = CarmenText(1, 12), c = CarmenText(3, 13);
  testing::WriteAll(dir / "log.gz", Gzipped(dir, a) + Gzipped(dir, b) + Gzipped(dir, c));
  const Result<std::string> text = ReadFileText(dir / "log.gz");
  ASSERT_TRUE(text.ok()) << text.error();
  EXPECT_EQ(text.value(), a + b + c);
  const Result<Log> read = ReadLog(dir / "log.gz");
  ASSERT_TRUE(read.ok()) << read.error();
  EXPECT_TRUE(testing::SameLog(read.value(), Parsed(a + b + c)));
}

TEST(LogReading, CorruptOrTruncatedGzipIsADiagnostic) {
  const testing::TempDir dir;
  const std::string gz = Gzipped(dir, CarmenText(50, 6));
  std::vector<std::string> bad;
  for (const std::size_t keep : {std::size_t{2}, std::size_t{10}, std::size_t{12}, gz.size() / 3,
                                 gz.size() - 5, gz.size() - 1})
    bad.push_back(gz.substr(0, keep));
  std::string bad_crc = gz;
  bad_crc[bad_crc.size() - 6] ^= 0x40;
  bad.push_back(bad_crc);
  std::string bad_size = gz;
  bad_size[bad_size.size() - 1] ^= 0x01;  // ISIZE, the trailer's last byte
  bad.push_back(bad_size);
  std::string bad_data = gz;
  for (std::size_t i = 30; i + 30 < bad_data.size(); i += 97) bad_data[i] = '\x55';
  bad.push_back(bad_data);
  for (std::size_t k = 0; k < bad.size(); ++k) {
    testing::WriteAll(dir / "log.gz", bad[k]);
    for (const Result<Log>& read : {ReadLog(dir / "log.gz"), ReadCarmenLog(dir / "log.gz")}) {
      EXPECT_THAT(read.diagnostics(), ElementsAre(DiagnosticAt((dir / "log.gz").string(), 0, 0,
                                                               "corrupt or truncated gzip data")))
          << "case " << k;
    }
  }
}

// The CRC-32 of gzip (RFC 1952), bit by bit: a test needs only a few bytes of it.
std::uint32_t Crc32(std::string_view bytes) {
  std::uint32_t crc = 0xffffffffu;
  for (const char c : bytes) {
    crc ^= static_cast<unsigned char>(c);
    for (int bit = 0; bit < 8; ++bit) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

// `priormap plot` (ReadLog: libdeflate) said "corrupt or truncated gzip data" of a log that
// `priormap convert` (ReadFileText: zlib) said was cut short: both now say the same, with where
// the damaged member starts, and whether the file ends inside it. The damage says what was
// expected there: "expected DEFLATE data, and a trailer that matches it" was said of a damaged
// header too, and "at byte offset 0 of 15085" read as the first member of 15085.
TEST(LogReading, EveryReaderSaysWhereAGzipMemberIsCutShortOrDamaged) {
  const testing::TempDir dir;
  const std::string gz = Gzipped(dir, CarmenText(50, 6));
  const std::string name = (dir / "log.gz").string();
  const auto diagnostics_of = [&](const std::string& bytes) {
    testing::WriteAll(dir / "log.gz", bytes);
    return std::vector<std::vector<Diagnostic>>{ReadLog(dir / "log.gz").diagnostics(),
                                                ReadCarmenLog(dir / "log.gz").diagnostics(),
                                                ReadFileText(dir / "log.gz").diagnostics()};
  };
  const std::string cut = gz + gz.substr(0, gz.size() / 2);
  for (const std::vector<Diagnostic>& diagnostics : diagnostics_of(cut))
    EXPECT_THAT(diagnostics,
                ElementsAre(DiagnosticAt(
                    name, 0, 0,
                    fmt::format("corrupt or truncated gzip data: the file ends at byte {}, inside "
                                "the gzip member at byte offset {}: expected the rest of that "
                                "member",
                                cut.size(), gz.size()))));
  std::string bad_crc = gz + gz;
  bad_crc[bad_crc.size() - 6] ^= 0x40;  // the second member's CRC-32
  for (const std::vector<Diagnostic>& diagnostics : diagnostics_of(bad_crc))
    EXPECT_THAT(diagnostics,
                ElementsAre(DiagnosticAt(
                    name, 0, 0,
                    fmt::format("corrupt or truncated gzip data: the gzip member at byte offset "
                                "{} (of a {}-byte file) is damaged (incorrect data check): "
                                "expected DEFLATE data and a trailer that matches it",
                                gz.size(), bad_crc.size()))));
  // A damaged header: the second member's header CRC (FHCRC) is wrong, the first member's
  // compression method is not DEFLATE (8), or its flags set a reserved bit.
  std::string header = gz.substr(0, 10);
  header[3] = static_cast<char>(header[3] | 0x02);
  const std::uint32_t crc = (Crc32(header) & 0xffffu) ^ 0x0001u;
  const std::string bad_header_crc =
      gz + header + static_cast<char>(crc & 0xffu) + static_cast<char>(crc >> 8) + gz.substr(10);
  std::string bad_method = gz;
  bad_method[2] = '\x07';
  std::string bad_flags = gz;
  bad_flags[3] = static_cast<char>(bad_flags[3] | 0x20);
  for (const auto& [bytes, at, why] :
       {std::tuple{bad_header_crc, gz.size(), "header crc mismatch"},
        std::tuple{bad_method, std::size_t{0}, "unknown compression method"},
        std::tuple{bad_flags, std::size_t{0}, "unknown header flags set"}}) {
    for (const std::vector<Diagnostic>& diagnostics : diagnostics_of(bytes))
      EXPECT_THAT(diagnostics, ElementsAre(DiagnosticAt(
                                   name, 0, 0,
                                   fmt::format("corrupt or truncated gzip data: the gzip member "
                                               "at byte offset {} (of a {}-byte file) is damaged "
                                               "({}): expected a gzip header",
                                               at, bytes.size(), why))))
          << why;
  }
}

TEST(LogReading, AGzipHeaderCrcIsCheckedByEveryReader) {
  const testing::TempDir dir;
  const std::string text = CarmenText(3, 8);
  const std::string gz = Gzipped(dir, text);
  // The same member with FHCRC set: the CRC-16 of the header follows its 10 bytes.
  std::string header = gz.substr(0, 10);
  header[3] = static_cast<char>(header[3] | 0x02);
  const std::uint32_t crc = Crc32(header) & 0xffffu;
  std::string good = header;
  good += static_cast<char>(crc & 0xffu);
  good += static_cast<char>(crc >> 8);
  good += gz.substr(10);
  std::string bad = good;
  bad[10] = static_cast<char>(bad[10] ^ 0x01);
  testing::WriteAll(dir / "good.log.gz", good);
  testing::WriteAll(dir / "bad.log.gz", bad);
  const Result<Log> read = ReadLog(dir / "good.log.gz");
  ASSERT_TRUE(read.ok()) << read.error();
  EXPECT_TRUE(testing::SameLog(read.value(), Parsed(text)));
  EXPECT_TRUE(ReadFileText(dir / "good.log.gz").ok());
  // ReadLog (libdeflate) refuses what ReadFileText (zlib, as gzip) refuses.
  EXPECT_THAT(ReadLog(dir / "bad.log.gz").diagnostics(),
              ElementsAre(DiagnosticAt((dir / "bad.log.gz").string(), 0, 0,
                                       "corrupt or truncated gzip data")));
  EXPECT_FALSE(ReadFileText(dir / "bad.log.gz").ok());
}

TEST(LogReading, LargeFilesReadTheSamePlainAndGzipped) {
  // Megabytes, compressed to more than 256 KB: the buffers that get their own mapping.
  const testing::TempDir dir;
  const std::string text = CarmenText(1700, 7);
  ASSERT_GT(text.size(), std::size_t{2} << 20);
  testing::WriteAll(dir / "plain.log", text);
  WriteTextFileAtomically(dir / "log.gz", text);
  ASSERT_GT(testing::ReadAll(dir / "log.gz").size(), std::size_t{256} << 10);
  const Log expected = Parsed(text);
  for (const char* name : {"plain.log", "log.gz"}) {
    const Result<Log> read = ReadLog(dir / name);
    ASSERT_TRUE(read.ok()) << read.error();
    EXPECT_TRUE(testing::SameLog(read.value(), expected)) << name;
  }
}

TEST(LogReading, MissingFilesAndDirectoriesAreDiagnostics) {
  const testing::TempDir dir;
  EXPECT_THAT(ReadLog(dir / "missing.log").diagnostics(),
              ElementsAre(DiagnosticAt((dir / "missing.log").string(), 0, 0, "no such file")));
  EXPECT_THAT(ReadCarmenLog(dir.path()).diagnostics(),
              ElementsAre(DiagnosticAt(dir.path().string(), 0, 0, "is a directory")));
}

// What the reader must make of a number: from_chars's value, after an optional '+' that is not
// followed by a sign; nullopt where from_chars takes less than all of it.
std::optional<double> FromChars(std::string text) {
  if (text.size() > 1 && text[0] == '+' && text[1] != '-' && text[1] != '+') text.erase(0, 1);
  double value = 0.0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return value;
}

bool SameNumber(double a, double b) {
  return (std::isnan(a) && std::isnan(b)) || std::memcmp(&a, &b, sizeof a) == 0;
}

// Plain decimals of every length (the reader's fast path and its limits: 19 digits, 2^53, 22
// decimals) and every other spelling from_chars knows.
std::vector<std::string> NumberSpellings() {
  std::vector<std::string> spellings = {"0",
                                        "-0",
                                        "0.0",
                                        "-0.0",
                                        "00000000000000000001.5",
                                        "1.",
                                        ".5",
                                        "-.5",
                                        "+1.5",
                                        "+.5",
                                        "9007199254740992",
                                        "9007199254740993",
                                        "-9007199254740993",
                                        "18446744073709551615",
                                        "18446744073709551616",
                                        "1234567890123456789",
                                        "12345678901234567890",
                                        "0.1234567890123456789",
                                        "0.12345678901234567890123",
                                        "1e3",
                                        "1E-3",
                                        "-2.5e+2",
                                        "4.9e-324",
                                        "1e400",
                                        "-1e400",
                                        "inf",
                                        "-inf",
                                        "infinity",
                                        "nan",
                                        "-nan",
                                        "NaN",
                                        "0.0000000000000000000001",
                                        "0.00000000000000000000001",
                                        "8.191",
                                        "81.91",
                                        "4503599627370497.5"};
  std::mt19937 rng(20261124);
  const std::string digits = "0123456789";
  for (int k = 0; k < 20000; ++k) {
    std::string s = k % 7 == 0 ? "-" : (k % 31 == 0 ? "+" : "");
    const int integer = std::uniform_int_distribution<int>(k % 5 == 0 ? 0 : 1, 21)(rng);
    const int decimals = std::uniform_int_distribution<int>(0, 24)(rng);
    for (int i = 0; i < integer; ++i) s += digits[std::uniform_int_distribution<int>(0, 9)(rng)];
    if (decimals > 0 || integer == 0) s += '.';
    for (int i = 0; i < std::max(decimals, integer == 0 ? 1 : 0); ++i)
      s += digits[std::uniform_int_distribution<int>(0, 9)(rng)];
    if (k % 13 == 0) s += fmt::format("e{}", std::uniform_int_distribution<int>(-30, 30)(rng));
    spellings.push_back(s);
  }
  return spellings;
}

TEST(LogReading, NumbersAreWhatFromCharsMakesOfThem) {
  std::vector<std::string> numbers;
  for (const std::string& s : NumberSpellings())
    if (FromChars(s)) numbers.push_back(s);
  ASSERT_GT(numbers.size(), 19000U);
  // Each number as a reading, where a finite one is required (timestamps) as the logger's
  // timestamp when it is finite, and where a world coordinate is (poses) as the laser's x when
  // it is one. The record's max range at the bound on returns makes the longer readings
  // no-returns, which are kept as read (a FLASER line has none, and the one detected among
  // these numbers would be no bound).
  std::string text;
  for (const std::string& s : numbers) {
    const std::string finite = std::isfinite(*FromChars(s)) ? s : "0";
    const std::string coordinate = IsWithinWorld(*FromChars(s)) ? s : "0";
    text += "ROBOTLASER1 0 0 0 0 1e9 0 0 1 " + s + " 0 " + coordinate +
            " 0 0 0 0 0 0 0 0 0 0 1 nohost " + finite + "\n";
  }
  const Log log = Parsed(text);
  ASSERT_EQ(log.scans.size(), numbers.size());
  int differences = 0;
  for (std::size_t k = 0; k < numbers.size(); ++k) {
    const double expected = *FromChars(numbers[k]);
    const Scan& scan = log.scans[k];
    const bool same =
        SameNumber(scan.ranges[0], expected) &&
        (!std::isfinite(expected) || SameNumber(scan.carmen->logger_timestamp, expected)) &&
        (!IsWithinWorld(expected) || SameNumber(scan.pose.x(), expected));
    if (!same && ++differences <= 10)
      ADD_FAILURE() << numbers[k] << ": read " << scan.ranges[0] << ", from_chars " << expected;
  }
  EXPECT_EQ(differences, 0);
}

TEST(LogReading, WhatFromCharsRejectsIsADiagnostic) {
  for (const std::string_view s : {"-", "+", ".", "-.", "1.2.3", "1e", "0x10", "1,5", "--1", "+-1",
                                   "++1", "1-", "5m", "e5", "nan(", "١"}) {
    const Result<Log> log = ParseCarmenLog(fmt::format("FLASER 1 {} 0 0 0 0 0 0\n", s), "text");
    EXPECT_THAT(log.diagnostics(),
                ElementsAre(DiagnosticAt("text", 1, 10, "expected a range reading (a number)")))
        << s;
  }
}

}  // namespace
}  // namespace priormap
