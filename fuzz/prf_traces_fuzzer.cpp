// libFuzzer harness for the trace files `priormap prf rhat` reads (trace.csv, then, after the
// input's first NUL byte, point_traces.csv). Besides crashes and sanitizer reports it checks that
// a rejected file gets diagnostics located inside its text, that accepted traces are consistent
// (a value per chain and record, samples rising, colours 0 or 1), that writing them again
// (FormatLogPosteriorTrace, FormatPointTraces) and reading them back gives the same values bit
// for bit, and that R̂ pools them without a crash.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include <priormap/prf/pooled_rhat.hpp>

#include "fuzz_check.hpp"

using priormap::fuzz::Check;
using priormap::fuzz::CheckLocated;
using priormap::fuzz::SameBits;
using priormap::prf::RunTraces;

namespace {

void CheckConsistent(const RunTraces& traces) {
  for (std::size_t i = 1; i < traces.samples.size(); ++i)
    Check(traces.samples[i - 1] < traces.samples[i], "samples rise");
  for (const auto& chain : traces.log_posterior)
    Check(chain.size() == traces.samples.size(), "a log-posterior per chain and record");
  for (const auto& chain : traces.point_colours)
    for (const auto& point : chain) {
      Check(point.size() == traces.samples.size(), "a colour per chain, point and record");
      for (const double colour : point) Check(colour == 0.0 || colour == 1.0, "colours are 0/1");
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  const std::size_t split = input.find('\0');
  const std::string_view trace_text = input.substr(0, split);
  const auto traces = priormap::prf::ParseLogPosteriorTrace(trace_text, "trace.csv");
  if (!traces.ok()) {
    CheckLocated(traces.diagnostics(), trace_text, "trace.csv");
    return 0;
  }
  CheckConsistent(traces.value());
  Check(traces.value().point_colours.empty(), "trace.csv holds no colours");

  const std::string written = priormap::prf::FormatLogPosteriorTrace(traces.value());
  const auto again = priormap::prf::ParseLogPosteriorTrace(written, "again.csv");
  Check(again.ok(), "a written trace is read back", again.ok() ? written : again.error());
  Check(again.value().samples == traces.value().samples, "the round trip keeps the samples",
        written);
  for (std::size_t c = 0; c < traces.value().log_posterior.size(); ++c)
    for (std::size_t i = 0; i < traces.value().samples.size(); ++i)
      Check(SameBits(again.value().log_posterior[c][i], traces.value().log_posterior[c][i]),
            "the round trip keeps every value", written);

  RunTraces run = traces.value();
  if (split != std::string_view::npos) {
    const std::string_view point_text = input.substr(split + 1);
    auto with_points = priormap::prf::ParsePointTraces(point_text, "points.csv", run);
    if (!with_points.ok()) {
      CheckLocated(with_points.diagnostics(), point_text, "points.csv");
      return 0;
    }
    run = std::move(with_points).value();
    CheckConsistent(run);
    Check(run.log_posterior == traces.value().log_posterior, "the colours keep the trace");
    const std::string points_written = priormap::prf::FormatPointTraces(run);
    const auto points_again =
        priormap::prf::ParsePointTraces(points_written, "again.csv", traces.value());
    Check(points_again.ok(), "written colours are read back",
          points_again.ok() ? points_written : points_again.error());
    Check(points_again.value().point_colours == run.point_colours,
          "the round trip keeps every colour", points_written);
  }
  priormap::prf::PooledRun pooled{.name = "fuzz", .chain_seeds = {}, .traces = run};
  for (std::size_t c = 0; c < run.log_posterior.size(); ++c) pooled.chain_seeds.push_back(c);
  (void)priormap::prf::PoolRhat({pooled});
  return 0;
}
