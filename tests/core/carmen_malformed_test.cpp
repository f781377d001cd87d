// Bad CARMEN input: every problem is reported as a Diagnostic at the file, line and column of
// the offending field, with a message saying what was expected; nothing crashes.
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <priormap/core/carmen_io.hpp>
#include <priormap/core/file_io.hpp>
#include <priormap/core/json_io.hpp>

#include "testing/diagnostic_matchers.hpp"
#include "testing/temp_dir.hpp"

namespace priormap {
namespace {

using testing::DiagnosticAt;
using ::testing::ElementsAre;
using testing::Lines;
using ::testing::SizeIs;

constexpr const char* kName = "bad.log";

// The diagnostics of parsing `text`, which must fail.
std::vector<Diagnostic> ParseErrors(const std::string& text,
                                    const CarmenReadOptions& options = {}) {
  const Result<Log> result = ParseCarmenLog(text, kName, options);
  EXPECT_FALSE(result.ok()) << "parsed without error:\n" << text;
  return result.diagnostics();
}

// One bad line: exactly one diagnostic at line 1, `col`, containing `message_part`.
void ExpectLineError(const std::string& line, int col, const std::string& message_part) {
  SCOPED_TRACE(line);
  EXPECT_THAT(ParseErrors(line + "\n"), ElementsAre(DiagnosticAt(kName, 1, col, message_part)));
}

// A complete, valid ROBOTLASER1 line with 3 readings and no remissions; fields (1-based columns):
// laser_type 13, start_angle 15, fov 20, angular_resolution 22, max_range 27, accuracy 30,
// remission_mode 35, count 37, readings 39 41 43, remission count 45, then 6 pose and 5 safety
// values; 67 characters.
const std::string kRobotLaser =
    "ROBOTLASER1 0 -1.5 3 0.01 80 0.01 0 3 1 2 3 0 0 0 0 0 0 0 0 0 0 0 0";

TEST(CarmenMalformed, ValidRobotLaserBaselineParses) {
  // The ROBOTLASER1 cases below each break this line in one place.
  EXPECT_TRUE(ParseCarmenLog(kRobotLaser + "\n", kName).ok());
}

// A --min-range at or beyond the max range would leave no reading valid; before, the max range
// was dropped instead, and every no-return reading became a wall.
// The message once said "the max range 80 m of scan 0 (its record's, the detected or the given
// one)": it now says which of them applies, at the scan's line, in the names the caller gives the
// two limits (a command's options).
TEST(CarmenMalformed, AMinimumRangeNotBelowTheMaxRangeIsRefused) {
  CarmenReadOptions options;
  options.min_range = 85.0;
  EXPECT_THAT(ParseErrors("# a comment\n" + kRobotLaser + "\n", options),
              ElementsAre(DiagnosticAt(kName, 2, 0,
                                       "the minimum range 85 m is not below the max range of "
                                       "scan 0, 80 m, its ROBOTLASER1 record's maximum_range: "
                                       "no reading could be valid")));
  options.min_range_name = "--min-range";
  options.max_range_name = "--max-range";
  options.max_range = 90.0;
  EXPECT_THAT(ParseErrors(kRobotLaser + "\n", options),
              ElementsAre(DiagnosticAt(kName, 1, 0,
                                       "--min-range 85 m is not below the max range of scan 0, "
                                       "80 m, its ROBOTLASER1 record's maximum_range (--max-range "
                                       "90 m is longer, and can only shorten it)")));
  options.max_range = 70.0;
  options.min_range = 70.0;
  EXPECT_THAT(ParseErrors(kRobotLaser + "\n", options),
              ElementsAre(DiagnosticAt(kName, 1, 0,
                                       "--min-range 70 m is not below the max range of scan 0, "
                                       "70 m, from --max-range: no reading could be valid")));
  options = {};
  options.min_range = 0.5;
  EXPECT_TRUE(ParseCarmenLog(kRobotLaser + "\n", kName, options).ok());
}

// FLASER lines carry no max range: the one that applies is detected from their no-return
// readings (here 12 at 50 m: 49.5 m), which the message says, at the first scan it leaves empty.
TEST(CarmenMalformed, AMinimumRangeNotBelowTheDetectedMaxRangeSaysItWasDetected) {
  std::string text = "ODOM 0 0 0 0 0 0\n";
  for (int k = 0; k < 3; ++k) text += "FLASER 5 1 50 50 50 50 0 0 0 0 0 0\n";
  CarmenReadOptions options;
  options.min_range = 60.0;
  EXPECT_THAT(ParseErrors(text, options),
              ElementsAre(DiagnosticAt(kName, 2, 0,
                                       "the minimum range 60 m is not below the max range of "
                                       "scan 0, 49.5 m, detected from the no-return readings of "
                                       "the FLASER and RLASER lines: no reading could be "
                                       "valid")));
}

// A Latin-1 PARAM value (an old log's) or host name is kept as read, and located, so that a
// command writing JSON, which holds only UTF-8, can refuse it where it is instead of replacing
// its bytes by U+FFFD without a word.
TEST(CarmenMalformed, TextThatIsNotUtf8IsKeptAndLocated) {
  const std::string text =
      "PARAM robot_name caf\xc3\xa9\n"            // UTF-8: fine
      "PARAM robot_place M\xfcnchen \xe9t\xe9\n"  // Latin-1
      "ODOM 0 0 0 0 0 0 1.5 h\xf6st 1.5\n";
  CarmenReadStats stats;
  const Result<Log> log = ParseCarmenLog(text, kName, {}, &stats);
  ASSERT_TRUE(log.ok()) << log.error();
  EXPECT_EQ(log.value().params.at(1).second, "M\xfcnchen \xe9t\xe9");
  EXPECT_EQ(log.value().odometry.at(0).carmen->host, "h\xf6st");
  ASSERT_TRUE(stats.not_utf8.has_value());
  EXPECT_THAT(std::vector<Diagnostic>{*stats.not_utf8},
              ElementsAre(DiagnosticAt(kName, 2, 20,
                                       "expected UTF-8 text in a PARAM value, got byte '\\xfc'")));

  CarmenReadStats host_stats;
  ASSERT_TRUE(ParseCarmenLog("ODOM 0 0 0 0 0 0 1.5 h\xf6st 1.5\n", kName, {}, &host_stats).ok());
  ASSERT_TRUE(host_stats.not_utf8.has_value());
  EXPECT_THAT(std::vector<Diagnostic>{*host_stats.not_utf8},
              ElementsAre(DiagnosticAt(kName, 1, 23,
                                       "expected UTF-8 text in a host name, got byte '\\xf6'")));

  CarmenReadStats utf8_stats;
  ASSERT_TRUE(ParseCarmenLog("PARAM robot_name caf\xc3\xa9\n", kName, {}, &utf8_stats).ok());
  EXPECT_FALSE(utf8_stats.not_utf8.has_value());
}

TEST(CarmenMalformed, AByteOrderMarkIsSkippedNotTakenForARecord) {
  const Result<Log> log =
      ParseCarmenLog("\xef\xbb\xbf" + kRobotLaser + "\n" + kRobotLaser + "\n", kName);
  ASSERT_TRUE(log.ok()) << log.error();
  EXPECT_EQ(log.value().scans.size(), 2U);
}

TEST(CarmenMalformed, NonNumericCountReportsTheCountColumn) {
  ExpectLineError("FLASER x 1 2 3 0 0 0 0 0 0", 8,
                  "expected the number of readings (a non-negative integer), got 'x'");
}

TEST(CarmenMalformed, NegativeCountIsRejected) {
  ExpectLineError("FLASER -1 1 2 3 0 0 0 0 0 0", 8,
                  "expected the number of readings (a non-negative integer), got '-1'");
}

TEST(CarmenMalformed, CountTooLargeForAnIntegerIsRejected) {
  ExpectLineError("FLASER 99999999999999999999 1 2 3 0 0 0 0 0 0", 8,
                  "expected the number of readings (a non-negative integer), got "
                  "'99999999999999999999'");
}

TEST(CarmenMalformed, CountLargerThanTheFieldsOnTheLineIsReportedAtTheCount) {
  ExpectLineError("FLASER 9 1 2 3 0 0 0 0 0 0", 8,
                  "the number of readings is 9, but only 9 fields follow it (expected 9 values, "
                  "then 6 pose values)");
}

TEST(CarmenMalformed, LineCutOffInsideTheReadingsIsReportedAtTheCount) {
  ExpectLineError("FLASER 180 1.5 1.6 1.7", 8,
                  "the number of readings is 180, but only 3 fields follow it");
}

TEST(CarmenMalformed, TruncatedFlaserWithTimestampsReportsTheFieldCountAtTheCount) {
  // One reading missing: 4 readings, 6 pose values and 3 timestamp fields follow the count 5.
  ExpectLineError("FLASER 5 1 2 3 4 0 0 0 0 0 0 1.5 host 1.5", 8,
                  "the number of readings is 5, but 13 fields follow it (expected 5 values, then "
                  "6 pose values and optionally ipc_timestamp host logger_timestamp: 11 or 14 "
                  "fields)");
}

TEST(CarmenMalformed, MissingPoseFieldsAreReportedAtTheCount) {
  ExpectLineError("FLASER 3 1 2 3 0 0 0 0 0", 8,
                  "the number of readings is 3, but only 8 fields follow it (expected 3 values, "
                  "then 6 pose values)");
}

TEST(CarmenMalformed, GarbageReadingIsReportedAtItsColumn) {
  ExpectLineError("FLASER 3 1 3.x4 2 0 0 0 0 0 0", 12,
                  "expected a range reading (a number), got '3.x4'");
}

TEST(CarmenMalformed, ReadingWithEmbeddedNulIsRejected) {
  const std::string line("FLASER 3 1 2\0 3 0 0 0 0 0 0", 27);
  ExpectLineError(line, 12, "expected a range reading (a number), got '2");
}

TEST(CarmenMalformed, NanPoseIsRejectedAsNonFinite) {
  ExpectLineError("FLASER 3 1 2 3 nan 0 0 0 0 0", 16, "laser pose x must be finite, got 'nan'");
}

TEST(CarmenMalformed, InfiniteOdometryThetaIsRejectedAsNonFinite) {
  ExpectLineError("FLASER 3 1 2 3 0 0 0 0 0 inf", 26,
                  "odometry pose theta must be finite, got 'inf'");
}

// A finite but absurd position was read, and failed later as a grid too large to make, without
// a line to look at; it is reported at its field, with the bound it breaks.
TEST(CarmenMalformed, APositionBeyondTheWorldIsReportedAtItsField) {
  ExpectLineError("FLASER 3 1 2 3 1e300 0 0 0 0 0", 16,
                  "expected laser pose x in metres of a local frame, at most 1e+09 in magnitude, "
                  "got '1e300'");
  ExpectLineError("FLASER 3 1 2 3 0 -2e9 0 0 0 0", 18, "laser pose y in metres");
  ExpectLineError("FLASER 3 1 2 3 0 0 0 0 1e10 0", 24, "odometry pose y in metres");
  ExpectLineError("ODOM 1e300 0 0 0 0 0", 6, "odometry pose x in metres");
  ExpectLineError("TRUEPOS 0 1e300 0 0 0 0", 11, "true pose y in metres");
  ExpectLineError("TRUEPOS 0 0 0 -1e300 0 0", 15, "odometry pose x in metres");
  ExpectLineError("ROBOTLASER1 0 -1.5 3 0.01 80 0.01 0 3 1 2 3 0 1e300 0 0 0 0 0 0 0 0 0 0", 47,
                  "laser pose x in metres");
  ExpectLineError("ROBOTLASER1 0 -1.5 3 0.01 80 0.01 0 3 1 2 3 0 0 0 0 0 1e300 0 0 0 0 0 0", 55,
                  "robot pose y in metres");
}

TEST(CarmenMalformed, PositionsUpToTheWorldsBoundAndAnyThetaAreRead) {
  const Result<Log> log =
      ParseCarmenLog("FLASER 3 1 2 3 1e9 -1e9 1e300 -1e9 1e9 0\nODOM -1e9 1e9 0 0 0 0\n", kName);
  ASSERT_TRUE(log.ok()) << log.error();
  EXPECT_EQ(log.value().scans.at(0).pose.x(), 1e9);
  EXPECT_EQ(log.value().odometry.at(0).pose.y(), 1e9);
}

// A reading of 1e300 in a log without a max range was read as a return 1e300 m away, and only
// `priormap plot` refused the log, naming no line: it is reported at the reading, once the max
// range (detected from the whole log) says it is a return.
TEST(CarmenMalformed, AReturnLongerThanTheWorldsBoundIsReportedAtTheReading) {
  EXPECT_THAT(ParseErrors("FLASER 3 1 1e300 2 0 0 0 0 0 0\n"
                          "ROBOTLASER1 0 -1.5 3 0.01 1e301 0.01 0 3 1 1e300 -3 0 0 0 0 0 0 0 0 "
                          "0 0 0 0\n"),
              ElementsAre(DiagnosticAt(kName, 1, 12,
                                       "expected a range reading in metres, at most 1e+09 for a "
                                       "return or at or above the max range (inf m) for no "
                                       "return, got '1e300'"),
                          DiagnosticAt(kName, 2, 44,
                                       "at or above the max range (1e+301 m) for no return, got "
                                       "'1e300'")));
  // Just beyond the bound; the bound itself is a return.
  EXPECT_THAT(ParseErrors("FLASER 2 1000000000.5 1e9 0 0 0 0 0 0\n"),
              ElementsAre(DiagnosticAt(kName, 1, 10, "got '1000000000.5'")));
}

TEST(CarmenMalformed, LongReturnsStopAtMaxDiagnosticsLikeOtherErrors) {
  CarmenReadOptions options;
  options.max_diagnostics = 2;
  EXPECT_THAT(
      ParseErrors("FLASER 1 2e9 0 0 0 0 0 0\nFLASER 1 3e9 0 0 0 0 0 0\n"
                  "FLASER 1 4e9 0 0 0 0 0 0\n",
                  options),
      ElementsAre(DiagnosticAt(kName, 1, 10, "got '2e9'"), DiagnosticAt(kName, 2, 10, "got '3e9'"),
                  DiagnosticAt(kName, 2, 0, "too many errors; stopped reading")));
}

// A no-return says nothing of where a surface is: at or above the max range (the record's, or
// the caller's), any value is kept as read, as for a sensor's no-echo sentinel.
TEST(CarmenMalformed, ANoReturnReadingBeyondTheWorldsBoundIsKeptAsRead) {
  const Result<Log> own = ParseCarmenLog(
      "ROBOTLASER1 0 -1.5 3 0.01 80 0.01 0 3 1 1e300 3 0 0 0 0 0 0 0 0 0 0 0 0\n", kName);
  ASSERT_TRUE(own.ok()) << own.error();
  EXPECT_EQ(own.value().scans.at(0).ranges.at(1), 1e300);
  EXPECT_EQ(own.value().scans.at(0).status.at(1), BeamStatus::kMaxRange);
  CarmenReadOptions options;
  options.max_range = 80.0;
  const Result<Log> given = ParseCarmenLog("FLASER 3 1 1e300 2 0 0 0 0 0 0\n", kName, options);
  ASSERT_TRUE(given.ok()) << given.error();
  EXPECT_EQ(given.value().scans.at(0).ranges.at(1), 1e300);
  EXPECT_EQ(given.value().scans.at(0).status.at(1), BeamStatus::kMaxRange);
  // Readings that are not measurements are no returns either.
  EXPECT_TRUE(ParseCarmenLog("FLASER 2 -1e300 inf 0 0 0 0 0 0\n", kName).ok());
}

TEST(CarmenMalformed, OdometryWithTooFewFieldsEndsEarly) {
  // The column is one past the end of the line: where the missing field should be.
  ExpectLineError("ODOM 1 2 3 0 0", 15, "ODOM record ends early: expected accel");
}

TEST(CarmenMalformed, OdometryWithNonNumericFieldNamesTheField) {
  ExpectLineError("ODOM 1 2 x 0 0 0", 10, "expected odometry pose theta (a number), got 'x'");
}

TEST(CarmenMalformed, TruncatedTruePoseEndsEarly) {
  ExpectLineError("TRUEPOS 1 2 3 4 5", 18,
                  "TRUEPOS record ends early: expected odometry pose theta");
}

TEST(CarmenMalformed, TruncatedRobotLaserIsReportedAtTheCount) {
  ExpectLineError("ROBOTLASER1 0 -1.5 3 0.01 80 0.01 0 3 1 2", 37,
                  "the number of readings is 3, but only 2 fields follow it (expected 3 values, "
                  "then the remission count, 6 pose values and 5 safety values)");
}

TEST(CarmenMalformed, NonIntegerLaserTypeIsRejected) {
  ExpectLineError("ROBOTLASER1 1.5 -1.5 3 0.01 80 0.01 0 3 1 2 3 0 0 0 0 0 0 0 0 0 0 0 0", 13,
                  "expected laser_type (an integer), got '1.5'");
}

TEST(CarmenMalformed, NonNumericRemissionCountIsRejected) {
  ExpectLineError("ROBOTLASER1 0 -1.5 3 0.01 80 0.01 0 3 1 2 3 x 0 0 0 0 0 0 0 0 0 0 0", 45,
                  "expected the number of remissions (a non-negative integer), got 'x'");
}

TEST(CarmenMalformed, NegativeRemissionCountIsRejected) {
  ExpectLineError("ROBOTLASER1 0 -1.5 3 0.01 80 0.01 0 3 1 2 3 -2 0 0 0 0 0 0 0 0 0 0 0", 45,
                  "expected the number of remissions (a non-negative integer), got '-2'");
}

TEST(CarmenMalformed, RemissionCountLargerThanTheFieldsOnTheLineIsRejected) {
  ExpectLineError("ROBOTLASER1 0 -1.5 3 0.01 80 0.01 0 3 1 2 3 5 0 0 0 0 0 0 0 0 0 0 0", 45,
                  "the number of remissions is 5, but only 11 fields follow it (expected 5 values, "
                  "then 6 pose values and 5 safety values)");
}

TEST(CarmenMalformed, ZeroAngularResolutionIsRejected) {
  ExpectLineError("ROBOTLASER1 0 -1.5 3 0 80 0.01 0 3 1 2 3 0 0 0 0 0 0 0 0 0 0 0 0", 22,
                  "angular_resolution must be positive, got 0");
}

TEST(CarmenMalformed, NegativeAngularResolutionIsRejected) {
  ExpectLineError("ROBOTLASER1 0 -1.5 3 -0.01 80 0.01 0 3 1 2 3 0 0 0 0 0 0 0 0 0 0 0 0", 22,
                  "angular_resolution must be positive, got -0.01");
}

TEST(CarmenMalformed, AngularResolutionThatGivesNoIncreasingAnglesIsRejected) {
  // Next to 1e308, 0.01 is below the spacing of doubles: every beam would get the same angle.
  ExpectLineError("ROBOTLASER1 0 1e308 3 0.01 80 0.01 0 3 1 2 3 0 0 0 0 0 0 0 0 0 0 0 0", 23,
                  "start_angle 1e+308 and angular_resolution 0.01 do not give 3 increasing, "
                  "finite beam angles");
  ExpectLineError("ROBOTLASER1 0 1 3 1e308 80 0.01 0 3 1 2 3 0 0 0 0 0 0 0 0 0 0 0 0", 19,
                  "start_angle 1 and angular_resolution 1e+308 do not give 3 increasing, finite "
                  "beam angles");
}

TEST(CarmenMalformed, ExtraTrailingFieldIsReportedAtTheField) {
  ExpectLineError("ODOM 1 2 3 0 0 0 1.0 host 2.0 junk", 31,
                  "unexpected extra field 'junk' at the end of the ODOM record");
  ExpectLineError(kRobotLaser + " 1.0 host 2.0 junk", 82,
                  "unexpected extra field 'junk' at the end of the ROBOTLASER1 record");
}

TEST(CarmenMalformed, ExtraTrailingFieldOfFlaserContradictsTheCount) {
  // FLASER lines have no other way to tell readings from the rest, so the count is blamed.
  ExpectLineError("FLASER 3 1 2 3 0 0 0 0 0 0 extra", 8,
                  "the number of readings is 3, but 10 fields follow it");
  ExpectLineError("FLASER 3 1 2 3 0 0 0 0 0 0 1.0 host 2.0 extra", 8,
                  "the number of readings is 3, but 13 fields follow it");
}

TEST(CarmenMalformed, OneTimestampFieldInsteadOfThreeEndsEarly) {
  ExpectLineError("ODOM 1 2 3 0 0 0 1.0", 21, "ODOM record ends early: expected host");
  ExpectLineError("FLASER 3 1 2 3 0 0 0 0 0 0 1.0", 8,
                  "the number of readings is 3, but 10 fields follow it");
}

TEST(CarmenMalformed, TwoTimestampFieldsInsteadOfThreeEndsEarly) {
  ExpectLineError("TRUEPOS 1 2 3 4 5 6 1.0 host", 29,
                  "TRUEPOS record ends early: expected logger_timestamp");
  ExpectLineError(kRobotLaser + " 1.0 host", 77,
                  "ROBOTLASER1 record ends early: expected logger_timestamp");
  ExpectLineError("RLASER 3 1 2 3 0 0 0 0 0 0 1.0 host", 8,
                  "the number of readings is 3, but 11 fields follow it");
}

TEST(CarmenMalformed, NonNumericTimestampIsRejected) {
  ExpectLineError("ODOM 1 2 3 0 0 0 abc host 2.0", 18,
                  "expected ipc_timestamp (a number), got 'abc'");
  ExpectLineError("ODOM 1 2 3 0 0 0 1.0 host nan", 27, "logger_timestamp must be finite");
}

TEST(CarmenMalformed, LineNumbersCountBlankAndCommentLines) {
  const std::string text =
      "# a comment\n"
      "\n"
      "ODOM 1 2 3 0 0 0\n"
      "ODOM 1 2 3 0 zero 0\n";
  EXPECT_THAT(ParseErrors(text),
              ElementsAre(DiagnosticAt(kName, 4, 14, "expected rv (a number), got 'zero'")));
}

TEST(CarmenMalformed, EveryBadLineIsReported) {
  const std::string text =
      "ODOM 1 2 3 0 0 0\n"
      "ODOM 1 2 x 0 0 0\n"
      "FLASER 3 1 2 3 0 0 0 0 0 0\n"
      "TRUEPOS 1 2\n";
  EXPECT_THAT(ParseErrors(text),
              ElementsAre(DiagnosticAt(kName, 2, 10, "expected odometry pose theta"),
                          DiagnosticAt(kName, 4, 12, "TRUEPOS record ends early")));
}

TEST(CarmenMalformed, TextWithoutRecordsIsRejected) {
  const std::string no_records = "no CARMEN records found";
  EXPECT_THAT(ParseErrors(R"({"format": "priormap.log", "version": 1, "records": []})"),
              ElementsAre(DiagnosticAt(kName, 0, 0, no_records)));
  EXPECT_THAT(ParseErrors(""), ElementsAre(DiagnosticAt(kName, 0, 0, no_records)));
  EXPECT_THAT(ParseErrors("# only a comment\n\n"),
              ElementsAre(DiagnosticAt(kName, 0, 0, no_records)));
}

TEST(CarmenMalformed, BinaryGarbageWithNulBytesIsRejected) {
  std::string garbage(
      "\x7f"
      "ELF\x02\x01\x01\0\0\0\0\0\0\0\0\0\x03\0>\0\x01\0\0\0",
      24);
  for (int i = 0; i < 200; ++i) garbage += static_cast<char>((i * 37 + 11) % 256);
  EXPECT_THAT(ParseErrors(garbage),
              ElementsAre(DiagnosticAt(kName, 0, 0, "no CARMEN records found")));
}

TEST(CarmenMalformed, OnlyUnknownRecordsAreRejectedButCounted) {
  CarmenReadStats stats;
  const Result<Log> result = ParseCarmenLog("NEFF 1 2 3\nSONAR 4\nNEFF 5\n", kName, {}, &stats);
  EXPECT_THAT(result.diagnostics(),
              ElementsAre(DiagnosticAt(kName, 0, 0, "no CARMEN records found")));
  EXPECT_EQ(stats.records["NEFF"], 2);
  EXPECT_EQ(stats.records["SONAR"], 1);
}

TEST(CarmenMalformed, MissingFileIsReported) {
  const testing::TempDir dir;
  const std::filesystem::path path = dir / "missing.log";
  const Result<Log> result = ReadCarmenLog(path);
  EXPECT_THAT(result.diagnostics(), ElementsAre(DiagnosticAt(path.string(), 0, 0, "no such file")));
}

TEST(CarmenMalformed, DirectoryInsteadOfFileIsReported) {
  const testing::TempDir dir;
  const Result<Log> result = ReadCarmenLog(dir.path());
  EXPECT_THAT(result.diagnostics(), ElementsAre(DiagnosticAt(dir.path().string(), 0, 0,
                                                             "is a directory, expected a file")));
}

std::string SomeLogText() {
  std::string text;
  for (int i = 0; i < 2000; ++i) {
    text += "FLASER 3 1.25 2.5 " + std::to_string(i) + " 0 0 0 0 0 0 " + std::to_string(i) +
            ".5 host 1.5\n";
  }
  return text;
}

TEST(CarmenMalformed, TruncatedGzipIsReported) {
  const testing::TempDir dir;
  const std::filesystem::path path = dir / "log.gz";
  WriteTextFileAtomically(path, SomeLogText());
  const std::string compressed = testing::ReadAll(path);
  ASSERT_GT(compressed.size(), 100U);
  testing::WriteAll(path, compressed.substr(0, compressed.size() / 2));
  EXPECT_THAT(ReadCarmenLog(path).diagnostics(),
              ElementsAre(DiagnosticAt(path.string(), 0, 0, "corrupt or truncated gzip data")));
}

TEST(CarmenMalformed, CorruptGzipIsReported) {
  const testing::TempDir dir;
  const std::filesystem::path path = dir / "log.gz";
  WriteTextFileAtomically(path, SomeLogText());
  std::string compressed = testing::ReadAll(path);
  for (std::size_t i = 20; i + 20 < compressed.size(); i += 7) compressed[i] = '\x55';
  testing::WriteAll(path, compressed);
  EXPECT_THAT(ReadCarmenLog(path).diagnostics(),
              ElementsAre(DiagnosticAt(path.string(), 0, 0, "corrupt or truncated gzip data")));
}

std::string BadLines(int n) {
  std::string text;
  for (int i = 0; i < n; ++i) text += "ODOM 1 2 x 0 0 0\n";
  return text;
}

TEST(CarmenMalformed, StopsWithTooManyErrorsAfterMaxDiagnostics) {
  CarmenReadOptions options;
  options.max_diagnostics = 3;
  EXPECT_THAT(ParseErrors(BadLines(10), options),
              ElementsAre(DiagnosticAt(kName, 1, 10, "expected odometry pose theta"),
                          DiagnosticAt(kName, 2, 10, "expected odometry pose theta"),
                          DiagnosticAt(kName, 3, 10, "expected odometry pose theta"),
                          DiagnosticAt(kName, 3, 0, "too many errors; stopped reading")));
}

TEST(CarmenMalformed, DefaultLimitIsTwentyDiagnostics) {
  const std::vector<Diagnostic> diagnostics = ParseErrors(BadLines(30));
  ASSERT_THAT(diagnostics, SizeIs(21));
  EXPECT_THAT(diagnostics.back(), DiagnosticAt(kName, 20, 0, "too many errors; stopped reading"));
}

TEST(CarmenMalformed, NonPositiveMaxDiagnosticsStillReadsAndReportsTheFirstError) {
  CarmenReadOptions options;
  options.max_diagnostics = 0;
  EXPECT_TRUE(ParseCarmenLog("ODOM 1 2 3 0 0 0\n", kName, options).ok());
  EXPECT_THAT(ParseErrors(BadLines(3), options),
              ElementsAre(DiagnosticAt(kName, 1, 10, "expected odometry pose theta"),
                          DiagnosticAt(kName, 1, 0, "too many errors; stopped reading")));
}

const std::string kEveryRecordType =
    "# comment\n"
    "PARAM robot_front_laser_max 81.9\n"
    "PARAM robot_name a robot with spaces\n"
    "FLASER 3 1.5 nan 2.5 1 2 0.5 1.1 2.1 0.6 12.5 host 12.75\n"
    "RLASER 2 4 5 1 2 0.5 1.1 2.1 0.6\n"
    "ODOM 1 2 3 0.1 0.2 0.3 13 host 13.5\n"
    "TRUEPOS 1 2 3 4 5 6 14 host 14.5\n" +
    kRobotLaser + "\n";

std::string WithCrlf(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '\n') out += '\r';
    out += c;
  }
  return out;
}

TEST(CarmenMalformed, CrlfLineEndingsParseLikeLf) {
  const Result<Log> lf = ParseCarmenLog(kEveryRecordType, kName);
  const Result<Log> crlf = ParseCarmenLog(WithCrlf(kEveryRecordType), kName);
  ASSERT_TRUE(lf.ok()) << lf.error();
  ASSERT_TRUE(crlf.ok()) << crlf.error();
  EXPECT_EQ(FormatJsonLog(crlf.value()), FormatJsonLog(lf.value()));
  ASSERT_EQ(crlf.value().params.size(), 2U);
  EXPECT_EQ(crlf.value().params[1].second, "a robot with spaces");
}

TEST(CarmenMalformed, CrlfDoesNotShiftTheColumnOfAMissingField) {
  EXPECT_THAT(ParseErrors("ODOM 1 2 3 0 0\r\n"),
              ElementsAre(DiagnosticAt(kName, 1, 15, "ODOM record ends early: expected accel")));
}

// ---- no input crashes the reader ----

// What holds for any input: a result, either a consistent log or diagnostics that point into
// the text.
void CheckParseIsWellBehaved(const std::string& text) {
  const Result<Log> result = ParseCarmenLog(text, kName);
  if (result.ok()) {
    RC_ASSERT(result.value().NumRecords() > 0U);
    const std::vector<std::string> problems = result.value().Problems();
    RC_ASSERT(problems.empty());
    return;
  }
  const std::vector<std::string> lines = Lines(text);
  RC_ASSERT(!result.diagnostics().empty());
  for (const Diagnostic& d : result.diagnostics()) {
    RC_ASSERT(d.file == kName);
    RC_ASSERT(!d.message.empty());
    RC_ASSERT(d.line >= 0);
    RC_ASSERT(d.line <= static_cast<int>(lines.size()));
    if (d.line > 0 && d.col > 0) {
      std::string line = lines[static_cast<std::size_t>(d.line - 1)];
      if (!line.empty() && line.back() == '\r') line.pop_back();
      RC_ASSERT(d.col <= static_cast<int>(line.size()) + 1);
    }
  }
}

RC_GTEST_PROP(CarmenMalformed, ArbitraryTextNeverCrashes, (const std::string& text)) {
  CheckParseIsWellBehaved(text);
}

// A valid log with one line changed: fields deleted, duplicated or replaced by troublesome
// values. (One line only, so that the result often still parses and the log is checked too.)
RC_GTEST_PROP(CarmenMalformed, MutatedRecordsNeverCrash, ()) {
  std::vector<std::string> lines = Lines(kEveryRecordType);
  const std::vector<std::string> replacements = {
      "nan", "inf", "-inf",  "-1",     "0",  "x", "3.x4", "1e999", "1e-400", "99999999999999999999",
      "+",   "-",   "1e308", "1e-300", "-0", "4", "180",  "#",     "FLASER", "\t",
      "0x10"};
  std::string& line = lines[*rc::gen::inRange<std::size_t>(0, lines.size())];
  std::vector<std::string> fields;
  std::size_t start = 0;
  while (start < line.size()) {
    std::size_t end = line.find(' ', start);
    if (end == std::string::npos) end = line.size();
    fields.push_back(line.substr(start, end - start));
    start = end + 1;
  }
  const int edits = *rc::gen::inRange(1, 3);
  for (int e = 0; e < edits && !fields.empty(); ++e) {
    const std::size_t at = *rc::gen::inRange<std::size_t>(0, fields.size());
    switch (*rc::gen::inRange(0, 3)) {
      case 0:
        fields.erase(fields.begin() + static_cast<std::ptrdiff_t>(at));
        break;
      case 1:
        fields.insert(fields.begin() + static_cast<std::ptrdiff_t>(at), fields[at]);
        break;
      default:
        fields[at] = *rc::gen::elementOf(replacements);
        break;
    }
  }
  line.clear();
  for (const std::string& f : fields) line += (line.empty() ? "" : " ") + f;
  std::string text;
  for (const std::string& l : lines) text += l + "\n";
  CheckParseIsWellBehaved(text);
}

}  // namespace
}  // namespace priormap
