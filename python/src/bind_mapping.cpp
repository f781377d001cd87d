// priormap.occupancy_grid and priormap.prf_map: mapping from localized scans given as numpy
// arrays (the log-odds grid and the polygonal random field posterior).
#include <atomic>
#include <chrono>
#include <cmath>
#include <future>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

#include <priormap/grid/occupancy_grid.hpp>
#include <priormap/prf/laser_data.hpp>
#include <priormap/prf/mapping.hpp>
#include <priormap/prf/polygon_map.hpp>

#include "bindings.hpp"
#include "convert.hpp"

namespace priormap::python {
namespace {

// The bounds `priormap prf` puts on --chains, --beam-step, --samples and --burn-in.
constexpr int kMaxChains = 256;
constexpr std::size_t kMaxBeamStep = 100000;
constexpr std::uint64_t kMaxStepCount = std::uint64_t{1} << 40;

py::dict RasterDict(const Eigen::MatrixXd& probability, const Vec2& origin, double resolution) {
  py::dict out;
  out["probability"] = MatrixToNumpy(probability);
  out["origin"] = py::make_tuple(origin.x(), origin.y());
  out["resolution"] = resolution;
  return out;
}

py::dict OccupancyGridOf(const Doubles& poses, const Doubles& ranges, const Doubles& angles,
                         double max_range, double resolution, double min_range) {
  const Log log = LogFromArrays(poses, ranges, angles, max_range, min_range, 0.01);
  grid::GridOptions options;
  options.resolution = resolution;
  if (std::isfinite(max_range)) options.max_range = max_range;
  const Box2 extent = grid::OccupancyGrid::ExtentOf(log, 0, log.scans.size(), options);
  if (extent.isEmpty()) throw std::invalid_argument("the scans have no usable reading");
  grid::OccupancyGrid map(extent, options);  // ValueError for a grid too large for memory
  OccupancyRaster raster;
  {
    const py::gil_scoped_release release;  // touches no Python object
    for (const Scan& scan : log.scans) map.Insert(scan);
    raster = map.Raster();
  }
  return RasterDict(raster.probability, raster.origin, raster.resolution);
}

py::dict PrfMap(const Doubles& poses, const Doubles& ranges, const Doubles& angles,
                double max_range, double p, std::uint64_t samples, std::uint64_t burn_in,
                int chains, std::uint64_t seed, std::size_t beam_step, bool anneal,
                double resolution, double min_range) {
  if (chains < 1 || chains > kMaxChains)
    throw std::invalid_argument(
        fmt::format("chains must be in [1, {}], got {}", kMaxChains, chains));
  if (!(p > 0.0 && std::isfinite(p)))
    throw std::invalid_argument(fmt::format("p must be positive and finite, got {}", p));
  if (beam_step < 1 || beam_step > kMaxBeamStep)
    throw std::invalid_argument(
        fmt::format("beam_step must be in [1, {}], got {}", kMaxBeamStep, beam_step));
  if (!(resolution > 0.0 && std::isfinite(resolution)))
    throw std::invalid_argument(fmt::format("resolution must be positive, got {}", resolution));
  // P(black) is a mean over the samples, and the annealing runs for as many steps.
  if (samples == 0 || samples > kMaxStepCount)
    throw std::invalid_argument(fmt::format("samples must be in [1, 2^40], got {}", samples));
  if (burn_in > kMaxStepCount)
    throw std::invalid_argument(fmt::format("burn_in must be in [0, 2^40], got {}", burn_in));
  const Log log = LogFromArrays(poses, ranges, angles, max_range, min_range, 0.01);
  prf::LaserSelection selection;
  selection.beam_step = beam_step;
  if (std::isfinite(max_range)) selection.max_range = max_range;
  auto selected = prf::SelectBeams(log, selection);
  if (!selected) throw std::invalid_argument(selected.diagnostics().front().message);
  const auto data = std::make_shared<const prf::LaserData>(std::move(selected).value());
  prf::MappingOptions options;
  options.sampler.p = p;
  options.samples = samples;
  options.burn_in = burn_in;
  options.chains = chains;
  options.seed = seed;
  options.raster_resolution = resolution;
  options.anneal_steps = anneal ? samples : 0;
  const prf::MappingData mapping = prf::LaserMappingData(data, options);
  if (const std::string problem = prf::RasterSizeProblem(mapping.window, resolution);
      !problem.empty())
    throw std::invalid_argument(fmt::format("resolution {} m: {}", resolution, problem));
  // Ctrl-C: signals reach only the main thread, so the run goes on in another, and this one
  // looks for them while it waits; the chains (and the annealing) stop at their next chunk.
  std::atomic<bool> interrupted{false};
  prf::MappingSession session;
  session.stop = &interrupted;
  prf::MappingResult r;
  {
    const py::gil_scoped_release release;
    auto run = std::async(std::launch::async, [&] {
      return prf::RunMapping(
          mapping, options, [](const prf::MappingProgress&) {}, session);
    });
    while (run.wait_for(std::chrono::milliseconds(100)) != std::future_status::ready) {
      if (interrupted) continue;
      const py::gil_scoped_acquire acquire;
      if (PyErr_CheckSignals() != 0) interrupted = true;
    }
    r = run.get();
  }
  if (interrupted) throw py::error_already_set();
  py::dict out;
  out["black_fraction"] = MatrixToNumpy(r.black_fraction);
  out["white_fraction"] = MatrixToNumpy(r.white_fraction);
  out["chain_spread"] = MatrixToNumpy(r.chain_spread);
  out["origin"] = py::make_tuple(r.raster.origin.x(), r.raster.origin.y());
  out["resolution"] = r.raster.cell.x();
  // The cells fit the window exactly, so they may be a little taller or wider than long.
  out["cell_size"] = py::make_tuple(r.raster.cell.x(), r.raster.cell.y());
  out["window"] =
      py::make_tuple(r.window.min.x(), r.window.min.y(), r.window.max.x(), r.window.max.y());
  out["rhat_log_posterior"] = r.rhat_log_posterior;
  out["rhat_point_colours"] = r.rhat_point_colours;
  out["proposals"] = r.proposals;
  out["proposals_per_second"] = r.ProposalsPerSecond();
  out["beams"] = data->beams.size();
  py::list log_posterior;
  for (const prf::ChainSummary& chain : r.chains) log_posterior.append(chain.log_posterior);
  out["log_posterior"] = log_posterior;
  if (r.map) {
    out["map_geojson"] = prf::FacesToGeoJson(prf::ExtractFaces(*r.map), r.window);
    out["map_edges"] = r.map->stats().edges;
    out["map_compact_bytes"] = prf::CompactMapBytes(*r.map);
  }
  return out;
}

constexpr const char* kScansDoc =
    "poses (n, 3): x, y, theta of the sensor per scan; ranges (n, m); angles (m,) or (n, m) in "
    "radians; NaN readings are invalid, readings at or above max_range are max-range readings";

}  // namespace

void BindMapping(py::module_& m) {
  m.def("occupancy_grid", &OccupancyGridOf, py::arg("poses"), py::arg("ranges"), py::arg("angles"),
        py::arg("max_range"), py::arg("resolution") = 0.05, py::arg("min_range") = 0.0,
        (std::string("Log-odds occupancy grid of localized laser scans. ") + kScansDoc +
         ". Returns 'probability' (rows from the bottom, NaN where unknown), 'origin' (lower-left "
         "corner of cell (0, 0)), 'resolution'.")
            .c_str());
  m.def("prf_map", &PrfMap, py::arg("poses"), py::arg("ranges"), py::arg("angles"),
        py::arg("max_range"), py::arg("p") = 0.1, py::arg("samples") = 200000,
        py::arg("burn_in") = 200000, py::arg("chains") = 2, py::arg("seed") = 1,
        py::arg("beam_step") = 1, py::arg("anneal") = false, py::arg("resolution") = 0.1,
        py::arg("min_range") = 0.0,
        (std::string("Polygonal random field posterior (Paskin & Thrun) of localized laser "
                     "scans, chains in parallel. ") +
         kScansDoc +
         ". Returns 'black_fraction' = P(occupied) per cell (rows from the bottom), "
         "'white_fraction', 'chain_spread' (the largest minus the smallest chain's P(black): "
         "where the chains disagree), 'origin', 'resolution', 'cell_size' (width, height: the "
         "cells fit the window exactly), 'window', R-hats, 'beams', 'proposals' and their speed, "
         "each chain's 'log_posterior'; with anneal=True the MAP polygon map as 'map_geojson'. "
         "chains: 1 to 256; samples: 1 to 2^40. The same seed gives the same result.")
            .c_str());
}

}  // namespace priormap::python
