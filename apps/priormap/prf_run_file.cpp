#include "prf_run_file.hpp"

#include <charconv>
#include <cmath>
#include <string_view>
#include <system_error>
#include <utility>

#include <fmt/format.h>

#include <priormap/core/file_io.hpp>
#include <priormap/prf/moves.hpp>

#include "cli_support.hpp"
#include "json_whole_number.hpp"
#include "prf_posterior_options.hpp"

namespace priormap::app {

namespace {

constexpr int kRunFileVersion = 2;

std::string FingerprintText(std::uint64_t fingerprint) {
  return fmt::format("{:016x}", fingerprint);
}

std::uint64_t FingerprintMember(const nlohmann::json& j, const char* key) {
  const std::string text = j.at(key).get<std::string>();
  std::uint64_t value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value, 16);
  if (text.size() != 16 || error != std::errc() || end != text.data() + text.size())
    throw JsonNumberError(fmt::format(
        "\"fingerprints\": \"{}\" is \"{}\", expected 16 hexadecimal digits", key, text));
  return value;
}

}  // namespace

nlohmann::json RunJson(const MappingCliOptions& o) {
  const prf::MappingOptions& m = o.mapping;
  nlohmann::json j = {
      {"format", "priormap prf run"},
      {"version", kRunFileVersion},
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
  if (o.started_with)
    j["fingerprints"] = {{"data", FingerprintText(o.started_with->data)},
                         {"run", FingerprintText(o.started_with->run)}};
  return j;
}

namespace {

// The command line's checks of the options run.json holds (cmd_prf.cpp, prf_posterior_options.cpp).
void RequireRunnableOptions(const MappingCliOptions& o) {
  const prf::MappingOptions& m = o.mapping;
  const auto require = [](bool ok, std::string_view key, auto value, std::string_view expected) {
    if (!ok) throw UserError(fmt::format("\"{}\" is {}, expected {}", key, value, expected));
  };
  const auto positive = [&](double value, std::string_view key) {
    require(std::isfinite(value) && value > 0.0, key, value, "a number > 0");
  };
  require(o.sensor == "auto" || o.sensor == "laser" || o.sensor == "sonar", "sensor", o.sensor,
          "auto, laser or sonar");
  require(o.selection.beam_step >= 1 && o.selection.beam_step <= 100000, "beam_step",
          o.selection.beam_step, "1 to 100000");
  positive(o.selection.max_range, "max_range");
  positive(m.sampler.p, "p");
  require(m.samples >= 1 && m.samples <= kMaxStepCount, "samples", m.samples,
          fmt::format("1 to {}", kMaxStepCount));
  require(m.burn_in <= kMaxStepCount, "burn_in", m.burn_in,
          fmt::format("at most {}", kMaxStepCount));
  require(m.anneal_steps <= kMaxStepCount, "anneal_steps", m.anneal_steps,
          fmt::format("at most {}", kMaxStepCount));
  require(m.chains >= 1 && m.chains <= 256, "chains", m.chains, "1 to 256");
  positive(m.model.sigma, "sigma");
  positive(m.cell_size, "cell_size");
  require(std::isfinite(m.sampler.weights[prf::MoveKind::kGuidedTriangle]) &&
              m.sampler.weights[prf::MoveKind::kGuidedTriangle] >= 0.0,
          "guided_births", m.sampler.weights[prf::MoveKind::kGuidedTriangle], "a number >= 0");
  require(std::isfinite(m.guide_jitter) && m.guide_jitter > 0.0 && m.guide_jitter <= 100.0,
          "guide_jitter", m.guide_jitter, "a number in (0, 100]");
  positive(m.raster_resolution, "resolution");
  require(m.trace_every >= 1 && m.trace_every <= kMaxStepCount, "trace_every", m.trace_every,
          fmt::format("1 to {}", kMaxStepCount));
  require(m.burn_in_replicas >= 1 && m.burn_in_replicas <= 64, "posterior.burn_in_replicas",
          m.burn_in_replicas, "1 to 64");
  require(m.sampler.screen_stride >= 1 && m.sampler.screen_stride <= 1024,
          "posterior.delayed_acceptance", m.sampler.screen_stride, "1 to 1024");
  for (const prf::ThinnedBurnIn& stage : m.thinned_burn_in)
    require(stage.stride >= 1, "posterior.thinned_burn_in stride", stage.stride, "at least 1");
  require(m.warm_burn_in.temperature >= 1.0, "posterior.warm_burn_in temperature",
          m.warm_burn_in.temperature, "at least 1");
  RequireConsistentPosteriorOptions(m);
}

}  // namespace

MappingCliOptions ReadRunFile(const std::filesystem::path& path, MappingCliOptions base) {
  const std::string text = ValueOrThrow(ReadFileText(path));
  MappingCliOptions o = std::move(base);
  try {
    const nlohmann::json j = nlohmann::json::parse(text);
    if (j.at("format") != "priormap prf run")
      throw UserError(fmt::format("{}: not a priormap prf run file", path.string()));
    if (j.at("version") != kRunFileVersion)
      throw UserError(fmt::format(
          "{}: version {} of the run file, which another version of priormap wrote; this one "
          "reads version {} (use the priormap that wrote it)",
          path.string(), j.at("version").dump(), kRunFileVersion));
    o.log = j.at("log").get<std::string>();
    // Runs written before --sensor existed are laser runs.
    o.sensor = j.contains("sensor") ? j.at("sensor").get<std::string>() : "laser";
    o.sonar_model = j.contains("sonar_model") ? j.at("sonar_model").get<std::string>() : "";
    o.range = j.at("range").get<std::string>();
    o.selection.beam_step = WholeNumberMember<std::size_t>(j, "beam_step");
    o.selection.max_range = j.at("max_range").get<double>();
    prf::MappingOptions& m = o.mapping;
    m.sampler.p = j.at("p").get<double>();
    m.samples = WholeNumberMember<std::uint64_t>(j, "samples");
    m.burn_in = WholeNumberMember<std::uint64_t>(j, "burn_in");
    m.chains = WholeNumberMember<int>(j, "chains");
    m.seed = WholeNumberMember<std::uint64_t>(j, "seed");
    o.anneal = j.at("anneal").get<bool>();
    m.anneal_steps = WholeNumberMember<std::uint64_t>(j, "anneal_steps");
    m.model.sigma = j.at("sigma").get<double>();
    m.cell_size = j.at("cell_size").get<double>();
    m.sampler.weights[prf::MoveKind::kGuidedTriangle] = j.at("guided_births").get<double>();
    m.guide_jitter = j.at("guide_jitter").get<double>();
    m.raster_resolution = j.at("resolution").get<double>();
    m.trace_every = WholeNumberMember<std::uint64_t>(j, "trace_every");
    m.sampler.check_invariants = j.at("check").get<bool>();
    // Runs written before these options existed ran the Arak process with a plain burn-in.
    PosteriorOptionsFromJson(j.value("posterior", nlohmann::json::object()), &m);
    if (j.contains("fingerprints"))
      o.started_with = RunFingerprints{.data = FingerprintMember(j.at("fingerprints"), "data"),
                                       .run = FingerprintMember(j.at("fingerprints"), "run")};
  } catch (const nlohmann::json::exception& e) {
    throw UserError(fmt::format("{}: not a valid run file ({})", path.string(), e.what()));
  } catch (const JsonNumberError& e) {
    throw UserError(fmt::format("{}: not a valid run file ({})", path.string(), e.what()));
  }
  // An edited file must meet what the command line checks, or it fails deep in the run.
  try {
    RequireRunnableOptions(o);
  } catch (const UserError& e) {
    throw UserError(fmt::format("{}: {}", path.string(), e.what()));
  }
  return o;
}

}  // namespace priormap::app
