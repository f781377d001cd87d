#pragma once
/// R̂ over the chains of several runs of one posterior (`priormap prf rhat`). A run's own R̂
/// compares its chains only; with two chains, two that happen to sit close pass it while other
/// seeds' chains sit far away. Pooling runs made with other seeds (or on other machines) gives
/// the diagnostic more chains, as Gelman et al. (BDA3, Sec. 11.4) advise.
///
/// A run's traces are read from its trace.csv (the log-posterior of each chain per record) and
/// point_traces.csv (each trace point's colour, 1 black, per chain and record); problems are
/// reported at file:line:col.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include <priormap/core/diagnostic.hpp>

namespace priormap::prf {

/// What a run recorded for R̂, per chain and trace record.
struct RunTraces {
  std::vector<std::uint64_t> samples;              ///< the sample index of each record
  std::vector<std::vector<double>> log_posterior;  ///< [chain][record]
  /// [chain][point][record], 1 black and 0 white; empty when the run did not record them.
  std::vector<std::vector<std::vector<double>>> point_colours;
};

/// trace.csv: "sample,chain0,...,chainC-1", then a line per record, each log-posterior in the
/// shortest form that reads back exactly.
[[nodiscard]] std::string FormatLogPosteriorTrace(const RunTraces& traces);
/// point_traces.csv: "sample,chain0_point0,...", then a line per record of 0 (white) and 1
/// (black); `traces` must hold the colours.
[[nodiscard]] std::string FormatPointTraces(const RunTraces& traces);

/// Parses trace.csv ("sample,chain0,...,chainC-1"); `name` is its path, for messages.
[[nodiscard]] Result<RunTraces> ParseLogPosteriorTrace(std::string_view text,
                                                       const std::string& name);
/// Parses point_traces.csv ("sample,chain0_point0,...") into `traces`, whose chains and samples
/// (from trace.csv) it must match.
[[nodiscard]] Result<RunTraces> ParsePointTraces(std::string_view text, const std::string& name,
                                                 RunTraces traces);

/// One run to pool: its traces and the seeds its chains draw from (chain c of a run with
/// --seed s draws from s + c), so that a chain given twice is refused.
struct PooledRun {
  std::string name;
  std::vector<std::uint64_t> chain_seeds;
  RunTraces traces;
};

/// One trace point's R̂ over the pooled chains, and what each chain made of the point.
struct PointRhat {
  std::size_t point = 0;  ///< its index among the trace points
  double rhat = 1.0;
  std::vector<double> black;  ///< per chain: the share of its records in which the point is black
};

struct PooledRhat {
  std::size_t chains = 0;
  /// Records per chain that enter R̂: the shortest run's.
  std::size_t records = 0;
  double log_posterior = 0.0;
  /// The largest over the trace points (1 with no points, as a run's own R̂ has it); none
  /// unless every run recorded them.
  std::optional<double> point_colours;
  std::size_t points = 0;
  /// Each trace point's R̂, in the points' order (none without point_colours), so that a
  /// large R̂ can be traced to the places where the chains' maps differ.
  std::vector<PointRhat> point_rhats;
  /// Each chain's mean log-posterior over the second half of the records that enter R̂ (the
  /// shortest run's), run after run.
  std::vector<double> second_half_means;
};

/// Split-R̂ over every chain of `runs`, each cut to the shortest run's records (one run alone
/// gives its own R̂), or what makes them unfit to pool: no chain, a chain seed given twice,
/// records at different samples, fewer than four records, or different numbers of trace points.
[[nodiscard]] std::variant<PooledRhat, std::string> PoolRhat(const std::vector<PooledRun>& runs);

}  // namespace priormap::prf
