#include "prf_posterior_options.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <numbers>
#include <string_view>

#include <fmt/format.h>

#include <priormap/prf/mapping_options_json.hpp>

#include "cli_support.hpp"
#include "json_whole_number.hpp"

namespace priormap::app {
namespace {

// Reads "A:B" into *a and *b, each the whole of its part; false on anything else.
template <typename A, typename B>
bool ParseColonPair(std::string_view text, A* a, B* b) {
  const auto parse = [](std::string_view part, auto* value) {
    const auto [end, error] = std::from_chars(part.data(), part.data() + part.size(), *value);
    return error == std::errc() && end == part.data() + part.size();
  };
  const auto colon = text.find(':');
  return colon != std::string_view::npos && parse(text.substr(0, colon), a) &&
         parse(text.substr(colon + 1), b);
}

// "STRIDE:STEPS", e.g. "16:1000000".
prf::ThinnedBurnIn ParseStage(const std::string& text) {
  prf::ThinnedBurnIn stage;
  if (!ParseColonPair(text, &stage.stride, &stage.steps) || stage.stride < 1)
    throw UserError(fmt::format(
        "--thinned-burn-in: expected STRIDE:STEPS with a stride of at least 1 (e.g. 16:1000000), "
        "got '{}'",
        text));
  return stage;
}

// "T:STEPS", e.g. "2:400000".
prf::WarmBurnIn ParseWarmStage(const std::string& text) {
  prf::WarmBurnIn warm;
  if (!ParseColonPair(text, &warm.temperature, &warm.steps) ||
      !(warm.temperature >= 1.0 && warm.temperature <= 1000.0))
    throw UserError(fmt::format(
        "--warm-burn-in: expected T:STEPS with a temperature from 1 to 1000 (e.g. 2:400000), "
        "got '{}'",
        text));
  return warm;
}

}  // namespace

void AddPosteriorOptions(CLI::App& cmd, prf::MappingOptions& m, PosteriorCliOptions& cli) {
  cmd.add_option("--free-space", m.sampler.free_space,
                 "β of a prior for free space (Paskin & Thrun, Sec. 4): a cost per m² of black; "
                 "0 is the Arak process")
      ->check(NonNegativeValue())
      ->capture_default_str();
  cmd.add_option("--orientation-weight", m.sampler.orientation.weight,
                 "κ of a prior for edges along --orientation or across it: a cost per metre of "
                 "edge at 45° to them; 0 is the Arak process")
      ->check(NonNegativeValue())
      ->capture_default_str();
  cmd.add_option("--orientation", cli.orientation_deg,
                 "θ₀ of the orientation prior (the building's axes), degrees")
      ->check(NumberValidator(
          [](double degrees, const std::string& text) -> std::string {
            if (std::isfinite(degrees * std::numbers::pi / 180.0)) return {};
            return text + " degrees is not a finite angle in radians";
          },
          ""))
      ->capture_default_str();
  cmd.add_option("--burn-in-temperature", m.burn_in_temperature,
                 "Start the burn-in at this temperature, cooling to 1 over its first half")
      ->check(CLI::Range(1.0, 1000.0))
      ->capture_default_str();
  cmd.add_option("--burn-in-replicas", m.burn_in_replicas,
                 "Replica exchange through the burn-in: replicas per chain, at temperatures "
                 "from 1 to --replica-temperature, swapping states every 1000 steps (1: none; "
                 "the burn-in costs this many times its steps)")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  cmd.add_option("--replica-temperature", m.replica_temperature,
                 "The hottest replica's temperature (the ladder is geometric from 1)")
      ->check(CLI::Range(1.0, 1000.0))
      ->capture_default_str();
  cmd.add_option("--replica-steps", m.replica_steps,
                 "The replicas run for this many steps of the burn-in, then the chain goes on "
                 "alone (0: the whole burn-in)")
      ->transform(StepCount())
      ->capture_default_str();
  cmd.add_option("--replica-pick", cli.replica_pick,
                 "Which replica the chain goes on from at the ladder's end: the cold one, or the "
                 "best (highest log-posterior), a best-of-K start")
      ->check(CLI::IsMember({"cold", "best"}))
      ->capture_default_str();
  cmd.add_option("--edge-shifts", m.sampler.weights[prf::MoveKind::kEdgeShift],
                 "Weight of the edge shifts, which move both ends of an edge by one step (a wall "
                 "shifted whole; the other kinds weigh 0.5 to 3); 0, the paper's move set, "
                 "switches them off")
      ->check(NonNegativeValue())
      ->capture_default_str();
  cmd.add_option("--step-scales", m.sampler.step_scales,
                 "Half-widths of the random-walk steps of the vertex moves and edge shifts, m; "
                 "each step draws one (finer ones help once walls are pinned to centimetres)")
      ->delimiter(',')
      ->check(PositiveValueUpTo(100.0, "m"))
      ->capture_default_str();
  cmd.add_option("--vertex-birth-widths", m.sampler.vertex_birth_widths,
                 "κ of the vertex births on an edge e, whose new vertex is uniform within κ|e| of "
                 "e, each birth drawing one κ; a vertex death straightens a bend only if its "
                 "vertex lies within the largest κ of the chord: a wide κ lets one step unmake a "
                 "tall wedge, and spreads the births that draw it")
      ->delimiter(',')
      ->check(PositiveValue())
      ->capture_default_str();
  cmd.add_option("--corner-completion", m.sampler.corner_completion,
                 "Probability that a vertex birth on edge uw puts its vertex near the corner "
                 "where the edges beyond u and w, extended, meet: a room's corner cut off by a "
                 "diagonal edge comes back in one step (0: off)")
      ->check(CLI::Range(0.0, 0.99))
      ->capture_default_str();
  cmd.add_option("--corner-completion-jitter", m.sampler.corner_completion_jitter,
                 "Half-width of the square around that corner in which such a vertex is "
                 "uniform, m")
      ->check(PositiveValue())
      ->capture_default_str();
  cmd.add_option("--neighbour-births", m.sampler.neighbour_birth,
                 "Probability that a vertex birth on edge uw puts its vertex next to the vertex "
                 "beyond u or beyond w: a wedge whose one face stands on a wall thins to that wall "
                 "in one step (0: off; with --corner-completion, the two sum below 1)")
      ->check(CLI::Range(0.0, 0.99))
      ->capture_default_str();
  cmd.add_option("--neighbour-birth-jitter", m.sampler.neighbour_birth_jitter,
                 "Half-width of the square around that vertex in which such a vertex is uniform, m")
      ->check(PositiveValue())
      ->capture_default_str();
  cmd.add_option("--vertex-jumps", m.sampler.weights[prf::MoveKind::kVertexJump],
                 "Weight of the vertex jumps, which move a vertex next to its neighbour's other "
                 "neighbour (a wedge on a wall thins to the wall in one step) or anywhere within "
                 "--vertex-jump-reach (the other kinds weigh 0.5 to 3; 0: off)")
      ->check(NonNegativeValue())
      ->capture_default_str();
  cmd.add_option("--vertex-pairs", m.sampler.weights[prf::MoveKind::kVertexPair],
                 "Weight of the vertex pair births and deaths: two vertices born on an edge in the "
                 "vertex births' rectangles, or two adjacent vertices removed at once, which cuts "
                 "a bump or a two-vertex wedge off a wall along a new edge (the other kinds weigh "
                 "0.5 to 3; 0: off)")
      ->check(NonNegativeValue())
      ->capture_default_str();
  cmd.add_option("--vertex-jump-reach", m.sampler.vertex_jump_reach,
                 "Half-width of the square around a vertex in which its far jumps are uniform, "
                 "m; a jump next to a neighbour's neighbour farther than this cannot be undone "
                 "and is refused")
      ->check(PositiveValue())
      ->capture_default_str();
  cmd.add_option("--vertex-jump-jitter", m.sampler.vertex_jump_jitter,
                 "Half-width of the square around the neighbour's neighbour in which a jump "
                 "lands, m")
      ->check(PositiveValue())
      ->capture_default_str();
  cmd.add_option("--delayed-acceptance", m.sampler.screen_stride,
                 "Screen each move on every K-th reading first (their log-likelihood times K) and "
                 "evaluate all the data only for moves that pass; the posterior is unchanged, "
                 "most rejections cost 1/K (1: off)")
      ->check(CLI::Range(1, 1024))
      ->capture_default_str();
  cmd.add_option("--thinned-burn-in", cli.thinned_burn_in,
                 "Burn-in stages on 1/STRIDE of the readings first, STEPS each (counted in the "
                 "burn-in), e.g. 16:1000000,4:500000")
      ->delimiter(',')
      ->check(ParsedBy("--thinned-burn-in", ParseStage));
  cmd.add_option("--thinned-rotation", m.thinned_rotation,
                 "Every STEPS steps of a thinned stage, go on with the next of its STRIDE "
                 "disjoint shares of the readings, so that no one share's posterior holds the "
                 "chain (0: one share per stage)")
      ->capture_default_str();
  cmd.add_flag("--thinned-weighed", m.thinned_weighed,
               "Count each reading of a thinned stage STRIDE times, so that the stage estimates "
               "the full data's log-likelihood instead of tempering it as T = STRIDE would");
  cmd.add_option("--warm-burn-in", cli.warm_burn_in,
                 "After the thinned stages, STEPS burn-in steps on every reading at temperature "
                 "T (counted in the burn-in; the rest of it is at 1), to let a chain leave a "
                 "wrong structure once all the data weigh in, e.g. 2:400000 (docs/benchmarks.md "
                 "measures when that works)")
      ->check(ParsedBy("--warm-burn-in", ParseWarmStage));
}

void ApplyPosteriorOptions(const PosteriorCliOptions& cli, prf::MappingOptions* m) {
  m->replica_pick_best = cli.replica_pick == "best";
  m->sampler.orientation.angle = cli.orientation_deg * std::numbers::pi / 180.0;
  if (!std::isfinite(m->sampler.orientation.angle))
    throw UserError("--orientation must be a finite angle");
  if (!cli.thinned_burn_in.empty()) {
    m->thinned_burn_in.clear();
    for (const std::string& text : cli.thinned_burn_in)
      m->thinned_burn_in.push_back(ParseStage(text));
  }
  if (!cli.warm_burn_in.empty()) m->warm_burn_in = ParseWarmStage(cli.warm_burn_in);
  RequireConsistentPosteriorOptions(*m);
}
void RequireConsistentPosteriorOptions(const prf::MappingOptions& m) {
  if (m.burn_in_replicas > 1 && !(m.replica_temperature > 1.0))
    throw UserError("--replica-temperature must be above 1 for more than one replica");
  if (m.sampler.corner_completion + m.sampler.neighbour_birth >= 1.0)
    throw UserError(fmt::format(
        "--corner-completion {} and --neighbour-births {} sum to 1 or more; a vertex birth "
        "needs a share for its rectangles",
        m.sampler.corner_completion, m.sampler.neighbour_birth));
  if (m.replica_steps > m.burn_in)
    throw UserError(fmt::format("--replica-steps: {} steps, more than the burn-in's {}",
                                m.replica_steps, m.burn_in));
  std::uint64_t steps = 0;
  for (const prf::ThinnedBurnIn& stage : m.thinned_burn_in)  // saturating: no wrap to pass
    steps += std::min(stage.steps, std::numeric_limits<std::uint64_t>::max() - steps);
  if (steps > m.burn_in)
    throw UserError(fmt::format(
        "--thinned-burn-in: the stages take {} steps, more than the burn-in's {} (they are part "
        "of it)",
        steps, m.burn_in));
  if (m.warm_burn_in.steps > m.burn_in - steps)
    throw UserError(fmt::format(
        "--warm-burn-in: {} steps after the thinned stages' {}, more than the burn-in's {} (they "
        "are part of it)",
        m.warm_burn_in.steps, steps, m.burn_in));
}

nlohmann::json PosteriorOptionsJson(const prf::MappingOptions& m) {
  nlohmann::json j = prf::SamplingOptionsJson(m);
  j["orientation_deg"] = m.sampler.orientation.angle * 180.0 / std::numbers::pi;
  // And bit for bit: degrees read back do not always give the same radians, which a resumed
  // run's checkpoints must match (they hold a fingerprint of the options).
  j["orientation_rad"] = m.sampler.orientation.angle;
  return j;
}

void PosteriorOptionsFromJson(const nlohmann::json& j, prf::MappingOptions* m) {
  m->sampler.free_space = j.value("free_space", 0.0);
  m->sampler.orientation.weight = j.value("orientation_weight", 0.0);
  m->sampler.orientation.angle = j.contains("orientation_rad")
                                     ? j.at("orientation_rad").get<double>()
                                     : j.value("orientation_deg", 0.0) * std::numbers::pi / 180.0;
  m->burn_in_temperature = j.value("burn_in_temperature", 1.0);
  m->burn_in_replicas = WholeNumberMember<int>(j, "burn_in_replicas", 1);
  m->replica_temperature = j.value("replica_temperature", 4.0);
  m->replica_steps = WholeNumberMember<std::uint64_t>(j, "replica_steps", 0);
  m->replica_pick_best = j.value("replica_pick", std::string("cold")) == "best";
  m->sampler.screen_stride = WholeNumberMember<int>(j, "delayed_acceptance", 1);
  m->sampler.weights[prf::MoveKind::kEdgeShift] = j.value("edge_shifts", 0.0);
  m->sampler.step_scales = j.value("step_scales", m->sampler.step_scales);
  m->sampler.vertex_birth_widths = j.value("vertex_birth_widths", m->sampler.vertex_birth_widths);
  if (j.contains("corner_completion")) {
    const nlohmann::json& corner = j.at("corner_completion");
    m->sampler.corner_completion = corner.value("probability", 0.0);
    m->sampler.corner_completion_jitter =
        corner.value("jitter", m->sampler.corner_completion_jitter);
  }
  if (j.contains("neighbour_birth")) {
    const nlohmann::json& neighbour = j.at("neighbour_birth");
    m->sampler.neighbour_birth = neighbour.value("probability", 0.0);
    m->sampler.neighbour_birth_jitter =
        neighbour.value("jitter", m->sampler.neighbour_birth_jitter);
  }
  if (j.contains("vertex_jump")) {
    const nlohmann::json& jump = j.at("vertex_jump");
    m->sampler.weights[prf::MoveKind::kVertexJump] = jump.value("weight", 0.0);
    m->sampler.vertex_jump_reach = jump.value("reach", m->sampler.vertex_jump_reach);
    m->sampler.vertex_jump_jitter = jump.value("jitter", m->sampler.vertex_jump_jitter);
  }
  m->sampler.weights[prf::MoveKind::kVertexPair] = j.value("vertex_pairs", 0.0);
  m->thinned_burn_in.clear();
  if (j.contains("thinned_burn_in"))
    for (const nlohmann::json& stage : j.at("thinned_burn_in"))
      m->thinned_burn_in.push_back({WholeNumberMember<int>(stage, "stride"),
                                    WholeNumberMember<std::uint64_t>(stage, "steps")});
  m->thinned_rotation = WholeNumberMember<std::uint64_t>(j, "thinned_rotation", 0);
  m->thinned_weighed = j.value("thinned_weighed", false);
  m->warm_burn_in = {};
  if (j.contains("warm_burn_in"))
    m->warm_burn_in = {j.at("warm_burn_in").at("temperature").get<double>(),
                       WholeNumberMember<std::uint64_t>(j.at("warm_burn_in"), "steps")};
}

}  // namespace priormap::app
