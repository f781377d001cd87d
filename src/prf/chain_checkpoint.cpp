#include <algorithm>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include <fmt/format.h>

#include <priormap/core/binary_io.hpp>
#include <priormap/core/file_io.hpp>
#include <priormap/prf/chain_checkpoint.hpp>
#include <priormap/prf/mapping.hpp>

namespace priormap::prf {
namespace {

// 2: the coloring statistics of the orientation prior, the black area of the free-space one.
// 3: a chain's burn-in replicas and swap counts.
// 4: the counters of the edge shift; delayed acceptance's screened-out counts.
// 5: which chain a chain checkpoint holds.
constexpr std::uint32_t kFormatVersion = 5;
constexpr std::string_view kChainKind = "PRFCHAIN";
constexpr std::string_view kAnnealKind = "PRFANNEA";

void PutVec(BinaryWriter& out, const Vec2& v) {
  out.Put(v.x());
  out.Put(v.y());
}

// The beams and sensors as both fingerprints hash them.
void PutLaserData(BinaryWriter& out, const LaserData& data) {
  out.Put(data.max_range);
  out.Put<std::uint64_t>(data.sensors.size());
  for (const Vec2& s : data.sensors) PutVec(out, s);
  out.Put<std::uint64_t>(data.beams.size());
  for (const LaserBeam& b : data.beams) {
    PutVec(out, b.origin);
    PutVec(out, b.direction);
    out.Put(b.range);
    out.Put<std::uint8_t>(b.max_reading ? 1 : 0);
    out.Put<std::int32_t>(b.sensor);
  }
}

std::string ReadWhole(const std::filesystem::path& path) {
  Result<std::string> bytes = ReadFileText(path);
  if (!bytes.ok())
    throw CheckpointReadError(bytes.error() +
                              "; the checkpoint is kept: make it a file priormap can read and "
                              "resume again");
  return std::move(bytes).value();
}

// The version a sealed file's header names (the 32-bit word after its 8-character kind), when
// the file starts as one of `kind`.
std::optional<std::uint32_t> SealedVersion(std::string_view bytes, std::string_view kind) {
  constexpr std::size_t kKindSize = 8;
  std::string kind_field(kind.substr(0, kKindSize));
  kind_field.resize(kKindSize, ' ');
  if (bytes.size() < kKindSize + 4 || bytes.substr(0, kKindSize) != kind_field) return std::nullopt;
  return BinaryReader(bytes.substr(kKindSize, 4), "header").Get<std::uint32_t>();
}

// Whether `bytes` are a whole sealed file of `kind` and `version` (size and checksum agree).
bool IsWholeSealed(std::string_view bytes, std::string_view kind, std::uint32_t version) {
  try {
    (void)UnsealBinary(bytes, kind, version, "");
    return true;
  } catch (const BinaryFormatError&) {
    return false;
  }
}

// The sealed payload's reader, past the fingerprint (checked).
BinaryReader OpenPayload(std::string_view bytes, std::string_view kind,
                         const std::filesystem::path& path, std::uint64_t fingerprint) {
  const std::string what = path.string();
  std::string_view payload;
  try {
    payload = UnsealBinary(bytes, kind, kFormatVersion, what);
  } catch (const BinaryFormatError&) {
    // A whole checkpoint of another version, earlier or later (another priormap wrote it), is
    // told from a damaged one, which the command would have the user remove.
    const std::optional<std::uint32_t> version = SealedVersion(bytes, kind);
    if (!version || *version == kFormatVersion || !IsWholeSealed(bytes, kind, *version))
      throw;  // damaged, or not a checkpoint
    throw CheckpointMismatchError(
        CheckpointMismatchError::Reason::kFormatVersion,
        fmt::format("{}: a checkpoint of version {} of the format, which {} priormap wrote; this "
                    "one reads version {}",
                    what, *version, *version < kFormatVersion ? "an earlier" : "a later",
                    kFormatVersion));
  }
  BinaryReader in(payload, what);
  if (in.Get<std::uint64_t>() != fingerprint)
    throw CheckpointMismatchError(
        CheckpointMismatchError::Reason::kAnotherRun,
        fmt::format("{}: a checkpoint of another run (its data or options differ from this one's)",
                    what));
  return in;
}

// The chains of a run differ only in their seeds, so a checkpoint swapped with another chain's,
// or copied over it, would pass every other check and continue as a duplicate chain.
void RequireChain(std::uint64_t held, std::size_t expected, const std::filesystem::path& path) {
  if (held != expected)
    throw CheckpointMismatchError(
        CheckpointMismatchError::Reason::kAnotherChain,
        fmt::format("{}: a checkpoint of chain {}, expected chain {} (checkpoints swapped or "
                    "copied?)",
                    path.string(), held, expected));
}

// Whether `name` is a checkpoint's own: "chain-K.ckpt" (ChainCheckpointPath) or "anneal.ckpt".
bool IsCheckpointName(std::string_view name) {
  return IsNumberedName(name, "chain-", ".ckpt", /*allow_leading_zeros=*/false) ||
         name == "anneal.ckpt";
}

// Whether `name` is that of a temporary file of WriteFileAtomically (".NAME.tmp-PID-N") for a
// checkpoint's NAME.
bool IsCheckpointTemporaryName(std::string_view name) {
  constexpr std::string_view kMarker = ".tmp-";
  const std::size_t marker = name.rfind(kMarker);
  if (!name.starts_with('.') || marker == std::string_view::npos || marker < 2) return false;
  const std::string_view numbers = name.substr(marker + kMarker.size());
  const std::size_t dash = numbers.find('-');
  return dash != std::string_view::npos &&
         IsNumberedName(numbers.substr(0, dash), "", "", /*allow_leading_zeros=*/false) &&
         IsNumberedName(numbers.substr(dash + 1), "", "", /*allow_leading_zeros=*/false) &&
         IsCheckpointName(name.substr(1, marker - 1));
}

void WriteSealed(const std::filesystem::path& path, std::string_view kind,
                 const BinaryWriter& payload) {
  WriteTextFileAtomically(path, SealBinary(kind, kFormatVersion, payload.bytes()));
}

}  // namespace

std::uint64_t LaserDataFingerprint(const LaserData& data, const LaserModel& model) {
  BinaryWriter out;
  PutLaserData(out, data);
  for (double v : {model.sigma, model.hit_weight, model.outlier_weight, model.max_weight})
    out.Put(v);
  return Fnv1a64(out.bytes());
}

std::uint64_t RunFingerprint(const LaserData& data, const MappingOptions& options) {
  BinaryWriter out;
  PutLaserData(out, data);
  const SamplerOptions& s = options.sampler;
  out.Put(s.p);
  // The Arak process (no orientation prior) hashes as before this option existed.
  if (s.orientation.weight != 0.0) {
    out.Put(s.orientation.weight);
    out.Put(s.orientation.angle);
  }
  if (!options.thinned_burn_in.empty()) {
    out.PutString("thinned burn-in");
    for (const ThinnedBurnIn& stage : options.thinned_burn_in) {
      out.Put<std::int32_t>(stage.stride);
      out.Put(stage.steps);
    }
    // Only when on, so that checkpoints of runs from before these options still resume.
    if (options.thinned_rotation != 0) {
      out.PutString("rotated");
      out.Put(options.thinned_rotation);
    }
    if (options.thinned_weighed) out.PutString("weighed");
  }
  if (options.burn_in_temperature != 1.0) {
    out.PutString("burn-in temperature");
    out.Put(options.burn_in_temperature);
  }
  if (const WarmStage warm = WarmStageOf(options); warm.end > warm.begin) {
    out.PutString("warm burn-in");
    out.Put(options.warm_burn_in.temperature);
    out.Put(options.warm_burn_in.steps);
  }
  if (s.free_space != 0.0) {
    out.PutString("free space");
    out.Put(s.free_space);
  }
  if (options.burn_in_replicas != 1) {
    out.PutString("burn-in replicas");
    out.Put<std::int32_t>(options.burn_in_replicas);
    out.Put(options.replica_temperature);
    out.Put(options.replica_steps);
    if (options.replica_pick_best) out.PutString("pick the best replica");
  }
  if (s.screen_stride != 1) {
    out.PutString("delayed acceptance");
    out.Put<std::int32_t>(s.screen_stride);
  }
  // The weights of the kinds there were before vertex jumps, and the jumps' and pairs' only when
  // on, so that checkpoints of runs without them still resume.
  for (int k = 0; k < kNumMoveKindsBeforeJumps; ++k)
    out.Put(s.weights.weight[static_cast<std::size_t>(k)]);
  if (s.weights[MoveKind::kVertexJump] > 0.0) {
    out.PutString("vertex jumps");
    out.Put(s.weights[MoveKind::kVertexJump]);
    out.Put(s.vertex_jump_reach);
    out.Put(s.vertex_jump_jitter);
  }
  if (s.weights[MoveKind::kVertexPair] > 0.0) {
    out.PutString("vertex pairs");
    out.Put(s.weights[MoveKind::kVertexPair]);
  }
  out.Put(s.birth_scale);
  out.PutVector(s.vertex_birth_widths);
  // Only when on, so that checkpoints of runs without corner completion still resume.
  if (s.corner_completion > 0.0) {
    out.PutString("corner completion");
    out.Put(s.corner_completion);
    out.Put(s.corner_completion_jitter);
  }
  if (s.neighbour_birth > 0.0) {
    out.PutString("neighbour births");
    out.Put(s.neighbour_birth);
    out.Put(s.neighbour_birth_jitter);
  }
  out.PutVector(s.step_scales);
  const LaserModel& m = options.model;
  for (double v :
       {m.sigma, m.hit_weight, m.outlier_weight, m.max_weight, options.cell_size, options.margin,
        options.raster_resolution, options.anneal_final_temperature, options.guide_jitter})
    out.Put(v);
  for (std::uint64_t v :
       {options.samples, options.burn_in, options.seed, options.trace_every, options.anneal_steps})
    out.Put(v);
  out.Put<std::int32_t>(options.chains);
  out.Put<std::int32_t>(options.trace_points);
  return Fnv1a64(out.bytes());
}

std::filesystem::path ChainCheckpointPath(const std::filesystem::path& directory,
                                          std::size_t chain) {
  return directory / fmt::format("chain-{}.ckpt", chain);
}

std::filesystem::path AnnealCheckpointPath(const std::filesystem::path& directory) {
  return directory / "anneal.ckpt";
}

std::size_t RemoveStaleCheckpointTemporaries(const std::filesystem::path& directory) {
  // The names of ChainCheckpointPath and AnnealCheckpointPath only: the directory may hold
  // other files of the caller's.
  return RemoveStaleTemporaryFiles(directory, IsCheckpointName).size();
}

std::size_t RemoveCheckpointTemporariesOfEndedWriters(const std::filesystem::path& directory) {
  std::vector<std::filesystem::path> stale;
  std::error_code ec;
  for (std::filesystem::directory_iterator it(directory, ec), end; !ec && it != end;
       it.increment(ec)) {
    std::error_code status_error;
    if (IsCheckpointTemporaryName(it->path().filename().string()) &&
        it->symlink_status(status_error).type() == std::filesystem::file_type::regular)
      stale.push_back(it->path());
  }
  // Removed after the listing, which removing entries during it might skip or repeat.
  std::size_t removed = 0;
  for (const std::filesystem::path& file : stale)
    if (std::filesystem::remove(file, ec)) ++removed;
  return removed;
}

void SaveChainCheckpoint(const std::filesystem::path& path, std::uint64_t fingerprint,
                         std::size_t chain, const PrfSampler& sampler,
                         std::span<const PrfSampler* const> hot,
                         const PosteriorEstimates* estimates, const ChainSummary& summary) {
  BinaryWriter out;
  out.Put(fingerprint);
  out.Put<std::uint64_t>(chain);
  sampler.Save(out);
  out.Put<std::uint64_t>(hot.size());
  for (const PrfSampler* replica : hot) replica->Save(out);
  out.Put<std::uint8_t>(estimates ? 1 : 0);
  if (estimates) estimates->Save(out);
  out.PutVector(summary.log_posterior_trace);
  out.Put<std::uint64_t>(summary.point_traces.size());
  for (const std::vector<double>& trace : summary.point_traces) out.PutVector(trace);
  out.Put<std::uint64_t>(summary.swaps.size());
  for (const SwapCounter& swaps : summary.swaps) {
    out.Put(swaps.proposed);
    out.Put(swaps.accepted);
  }
  WriteSealed(path, kChainKind, out);
}

LoadedChain LoadChainCheckpoint(const std::filesystem::path& path, std::uint64_t fingerprint,
                                std::size_t expected_chain, const Window& window,
                                const MappingOptions& options,
                                const std::function<std::unique_ptr<DataTerm>()>& make_data,
                                PosteriorEstimates* estimates, ChainSummary* summary) {
  const std::string bytes = ReadWhole(path);
  BinaryReader in = OpenPayload(bytes, kChainKind, path, fingerprint);
  RequireChain(in.Get<std::uint64_t>(), expected_chain, path);
  LoadedChain chain;
  chain.sampler = PrfSampler::Load(in, window, options.cell_size, options.sampler, make_data());
  // K − 1: the most hot replicas, and the pairs of adjacent rungs.
  const auto pairs = static_cast<std::uint64_t>(std::max(options.burn_in_replicas, 1)) - 1;
  const std::uint64_t hot = in.GetCount(pairs, "replicas");
  for (std::uint64_t k = 0; k < hot; ++k) {
    chain.hot.push_back(
        PrfSampler::Load(in, window, options.cell_size, options.sampler, make_data()));
    if (chain.hot.back()->steps() != chain.sampler->steps())
      in.Fail("a replica out of step with its chain");
  }
  chain.recording = in.Get<std::uint8_t>() != 0;
  if (chain.recording) estimates->Load(in);
  summary->log_posterior_trace = in.GetVector<double>();
  if (in.Get<std::uint64_t>() != summary->point_traces.size())
    in.Fail("traces of another set of points");
  for (std::vector<double>& trace : summary->point_traces) trace = in.GetVector<double>();
  summary->swaps.resize(in.GetCount(pairs, "swap counters"));
  for (SwapCounter& swaps : summary->swaps) {
    swaps.proposed = in.Get<std::uint64_t>();
    swaps.accepted = in.Get<std::uint64_t>();
    if (swaps.accepted > swaps.proposed) in.Fail("more swaps accepted than offered");
  }
  if (!in.AtEnd()) in.Fail("data after the chain's state");
  return chain;
}

void SaveAnnealCheckpoint(const std::filesystem::path& path, std::uint64_t fingerprint,
                          std::size_t chain, const PrfSampler& sampler) {
  BinaryWriter out;
  out.Put(fingerprint);
  out.Put<std::uint64_t>(chain);
  sampler.Save(out);
  WriteSealed(path, kAnnealKind, out);
}

LoadedAnneal LoadAnnealCheckpoint(const std::filesystem::path& path, std::uint64_t fingerprint,
                                  const Window& window, const MappingOptions& options,
                                  std::unique_ptr<DataTerm> data) {
  const std::string bytes = ReadWhole(path);
  BinaryReader in = OpenPayload(bytes, kAnnealKind, path, fingerprint);
  LoadedAnneal anneal;
  anneal.chain = in.GetCount(static_cast<std::uint64_t>(options.chains) - 1, "chains");
  anneal.sampler =
      PrfSampler::Load(in, window, options.cell_size, options.sampler, std::move(data));
  if (!in.AtEnd()) in.Fail("data after the chain's state");
  return anneal;
}

}  // namespace priormap::prf
