#include "prf_run_file.hpp"

#include <utility>

#include <fmt/format.h>

#include <priormap/core/file_io.hpp>
#include <priormap/prf/moves.hpp>

#include "cli_support.hpp"

namespace priormap::app {

nlohmann::json RunJson(const MappingCliOptions& o) {
  const prf::MappingOptions& m = o.mapping;
  return {{"format", "priormap prf run"},
          {"version", 2},
          {"log", std::filesystem::absolute(o.log).string()},
          {"sensor", o.sensor},
          {"sonar_model",
           o.sonar_model.empty() ? "" : std::filesystem::absolute(o.sonar_model).string()},
          {"range", o.range},
          {"beam_step", o.selection.beam_step},
          {"max_range", o.selection.max_range},
          {"p", m.sampler.p},
          {"samples", m.samples},
          {"burn_in", m.burn_in},
          {"chains", m.chains},
          {"seed", m.seed},
          {"anneal", o.anneal},
          {"anneal_steps", m.anneal_steps},
          {"sigma", m.model.sigma},
          {"cell_size", m.cell_size},
          {"guided_births", m.sampler.weights[prf::MoveKind::kGuidedTriangle]},
          {"guide_jitter", m.guide_jitter},
          {"resolution", m.raster_resolution},
          {"trace_every", m.trace_every},
          {"check", m.sampler.check_invariants},
          {"posterior", PosteriorOptionsJson(m)}};
}

MappingCliOptions ReadRunFile(const std::filesystem::path& path, MappingCliOptions base) {
  const std::string text = ValueOrThrow(ReadFileText(path));
  MappingCliOptions o = std::move(base);
  try {
    const nlohmann::json j = nlohmann::json::parse(text);
    if (j.at("format") != "priormap prf run" || j.at("version") != 2)
      throw UserError(fmt::format("{}: not a run file of this version", path.string()));
    o.log = j.at("log").get<std::string>();
    // Runs written before --sensor existed are laser runs.
    o.sensor = j.contains("sensor") ? j.at("sensor").get<std::string>() : "laser";
    o.sonar_model = j.contains("sonar_model") ? j.at("sonar_model").get<std::string>() : "";
    o.range = j.at("range").get<std::string>();
    o.selection.beam_step = j.at("beam_step").get<std::size_t>();
    o.selection.max_range = j.at("max_range").get<double>();
    prf::MappingOptions& m = o.mapping;
    m.sampler.p = j.at("p").get<double>();
    m.samples = j.at("samples").get<std::uint64_t>();
    m.burn_in = j.at("burn_in").get<std::uint64_t>();
    m.chains = j.at("chains").get<int>();
    m.seed = j.at("seed").get<std::uint64_t>();
    o.anneal = j.at("anneal").get<bool>();
    m.anneal_steps = j.at("anneal_steps").get<std::uint64_t>();
    m.model.sigma = j.at("sigma").get<double>();
    m.cell_size = j.at("cell_size").get<double>();
    m.sampler.weights[prf::MoveKind::kGuidedTriangle] = j.at("guided_births").get<double>();
    m.guide_jitter = j.at("guide_jitter").get<double>();
    m.raster_resolution = j.at("resolution").get<double>();
    m.trace_every = j.at("trace_every").get<std::uint64_t>();
    m.sampler.check_invariants = j.at("check").get<bool>();
    // Runs written before these options existed ran the Arak process with a plain burn-in.
    PosteriorOptionsFromJson(j.value("posterior", nlohmann::json::object()), &m);
  } catch (const nlohmann::json::exception& e) {
    throw UserError(fmt::format("{}: not a valid run file ({})", path.string(), e.what()));
  }
  return o;
}

}  // namespace priormap::app
