#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <numeric>
#include <set>

#include <fmt/format.h>

#include <priormap/prf/pooled_rhat.hpp>
#include <priormap/prf/rhat.hpp>

namespace priormap::prf {
namespace {

struct Field {
  std::string_view text;
  int col = 1;  // 1-based
};

struct CsvLine {
  int number = 0;   // 1-based
  int end_col = 1;  // one past the last character, where a missing value is reported
  std::vector<Field> fields;
};

// The file's non-empty lines split at commas (a trailing \r is dropped).
std::vector<CsvLine> SplitCsv(std::string_view text) {
  std::vector<CsvLine> lines;
  int number = 0;
  while (!text.empty()) {
    const std::size_t end = std::min(text.find('\n'), text.size());
    std::string_view line = text.substr(0, end);
    text.remove_prefix(std::min(end + 1, text.size()));
    ++number;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (line.empty()) continue;
    CsvLine csv{.number = number, .end_col = static_cast<int>(line.size()) + 1, .fields = {}};
    std::size_t start = 0;
    while (true) {
      const std::size_t comma = line.find(',', start);
      const std::size_t stop = comma == std::string_view::npos ? line.size() : comma;
      csv.fields.push_back({line.substr(start, stop - start), static_cast<int>(start) + 1});
      if (comma == std::string_view::npos) break;
      start = comma + 1;
    }
    lines.push_back(std::move(csv));
  }
  return lines;
}

Diagnostic At(const std::string& name, int line, int col, std::string message) {
  return {.file = name, .line = line, .col = col, .message = std::move(message)};
}

// A data line must hold `expected` values: the sample, then `after_sample`. Reported at its
// first extra value, or at its end when values are missing.
std::optional<Diagnostic> CheckValueCount(const std::string& name, const CsvLine& line,
                                          std::size_t expected, std::string_view after_sample) {
  if (line.fields.size() == expected) return std::nullopt;
  const int col = line.fields.size() > expected ? line.fields[expected].col : line.end_col;
  return At(name, line.number, col,
            fmt::format("expected {} values (the sample, then {}), found {}", expected,
                        after_sample, line.fields.size()));
}

std::optional<std::uint64_t> ParseCount(std::string_view text) {
  std::uint64_t value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return value;
}

std::optional<double> ParseFinite(std::string_view text) {
  double value = 0.0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || !std::isfinite(value))
    return std::nullopt;
  return value;
}

// Checks a header whose first column is "sample" and whose others are `expected(i)`.
template <typename Name>
std::optional<Diagnostic> CheckHeader(const std::string& name, const CsvLine& header,
                                      Name&& expected) {
  if (header.fields[0].text != "sample")
    return At(name, header.number, 1,
              fmt::format("expected the column 'sample', found {}",
                          QuoteForMessage(header.fields[0].text)));
  for (std::size_t i = 1; i < header.fields.size(); ++i) {
    const std::string want = expected(i - 1);
    if (header.fields[i].text != want)
      return At(name, header.number, header.fields[i].col,
                fmt::format("expected the column '{}', found {}", want,
                            QuoteForMessage(header.fields[i].text)));
  }
  return std::nullopt;
}

// The values v of some traces mapped to (v - mid) / half, and back.
struct AffineMap {
  double mid = 0.0, half = 1.0;
  double lo = 0.0, hi = 0.0;  // the values' range, which a mean mapped back stays in
  bool identity = true;
  [[nodiscard]] double Unmap(double x) const {
    return identity ? x : std::clamp(mid + half * x, lo, hi);
  }
};

// Split-R̂ is unchanged by an affine map of the values (a shift cancels out, a scale factor
// divides out of B/W), but its sums of squares overflow to NaN for values beyond about 1e154 in
// magnitude, which a trace.csv may hold (any finite number is read). Traces that hold such
// values are mapped into [-1, 1]; ordinary log-posteriors are left exactly as they are, so that
// one run's pooled R̂ equals its own.
AffineMap MapIntoUnitRange(std::vector<std::vector<double>>* traces) {
  constexpr double kLargestLeftAsIs = 1e100;
  AffineMap map;
  map.lo = std::numeric_limits<double>::infinity();
  map.hi = -map.lo;
  for (const std::vector<double>& trace : *traces)
    for (const double v : trace) {
      map.lo = std::min(map.lo, v);
      map.hi = std::max(map.hi, v);
    }
  if (!(std::max(std::abs(map.lo), std::abs(map.hi)) > kLargestLeftAsIs)) return map;
  map.identity = false;
  // Halves first: hi - lo may overflow, hi / 2 - lo / 2 cannot.
  map.mid = map.lo / 2.0 + map.hi / 2.0;
  map.half = map.hi / 2.0 - map.lo / 2.0;
  for (std::vector<double>& trace : *traces)
    for (double& v : trace) v = map.half > 0.0 ? (v - map.mid) / map.half : 0.0;
  return map;
}

}  // namespace

std::string FormatLogPosteriorTrace(const RunTraces& traces) {
  std::string text = "sample";
  for (std::size_t c = 0; c < traces.log_posterior.size(); ++c) text += fmt::format(",chain{}", c);
  text += "\n";
  for (std::size_t i = 0; i < traces.samples.size(); ++i) {
    text += fmt::format("{}", traces.samples[i]);
    for (const std::vector<double>& chain : traces.log_posterior)
      text += fmt::format(",{}", chain[i]);
    text += "\n";
  }
  return text;
}

std::string FormatPointTraces(const RunTraces& traces) {
  std::string text = "sample";
  for (std::size_t c = 0; c < traces.point_colours.size(); ++c)
    for (std::size_t k = 0; k < traces.point_colours[c].size(); ++k)
      text += fmt::format(",chain{}_point{}", c, k);
  text += "\n";
  for (std::size_t i = 0; i < traces.samples.size(); ++i) {
    text += fmt::format("{}", traces.samples[i]);
    for (const auto& chain : traces.point_colours)
      for (const std::vector<double>& colours : chain) text += colours[i] == 1.0 ? ",1" : ",0";
    text += "\n";
  }
  return text;
}

Result<RunTraces> ParseLogPosteriorTrace(std::string_view text, const std::string& name) {
  const std::vector<CsvLine> lines = SplitCsv(text);
  if (lines.empty())
    return At(name, 1, 1, "expected the header 'sample,chain0,...', found nothing");
  const CsvLine& header = lines[0];
  if (header.fields.size() < 2)
    return At(name, header.number, 1, "expected the header 'sample,chain0,...' with a chain");
  if (auto problem =
          CheckHeader(name, header, [](std::size_t c) { return fmt::format("chain{}", c); }))
    return *problem;
  const std::size_t chains = header.fields.size() - 1;
  RunTraces traces;
  traces.log_posterior.assign(chains, {});
  for (std::size_t l = 1; l < lines.size(); ++l) {
    const CsvLine& line = lines[l];
    if (auto problem = CheckValueCount(name, line, chains + 1, "one per chain as in the header"))
      return *problem;
    const auto sample = ParseCount(line.fields[0].text);
    if (!sample)
      return At(
          name, line.number, 1,
          fmt::format("expected a sample count, found {}", QuoteForMessage(line.fields[0].text)));
    if (!traces.samples.empty() && *sample <= traces.samples.back())
      return At(name, line.number, 1,
                fmt::format("expected a sample count above the last one ({}), found {}",
                            traces.samples.back(), *sample));
    traces.samples.push_back(*sample);
    for (std::size_t c = 0; c < chains; ++c) {
      const Field& field = line.fields[c + 1];
      const auto value = ParseFinite(field.text);
      if (!value)
        return At(
            name, line.number, field.col,
            fmt::format("expected a finite log-posterior, found {}", QuoteForMessage(field.text)));
      traces.log_posterior[c].push_back(*value);
    }
  }
  return traces;
}

Result<RunTraces> ParsePointTraces(std::string_view text, const std::string& name,
                                   RunTraces traces) {
  const std::vector<CsvLine> lines = SplitCsv(text);
  const std::size_t chains = traces.log_posterior.size();
  if (lines.empty())
    return At(name, 1, 1, "expected the header 'sample,chain0_point0,...', found nothing");
  const CsvLine& header = lines[0];
  const std::size_t columns = header.fields.size() - 1;
  if (chains == 0 || columns % chains != 0)
    return At(name, header.number, 1,
              fmt::format("expected a column per chain and trace point for the {} chains of "
                          "trace.csv, found {} columns",
                          chains, columns));
  const std::size_t points = columns / chains;
  if (auto problem = CheckHeader(name, header, [&](std::size_t i) {
        return fmt::format("chain{}_point{}", i / points, i % points);
      }))
    return *problem;
  if (lines.size() - 1 != traces.samples.size()) {
    // At the first record too many, or at the end of the last one when some are missing.
    const bool too_many = lines.size() - 1 > traces.samples.size();
    const CsvLine& at = too_many ? lines[traces.samples.size() + 1] : lines.back();
    return At(name, at.number, too_many ? 1 : at.end_col,
              fmt::format("expected {} records, as in trace.csv, found {}", traces.samples.size(),
                          lines.size() - 1));
  }
  traces.point_colours.assign(chains, std::vector<std::vector<double>>(points));
  for (std::size_t l = 1; l < lines.size(); ++l) {
    const CsvLine& line = lines[l];
    if (auto problem = CheckValueCount(name, line, columns + 1, "one per column of the header"))
      return *problem;
    const auto sample = ParseCount(line.fields[0].text);
    if (!sample || *sample != traces.samples[l - 1])
      return At(name, line.number, 1,
                fmt::format("expected the sample {}, as in trace.csv, found {}",
                            traces.samples[l - 1], QuoteForMessage(line.fields[0].text)));
    for (std::size_t i = 0; i < columns; ++i) {
      const Field& field = line.fields[i + 1];
      if (field.text != "0" && field.text != "1")
        return At(name, line.number, field.col,
                  fmt::format("expected a colour, 0 (white) or 1 (black), found {}",
                              QuoteForMessage(field.text)));
      traces.point_colours[i / points][i % points].push_back(field.text == "1" ? 1.0 : 0.0);
    }
  }
  return traces;
}

std::variant<PooledRhat, std::string> PoolRhat(const std::vector<PooledRun>& runs) {
  PooledRhat pooled;
  std::set<std::uint64_t> seeds;
  std::size_t records = std::numeric_limits<std::size_t>::max();
  for (const PooledRun& run : runs) {
    const std::size_t chains = run.traces.log_posterior.size();
    if (run.chain_seeds.size() != chains)
      return fmt::format("{}: {} chain seeds for {} chains", run.name, run.chain_seeds.size(),
                         chains);
    for (const std::uint64_t seed : run.chain_seeds)
      if (!seeds.insert(seed).second)
        return fmt::format(
            "{}: a chain draws from seed {}, as one of another run does (chain c of a run with "
            "--seed s draws from s + c): with the same settings it is the same chain, with "
            "others it is not independent of it; give one of the runs another --seed",
            run.name, seed);
    pooled.chains += chains;
    records = std::min(records, run.traces.samples.size());
  }
  // One chain is enough for split-R̂ (its halves), as a run's own R̂ has it.
  if (pooled.chains == 0) return "R-hat needs at least one chain";
  for (const PooledRun& run : runs)
    if (run.traces.samples.size() < 4)
      return fmt::format("{}: R-hat needs at least 4 trace records per chain; it has {}", run.name,
                         run.traces.samples.size());
  // The records must be at the same samples, or the chains' halves cover different stretches.
  const PooledRun& first = runs.front();
  for (const PooledRun& run : runs)
    for (std::size_t i = 0; i < records; ++i)
      if (run.traces.samples[i] != first.traces.samples[i])
        return fmt::format(
            "{} records sample {} where {} records sample {}: pool runs with the same "
            "--trace-every",
            run.name, run.traces.samples[i], first.name, first.traces.samples[i]);
  pooled.records = records;

  std::vector<std::vector<double>> traces;
  for (const PooledRun& run : runs)
    for (const std::vector<double>& trace : run.traces.log_posterior)
      traces.emplace_back(trace.begin(), trace.begin() + static_cast<std::ptrdiff_t>(records));
  for (const std::vector<double>& trace : traces) {
    double mean = SecondHalfMean(trace);
    if (!std::isfinite(mean)) {
      // Its sum overflowed: the mean of its values mapped into [-1, 1], mapped back (mapped
      // with the other chains' values, an ordinary chain's mean would lose its digits).
      std::vector<std::vector<double>> alone = {trace};
      const AffineMap map = MapIntoUnitRange(&alone);
      mean = map.Unmap(SecondHalfMean(alone[0]));
    }
    pooled.second_half_means.push_back(mean);
  }
  // Mapped together, chains whose values differ by more than ~1e16 times their own spread
  // become constant, and R̂ saturates at +inf: the pool has not converged either way.
  (void)MapIntoUnitRange(&traces);
  pooled.log_posterior = SplitRhat(traces);

  // The colours, when every run recorded them (runs made before point_traces.csv did not).
  const bool all_recorded = std::all_of(runs.begin(), runs.end(), [](const PooledRun& run) {
    return !run.traces.point_colours.empty();
  });
  if (!all_recorded) return pooled;
  const std::size_t points = first.traces.point_colours[0].size();
  for (const PooledRun& run : runs)
    if (run.traces.point_colours[0].size() != points)
      return fmt::format("{} traced {} points where {} traced {}", run.name,
                         run.traces.point_colours[0].size(), first.name, points);
  pooled.points = points;
  double largest = 1.0;  // as a run's own R̂ has it when there are no points
  for (std::size_t k = 0; k < points; ++k) {
    traces.clear();
    PointRhat point;
    point.point = k;
    for (const PooledRun& run : runs)
      for (const auto& chain : run.traces.point_colours) {
        traces.emplace_back(chain[k].begin(),
                            chain[k].begin() + static_cast<std::ptrdiff_t>(records));
        point.black.push_back(std::accumulate(traces.back().begin(), traces.back().end(), 0.0) /
                              static_cast<double>(records));
      }
    point.rhat = SplitRhat(traces);
    largest = std::max(largest, point.rhat);
    pooled.point_rhats.push_back(std::move(point));
  }
  pooled.point_colours = largest;
  return pooled;
}

}  // namespace priormap::prf
