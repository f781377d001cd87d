#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>

#include <tbb/parallel_for.h>

#include <priormap/core/check.hpp>
#include <priormap/core/rng.hpp>
#include <priormap/prf/estimates.hpp>
#include <priormap/prf/laser_likelihood.hpp>
#include <priormap/prf/mapping.hpp>
#include <priormap/prf/rhat.hpp>

namespace priormap::prf {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

// Points whose colours enter R̂: for evenly spread beams that hit something, one point midway
// (seen free) and one 0.1 m behind the hit (likely occupied, often uncertain).
std::vector<Vec2> TracePoints(const LaserData& data, const Window& window, int count) {
  std::vector<std::size_t> hits;
  for (std::size_t i = 0; i < data.beams.size(); ++i)
    if (!data.beams[i].max_reading) hits.push_back(i);
  std::vector<Vec2> points;
  if (hits.empty() || count <= 0) return points;
  const int pairs = std::max(1, count / 2);
  for (int k = 0; k < pairs; ++k) {
    const LaserBeam& beam = data.beams[hits[static_cast<std::size_t>(k) * hits.size() /
                                            static_cast<std::size_t>(pairs)]];
    for (double along : {0.5 * beam.range, beam.range + 0.1}) {
      const Vec2 p = beam.origin + along * beam.direction;
      if (window.ContainsInterior(p)) points.push_back(p);
    }
  }
  return points;
}

}  // namespace

MappingResult RunMapping(std::shared_ptr<const LaserData> data, const MappingOptions& options,
                         const std::function<void(const MappingProgress&)>& progress) {
  PRIORMAP_CHECK(options.chains >= 1, "at least one chain");
  PRIORMAP_CHECK(options.trace_every >= 1 && options.chunk >= 1, "positive trace and chunk");
  const auto start = Clock::now();
  MappingResult result;
  result.window = WindowAround(*data, options.margin);
  result.trace_points = TracePoints(*data, result.window, options.trace_points);

  const auto chains = static_cast<std::size_t>(options.chains);
  std::vector<std::unique_ptr<PrfSampler>> samplers(chains);
  std::vector<std::unique_ptr<PosteriorEstimates>> estimates(chains);
  result.chains.resize(chains);
  std::mutex progress_mutex;
  std::atomic<std::uint64_t> steps_done{0};
  const std::uint64_t steps_total = chains * (options.burn_in + options.samples);

  tbb::parallel_for(std::size_t{0}, chains, [&](std::size_t c) {
    SamplerOptions sampler_options = options.sampler;
    sampler_options.temperature = 1.0;
    auto likelihood = std::make_unique<LaserLikelihood>(data, options.model, options.cell_size);
    auto sampler =
        std::make_unique<PrfSampler>(Coloring(result.window, options.cell_size), sampler_options,
                                     SplitMix64(options.seed + c), std::move(likelihood));
    auto chain_estimates =
        std::make_unique<PosteriorEstimates>(result.window, options.raster_resolution);
    ChainSummary& summary = result.chains[c];
    summary.point_traces.assign(result.trace_points.size(), {});
    const auto report = [&](std::uint64_t steps) {
      steps_done += steps;
      if (!progress) return;
      std::lock_guard lock(progress_mutex);
      progress({.steps_done = steps_done.load(),
                .steps_total = steps_total,
                .seconds = Seconds(start),
                .log_posterior = sampler->LogPosterior(),
                .counters = sampler->counters()});
    };
    for (std::uint64_t done = 0; done < options.burn_in;) {
      const std::uint64_t n = std::min(options.chunk, options.burn_in - done);
      sampler->Run(n);
      done += n;
      report(n);
    }
    sampler->RecordInto(chain_estimates.get());
    std::uint64_t since_report = 0;
    for (std::uint64_t done = 0; done < options.samples;) {
      const std::uint64_t n = std::min(options.trace_every, options.samples - done);
      sampler->Run(n);
      done += n;
      since_report += n;
      if (n == options.trace_every) {
        summary.log_posterior_trace.push_back(sampler->LogPosterior());
        for (std::size_t k = 0; k < result.trace_points.size(); ++k)
          summary.point_traces[k].push_back(
              sampler->coloring().ColourAt(result.trace_points[k]) == Colour::kBlack ? 1.0 : 0.0);
      }
      if (since_report >= options.chunk || done == options.samples) {
        report(since_report);
        since_report = 0;
      }
    }
    summary.counters = sampler->counters();
    summary.log_posterior = sampler->LogPosterior();
    summary.edges = sampler->coloring().stats().edges;
    samplers[c] = std::move(sampler);
    estimates[c] = std::move(chain_estimates);
  });
  result.sampling_time_s = Seconds(start);
  result.proposals = steps_total;

  // Pooled estimates: every chain records the same number of samples.
  result.raster = estimates[0]->grid();
  result.black_fraction = Eigen::MatrixXd::Zero(result.raster.ny, result.raster.nx);
  result.white_fraction = result.black_fraction;
  if (options.samples > 0) {
    for (std::size_t c = 0; c < chains; ++c) {
      result.black_fraction += estimates[c]->BlackFraction(samplers[c]->steps());
      result.white_fraction += estimates[c]->WhiteFraction(samplers[c]->steps());
    }
    result.black_fraction /= static_cast<double>(chains);
    result.white_fraction /= static_cast<double>(chains);
  }

  // R̂ needs at least 4 trace records per chain.
  if (result.chains[0].log_posterior_trace.size() >= 4) {
    std::vector<std::vector<double>> traces;
    for (const ChainSummary& chain : result.chains) traces.push_back(chain.log_posterior_trace);
    result.rhat_log_posterior = SplitRhat(traces);
    result.rhat_point_colours = 1.0;
    for (std::size_t k = 0; k < result.trace_points.size(); ++k) {
      traces.clear();
      for (const ChainSummary& chain : result.chains) traces.push_back(chain.point_traces[k]);
      result.rhat_point_colours = std::max(result.rhat_point_colours, SplitRhat(traces));
    }
  } else {
    result.rhat_log_posterior = result.rhat_point_colours = std::nan("");
  }

  if (options.anneal_steps > 0) {
    // From the chain that ended highest; the temperature falls geometrically from 1.
    std::size_t best = 0;
    for (std::size_t c = 1; c < chains; ++c)
      if (result.chains[c].log_posterior > result.chains[best].log_posterior) best = c;
    PrfSampler& sampler = *samplers[best];
    sampler.RecordInto(nullptr);
    const std::uint64_t stages = 100;
    const std::uint64_t per_stage = std::max<std::uint64_t>(1, options.anneal_steps / stages);
    for (std::uint64_t s = 0; s < stages; ++s) {
      const double fraction = static_cast<double>(s + 1) / static_cast<double>(stages);
      sampler.set_temperature(std::pow(options.anneal_final_temperature, fraction));
      sampler.Run(per_stage);
    }
    result.map = sampler.coloring();
    result.map_log_posterior = sampler.LogPosterior();
  }
  result.wall_time_s = Seconds(start);
  return result;
}

}  // namespace priormap::prf
