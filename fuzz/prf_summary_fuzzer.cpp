// libFuzzer harness for the summary.json of a `priormap prf` run as `priormap prf rhat` reads it
// (cmd_prf_rhat.cpp: the data's fingerprint or size, the window, the sensor, the trace points),
// run as the command runs: `prf rhat A B` on two run directories whose other files (run.json,
// trace.csv, point_traces.csv: two chains each, seeds 1 and 3, three trace points of which the
// chains disagree on the first) are fixed and valid. The input is A's summary.json and, after
// its first NUL byte, B's (A's again when there is none). Besides crashes and sanitizer reports
// it checks that the command either fails with a UserError that names a run (what main prints)
// and no other exception, or prints one JSON document of the four chains' R̂.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <string>
#include <string_view>
#include <tuple>
#include <unistd.h>  // ftruncate

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "cli_support.hpp"
#include "commands.hpp"
#include "fuzz_check.hpp"
#include "fuzz_scratch.hpp"
#include "prf_run_file.hpp"

using priormap::fuzz::Check;
namespace fs = std::filesystem;

namespace {

constexpr std::string_view kTraceA =
    "sample,chain0,chain1\n"
    "500,329.2100480213476,188.2425182341485\n"
    "1000,444.31830892457856,328.7918945609457\n"
    "1500,516.0492141231676,420.80628187026764\n"
    "2000,553.9302064803627,482.39897222146504\n"
    "2500,580.7617811283463,534.9535248223602\n"
    "3000,603.2951508847809,545.890734343435\n";
constexpr std::string_view kTraceB =
    "sample,chain0,chain1\n"
    "500,301.5,250.25\n"
    "1000,410.125,380.5\n"
    "1500,500.0625,470\n"
    "2000,560.5,520.75\n"
    "2500,590.25,560.5\n"
    "3000,600.5,598.125\n";
// Point 0 black in chain 0 and white in chain 1 (R̂ +inf), point 1 mixed, point 2 white.
constexpr std::string_view kPointTraces =
    "sample,chain0_point0,chain0_point1,chain0_point2,chain1_point0,chain1_point1,chain1_point2\n"
    "500,1,0,0,0,1,0\n"
    "1000,1,1,0,0,0,0\n"
    "1500,1,0,0,0,1,0\n"
    "2000,1,1,0,0,0,0\n"
    "2500,1,0,0,0,1,0\n"
    "3000,1,1,0,0,0,0\n";

// The two run directories, with every file but summary.json; stdout (where the command prints
// its JSON) goes to a file of the scratch directory.
struct Runs {
  fs::path a, b, out;
};

const Runs& SetUp() {
  static const Runs runs = [] {
    const priormap::fuzz::ScratchDirectory& scratch = priormap::fuzz::Scratch();
    Runs r{scratch.path() / "a", scratch.path() / "b", scratch.path() / "stdout.json"};
    for (const auto& [dir, seed, trace] :
         {std::tuple{fs::path("a"), 1, kTraceA}, std::tuple{fs::path("b"), 3, kTraceB}}) {
      priormap::app::MappingCliOptions run;
      run.log = "/data/square.json";
      run.mapping.samples = 2000;
      run.mapping.burn_in = 1000;
      run.mapping.trace_every = 500;
      run.mapping.chains = 2;
      run.mapping.seed = static_cast<std::uint64_t>(seed);
      scratch.Write(dir / "run.json", priormap::app::RunJson(run).dump(2) + "\n");
      scratch.Write(dir / "trace.csv", trace);
      scratch.Write(dir / "point_traces.csv", kPointTraces);
    }
    if (std::freopen(r.out.c_str(), "w+", stdout) == nullptr) {
      std::perror("fuzz: freopen stdout");
      std::abort();
    }
    return r;
  }();
  return runs;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  const Runs& runs = SetUp();
  const std::size_t split = input.find('\0');
  const priormap::fuzz::ScratchDirectory& scratch = priormap::fuzz::Scratch();
  scratch.Write("a/summary.json", input.substr(0, split));
  scratch.Write("b/summary.json",
                split == std::string_view::npos ? input : input.substr(split + 1));

  std::fflush(stdout);
  Check(ftruncate(fileno(stdout), 0) == 0, "stdout is emptied");
  std::rewind(stdout);
  CLI::App prf{"prf", "prf"};
  priormap::app::AddPrfRhatCommand(prf);
  const std::string a = runs.a.string(), b = runs.b.string();
  const char* argv[] = {"prf", "rhat", a.c_str(), b.c_str()};
  try {
    prf.parse(4, argv);
  } catch (const priormap::app::UserError& e) {
    const std::string_view message = e.what();
    Check(message.find(a) != std::string_view::npos || message.find(b) != std::string_view::npos,
          "a refused run is a UserError that names it", message);
    return 0;
  } catch (const std::exception& e) {
    Check(false, "prf rhat throws UserError only", e.what());
  }
  std::fflush(stdout);
  const std::string printed = priormap::fuzz::ReadBytes(runs.out);
  const nlohmann::json result = nlohmann::json::parse(printed, nullptr, false);
  Check(result.is_object() && result.value("chains", 0) == 4 && result.contains("rhat") &&
            result.contains("runs") && result.at("runs").size() == 2,
        "prf rhat prints the R-hat of the four chains as JSON", printed);
  return 0;
}
