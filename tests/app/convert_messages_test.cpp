// End-to-end tests of what `priormap convert` says about unusual logs and arguments: the option
// and the limit behind a refused --min-range, an output that names the input, and text that the
// output format cannot hold. Each failure exits 1 (bad input, or an option checked against it)
// and writes nothing.
#include <algorithm>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "cli_fixture.hpp"
#include "testing/temp_dir.hpp"

namespace priormap {
namespace {

namespace fs = std::filesystem;
using priormap::testing::ReadAll;
using priormap::testing::WriteAll;
using ::testing::HasSubstr;

using RunResult = priormap::testing::ProcessResult;

class ConvertMessages : public priormap::testing::CliFixture {
 protected:
  // Fails with exit status 1, its message on stderr, writing nothing: the output that -o names
  // is absent after the run, or, when it was there before (the input itself), as it was.
  RunResult FailsWithBadInput(const std::vector<std::string>& args) const {
    // What follows -o (every call names an output; `at` throws when none does).
    const auto o =
        static_cast<std::size_t>(std::find(args.begin(), args.end(), "-o") - args.begin());
    const fs::path output = Work(args.at(o + 1));
    const std::optional<std::string> before =
        fs::exists(output) ? std::optional(ReadAll(output)) : std::nullopt;
    RunResult r = RunFailing(args);
    EXPECT_EQ(r.status, 1) << "stderr:\n" << r.err;
    if (before)
      EXPECT_EQ(ReadAll(output), *before) << output;
    else
      EXPECT_FALSE(fs::exists(fs::symlink_status(output))) << output << " was written";
    return r;
  }
};

// "the minimum range 500 m is not below the max range 49.5 m of scan 0 (its record's, the
// detected or the given one)" named neither the option nor which max range applied.
TEST_F(ConvertMessages, AMinRangeBeyondTheMaxRangeNamesTheOptionAndWhereTheMaxRangeComesFrom) {
  // 12 readings at 50 m: the detected max range is 49.5 m.
  std::string flaser = "ODOM 0 0 0 0 0 0\n";
  for (int k = 0; k < 3; ++k) flaser += "FLASER 5 1 50 50 50 50 0 0 0 0 0 0\n";
  WriteAll(Work("flaser.log"), flaser);
  EXPECT_THAT(
      FailsWithBadInput({"convert", "flaser.log", "-o", "out.json", "--min-range", "60"}).err,
      HasSubstr("priormap: error: flaser.log:2: --min-range 60 m is not below the max "
                "range of scan 0, 49.5 m, detected from the no-return readings of the "
                "FLASER and RLASER lines: no reading could be valid\n"));
  EXPECT_THAT(FailsWithBadInput({"convert", "flaser.log", "-o", "out.json", "--min-range", "60",
                                 "--max-range", "70"})
                  .err,
              HasSubstr("49.5 m, detected from the no-return readings of the FLASER and RLASER "
                        "lines (--max-range 70 m is longer, and can only shorten it)"));
  WriteAll(Work("robot.log"),
           "PARAM robot_name r\n"
           "ROBOTLASER1 0 -1.5 3 0.01 8 0.01 0 3 1 2 9 0 0 0 0 0 0 0 0 0 0 0 0\n");
  EXPECT_THAT(FailsWithBadInput({"convert", "robot.log", "-o", "out.json", "--min-range", "8"}).err,
              HasSubstr("priormap: error: robot.log:2: --min-range 8 m is not below the max range "
                        "of scan 0, 8 m, its ROBOTLASER1 record's maximum_range: no reading "
                        "could be valid\n"));
}

// `convert a.log -o a.log` replaced the log by its conversion: with --to json, or a lossy
// output, the original was gone.
TEST_F(ConvertMessages, AnOutputThatNamesTheInputIsRefusedAndTheInputKept) {
  const std::string log = "FLASER 3 1 2 3 0 0 0 0 0 0 1.5 host 1.5\n";
  WriteAll(Work("in.log"), log);
  fs::create_symlink("in.log", Work("link.log"));
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"convert", "in.log", "-o", "in.log"},
        {"convert", "in.log", "-o", "./in.log", "--to", "json"},
        {"convert", "link.log", "-o", "in.log"},
        {"convert", "in.log", "-o", "link.log"}}) {
    EXPECT_THAT(FailsWithBadInput(args).err, HasSubstr("one would overwrite the other"))
        << args[1] << " -o " << args[3];
    EXPECT_EQ(ReadAll(Work("in.log")), log);
  }
}

// A Latin-1 PARAM value became U+FFFD in the JSON written, without a word; CARMEN keeps the bytes.
TEST_F(ConvertMessages, TextThatIsNotUtf8IsRefusedForJsonAtItsByteAndKeptForCarmen) {
  const std::string log =
      "PARAM robot_place M\xfcnchen\n"
      "FLASER 3 1 2 3 0 0 0 0 0 0 1.5 host 1.5\n";
  WriteAll(Work("latin1.log"), log);
  EXPECT_THAT(FailsWithBadInput({"convert", "latin1.log", "-o", "out.json"}).err,
              HasSubstr("priormap: error: latin1.log:1:20: expected UTF-8 text in a PARAM value, "
                        "got byte '\\xfc': JSON holds only UTF-8; re-encode the log"));
  WriteAll(Work("host.log"), "FLASER 3 1 2 3 0 0 0 0 0 0 1.5 h\xf6st 1.5\n");
  EXPECT_THAT(FailsWithBadInput({"convert", "host.log", "-o", "out.json.gz"}).err,
              HasSubstr("priormap: error: host.log:1:33: expected UTF-8 text in a host name"));
  const RunResult carmen = Run({"convert", "latin1.log", "-o", "out.log"});
  EXPECT_EQ(carmen.status, 0) << carmen.err;
  EXPECT_THAT(ReadAll(Work("out.log")), HasSubstr("PARAM robot_place M\xfcnchen\n"));
}

}  // namespace
}  // namespace priormap
