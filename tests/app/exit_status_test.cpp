// The exit statuses README promises for a refused command line: 2 where an option's value is
// refused on its own (by CLI11's checks or the command's own) or a required option is missing, 1
// where a value is refused against the input or the other options.
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "cli_fixture.hpp"

namespace priormap {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

struct Refusal {
  std::vector<std::string> args;
  std::string error;  // a line of stderr, after "priormap: error: "
};

class ExitStatus : public testing::CliFixture {
 protected:
  void ExpectRefused(const std::vector<Refusal>& refusals, int status) const {
    for (const Refusal& refusal : refusals) {
      const std::string line = fmt::format("{}", fmt::join(refusal.args, " "));
      const testing::ProcessResult r = RunFailing(refusal.args);
      EXPECT_EQ(r.status, status) << line << "\n" << r.err;
      EXPECT_THAT(r.err, HasSubstr("priormap: error: " + refusal.error)) << line;
    }
  }
};

// A value its option's own check refuses, whichever command reads it, and before any input is
// read (the input files named here do not exist).
TEST_F(ExitStatus, AValueRefusedOnItsOwnExitsWithTwo) {
  ExpectRefused(
      {
          {{"simulate", "--sensor", "kinect", "-o", "s.json"},
           "--sensor: unknown sensor 'kinect' (expected a laser: utm30, lms200; or a sonar ring: "
           "pioneer8, pioneer16, robond)"},
          {{"simulate", "--correlation", "1", "-o", "s.json"},
           "--correlation: 1 is not in [0, 1), 1 excluded"},
          {{"simulate", "--outliers", "1.5", "-o", "s.json"},
           "--outliers: 1.5 is not a probability (expected a number in [0, 1])"},
          {{"simulate", "--dropout=-0.1", "-o", "s.json"},
           "--dropout: -0.1 is not a probability (expected a number in [0, 1])"},
          {{"simulate", "--sigma", "1e101", "-o", "s.json"},
           "--sigma: sigma must be in [1e-100, 1e100] m (got 1e+101)"},
          {{"simulate", "--min-range=-1", "-o", "s.json"},
           "--min-range: -1 is negative (expected a number >= 0)"},
          {{"simulate", "--pose", "1,2", "-o", "s.json"},
           "--pose: expected x,y,theta (three numbers), got '1,2'"},
          {{"simulate", "-o", "s.json", "--png", "s.bmp"},
           "--png: 's.bmp' must end in .png, .svg or .pdf"},
          {{"plot", "missing.json", "-o", "p.gif"},
           "--out: 'p.gif' must end in .png, .svg or .pdf"},
          {{"scan", "--prior", "rectangular", "-i", "missing.json", "-o", "m.json", "--png",
            "f.svg"},
           "--png: 'f.svg' must end in .png"},
          {{"prior", "eval", "rectangular", "--block", "corner", "--at", "rho_1=1"},
           "--block: expected same_region, different_region or different_surface, got 'corner'"},
          {{"prior", "eval", "no-such-prior", "--at", "rho_1=1,rho_1=2"},
           "--at: rho_1 is given twice"},
          {{"prf", "--log", "missing.json", "-o", "run", "--range", "5:2"},
           "--range: '5:2' is empty (a must be below b)"},
          {{"prf", "--log", "missing.json", "-o", "run", "--thinned-burn-in", "0:100"},
           "--thinned-burn-in: expected STRIDE:STEPS with a stride of at least 1"},
          {{"prf", "--log", "missing.json", "-o", "run", "--warm-burn-in", "0.5:100"},
           "--warm-burn-in: expected T:STEPS with a temperature from 1 to 1000"},
          {{"prf", "--log", "missing.json", "-o", "run", "--orientation", "1e308"},
           "--orientation: 1e308 degrees is not a finite angle in radians"},
          {{"prf", "--log", "missing.json", "-o", "run", "--samples", "0"},
           "--samples 0: P(black), R-hat and the annealing's start come from the samples"},
          {{"prf", "prior-stats", "--moves", "triangle,teleport"},
           "--moves: unknown move kind 'teleport' (expected: triangle, "},
          {{"prf", "prior-stats", "--distances", "0.5,0"},
           "--distances: 0 is not positive (expected a number > 0)"},
          {{"prf", "study", "--sensors", "utm30,sonar9", "-o", "study"},
           "--sensors: unknown sensor 'sonar9' (expected one of: utm30, lms200)"},
          {{"prf", "study", "--samples", "0", "-o", "study"},
           "--samples: expected at least one sample per chain (P(black) is their mean), got 0"},
          {{"prf", "study", "--resolution", "2", "-o", "study"},
           "--resolution: expected at least 0.005 m (finer, the scenes' rasters would not fit) "
           "and at most 1 m (coarser, a room is a cell or two), got 2"},
          {{"prf", "study", "--sensors", "utm30,lms200,utm30", "-o", "study"},
           "--sensors: sensor 'utm30' is given twice (each case runs once)"},
          {{"prf", "sonar-study", "--scenes", "office,office", "-o", "study"},
           "--scenes: scene 'office' is given twice (each case runs once)"},
          {{"prf", "sonar-study", "--samples", "0", "-o", "study"},
           "--samples: expected at least one sample per chain (P(black) is their mean), got 0"},
          {{"prf", "sonar-study", "--sensor", "utm30", "-o", "study"},
           "--sensor: unknown sonar 'utm30' (expected one of: pioneer8, pioneer16, robond)"},
          {{"prf", "fit-sonar", "--sensor", "utm30", "-o", "m.json"},
           "--sensor: unknown sonar 'utm30' (expected one of: pioneer8, pioneer16, robond)"},
          {{"prf", "fit-sonar", "--scenes", "office,l-office,office", "-o", "m.json"},
           "--scenes: 'office' is given twice (each scene is fitted once)"},
          {{"grid", "--log", "missing.json", "-o", "grid", "--range", "3"},
           "--range: '3' is not a:b with scan indices a < b"},
          {{"slam", "run", "--observations", "o.csv", "--odometry", "d.csv", "--no-prior", "-o",
            "run", "--initial-pose", "1,2"},
           "--initial-pose: expected x,y,theta (three numbers, m, m, rad), got '1,2'"},
          {{"slam", "run", "--observations", "o.csv", "--odometry", "d.csv", "--no-prior", "-o",
            "run", "--increment-std", "0.1,-0.1,0.01"},
           "--increment-std: expected sx,sy,stheta (three numbers >= 0: m, m, rad), got "
           "'0.1,-0.1,0.01'"},
          {{"demo", "--quick", "--data", "no-such-dir", "--out", ""},
           "-o/--out: an empty directory name"},
      },
      2);
}

// An option that a command requires, unless another option stands in for it, missing or empty:
// a missing required option, as CLI11 reports for those it knows to be required.
TEST_F(ExitStatus, AMissingRequiredOptionExitsWithTwo) {
  ExpectRefused(
      {
          {{"simulate", "--scene", "square"},
           "--out is required (or --write-scene alone to export the scene)"},
          {{"prf", "-o", "run"}, "--log is required (or a subcommand: prior-stats, study"},
          {{"prf", "--log", "missing.json"}, "-o/--out is required"},
          {{"prf", "study", "-o", ""}, "-o/--out is required"},
          {{"prf", "sonar-study", "-o", ""}, "-o/--out is required"},
          {{"prf", "fit-sonar", "-o", ""}, "-o/--out is required"},
          {{"slam", "run", "--observations", "o.csv", "--odometry", "d.csv", "-o", "run"},
           "--prior-map is required (or --no-prior to filter without a prior map)"},
      },
      2);
}

// An option no command knows, or a stray argument, is reported before a required option missing
// or a value refused: the typo is likely the cause of those (--ouput for --out). Every command.
TEST_F(ExitStatus, AnUnknownOptionIsReportedFirstAndExitsWithTwo) {
  ExpectRefused(
      {
          {{"scan", "--bogus"}, "The following argument was not expected: --bogus"},
          {{"scan", "--prior", "polygonal", "-i", "missing.json", "--ouput", "m.json"},
           "The following arguments were not expected: --ouput m.json"},
          {{"simulate", "--sensor", "kinect", "--bogus", "-o", "s.json"},
           "The following argument was not expected: --bogus"},
          {{"convert", "in.log", "--bogus"}, "The following argument was not expected: --bogus"},
          {{"plot", "--bogus"}, "The following argument was not expected: --bogus"},
          {{"prior", "eval", "--bogus"}, "The following argument was not expected: --bogus"},
          {{"prf", "--bogus"}, "The following argument was not expected: --bogus"},
          {{"prf", "study", "--bogus"}, "The following argument was not expected: --bogus"},
          {{"prf", "fit-sonar", "--bogus"}, "The following argument was not expected: --bogus"},
          {{"grid", "--bogus"}, "The following argument was not expected: --bogus"},
          {{"slam", "run", "--bogus"}, "The following argument was not expected: --bogus"},
      },
      2);
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"scan", "--bogus"}, {"prf", "study", "--bogus"}}) {
    const testing::ProcessResult r = RunFailing(args);
    EXPECT_THAT(r.err, Not(HasSubstr("required"))) << r.err;
  }
}

// Values that are fine on their own, refused with the other options or against the input.
TEST_F(ExitStatus, AValueRefusedWithTheOtherOptionsOrTheInputExitsWithOne) {
  testing::WriteAll(Work("box.json"), R"({"format": "priormap.scene", "version": 1,
    "name": "box", "surfaces": [{"type": "polyline",
    "points": [[-3, -3], [3, -3], [3, 3], [-3, 3]], "closed": true}],
    "waypoints": [[-1, 0], [1, 0]]})");
  ExpectRefused(
      {
          {{"simulate", "--min-range", "5", "--max-range", "2", "-o", "s.json"},
           "sensor: need 0 <= min_range < max_range < inf (got 5 and 2)"},
          {{"simulate", "--log", "--pose", "0,0,0", "-o", "s.json"},
           "--pose places a single scan; --log follows the scene's waypoints"},
          {{"simulate", "--write-scene", "scene.json", "--png", "s.png"},
           "--png draws the simulated scan or log: give --out too"},
          {{"scan", "--prior", "rectangular", "-i", "missing.json", "-o", "m.json", "--all",
            "--png", "f.png"},
           "--png draws one scan, not --all (choose it with --index)"},
          {{"prior", "eval", "rectangular", "--at", "rho_1=1"}, "--at: missing a value for "},
          {{"prf", "prior-stats", "--window", "2", "--distances", "3"},
           "--distances: 3 is not inside (0, window = 2)"},
          {{"prf", "--log", "missing.json", "-o", "run", "--corner-completion", "0.6",
            "--neighbour-births", "0.5"},
           "--corner-completion 0.6 and --neighbour-births 0.5 sum to 1 or more"},
          {{"prf", "fit-sonar", "--scenes", "box.json,./box.json", "-o", "m.json"},
           "--scenes: 'box.json' and './box.json' are both scene 'box'"},
          {{"prf", "fit-sonar", "--log", "missing.json", "--scene", "office", "--scenes", "office",
            "--rate", "3", "-o", "m.json"},
           "--scenes and --rate are for simulated rings to fit; with --log the readings are the "
           "log's: give one or the other"},
          {{"prf", "fit-sonar", "--log", "missing.json", "--scene", "office", "--seed", "3", "-o",
            "m.json"},
           "--seed is for simulated rings to fit; with --log the readings are the log's: give one "
           "or the other"},
          {{"prf", "fit-sonar", "--log", "missing.json", "--scene", "office", "--scenes", "office",
            "--rate", "3", "--seed", "3", "-o", "m.json"},
           "--scenes, --rate and --seed are for simulated rings to fit; "},
          {{"prf", "fit-sonar", "--scene", "office", "-o", "m.json"},
           "--scene is the map of --log: without --log, the rings are simulated in --scenes"},
          {{"prf", "study", "--scenes", "box.json,./box.json", "-o", "study"},
           "scene 'box' is given twice (each case runs once)"},
          // A scene that is neither built in nor a file, named by its option as a sensor is.
          {{"prf", "study", "--scenes", "l-room,nowhere", "-o", "study"},
           "--scenes: unknown scene 'nowhere' (expected one of: square, rectangle, "},
          {{"prf", "sonar-study", "--scenes", "nowhere", "-o", "study"},
           "--scenes: unknown scene 'nowhere' (expected one of: "},
          {{"prf", "fit-sonar", "--scenes", "nowhere", "-o", "m.json"},
           "--scenes: unknown scene 'nowhere' (expected one of: "},
          {{"simulate", "--scene", "nowhere", "-o", "s.json"},
           "--scene: unknown scene 'nowhere' (expected one of: "},
          {{"convert", "--from", "roboND-sonar", "m.txt", "p.txt", "--max-range", "6", "-o",
            "x.json"},
           "--max-range 6 m: with --from roboND-sonar it can be at most 5.11 m"},
      },
      1);
}

}  // namespace
}  // namespace priormap
