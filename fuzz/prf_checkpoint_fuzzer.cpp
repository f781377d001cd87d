// libFuzzer harness for the chain checkpoints `priormap prf --resume DIR` reads
// (LoadChainCheckpoint: DIR/checkpoints/chain-K.ckpt), past the seal, the run's fingerprint and
// the chain's index that guard whole files, so that damaged or hostile data reach the loader:
// the input is the payload after the fingerprint and the index, sealed by the harness as the
// writer seals it. The run is a small laser run of one chain with a two-replica ladder through
// its burn-in; at start the harness runs it to a checkpoint to learn the seal's kind and version,
// the fingerprint and the index (with PRIORMAP_FUZZ_WRITE_SEEDS=DIR it also writes the payloads
// of checkpoints taken in the burn-in and while recording there: the seed corpus). Besides
// crashes and sanitizer reports it checks that a refused checkpoint is a BinaryFormatError (what
// the command reports as "cannot resume"), never another exception, and that a chain loaded is
// valid (its coloring, replicas in step, swap counts) and saves to a checkpoint that loads back
// and saves to the same bytes.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <priormap/core/binary_io.hpp>
#include <priormap/prf/chain_checkpoint.hpp>
#include <priormap/prf/estimates.hpp>
#include <priormap/prf/mapping.hpp>

#include "fuzz_check.hpp"
#include "fuzz_scratch.hpp"

using priormap::fuzz::Check;
using priormap::prf::ChainSummary;
using priormap::prf::LoadedChain;
using priormap::prf::PosteriorEstimates;
using priormap::prf::PrfSampler;
namespace fs = std::filesystem;

namespace {

// Twelve beams from each of two sensors inside a 3 m square room.
std::shared_ptr<const priormap::prf::LaserData> Room() {
  auto data = std::make_shared<priormap::prf::LaserData>();
  data->max_range = 8.0;
  data->sensors = {priormap::Vec2(0.0, 0.0), priormap::Vec2(0.5, 0.25)};
  for (int s = 0; s < 2; ++s)
    for (int k = 0; k < 12; ++k) {
      priormap::prf::LaserBeam beam;
      beam.origin = data->sensors[static_cast<std::size_t>(s)];
      const double angle = 0.1 + k * 0.5236;
      beam.direction = priormap::Vec2(std::cos(angle), std::sin(angle));
      double range = data->max_range;
      for (int axis = 0; axis < 2; ++axis)
        if (beam.direction[axis] != 0.0)
          range = std::min(range, ((beam.direction[axis] > 0 ? 1.5 : -1.5) - beam.origin[axis]) /
                                      beam.direction[axis]);
      beam.range = range;
      beam.sensor = s;
      data->beams.push_back(beam);
    }
  return data;
}

priormap::prf::MappingOptions Options() {
  priormap::prf::MappingOptions options;
  options.burn_in = 40;
  options.samples = 40;
  options.chains = 1;
  options.trace_every = 10;
  options.trace_points = 2;
  options.cell_size = 1.0;
  options.raster_resolution = 1.0;
  options.burn_in_replicas = 2;
  options.chunk = 10;
  return options;
}

struct Run {
  priormap::prf::MappingOptions options = Options();
  priormap::prf::MappingData data = priormap::prf::LaserMappingData(Room(), options);
  std::string kind;  // the seal's kind and version, as the writer seals
  std::uint32_t version = 0;
  // The payload's first 16 bytes: the run's fingerprint and the chain's index (0).
  std::string stamp;
  // The payloads (after the stamp) of the checkpoints the run wrote, with short random
  // generator states: the seed corpus.
  std::vector<std::string> seed_payloads;
};

// Runs the chain for `steps` steps from scratch, checkpointed in `dir`; the chain's checkpoint.
std::string CheckpointAfter(const Run& run, std::uint64_t steps, const fs::path& dir) {
  fs::remove_all(dir);
  const priormap::prf::MappingSession session{
      .checkpoint_directory = dir, .checkpoint_every_s = 1e9, .stop_after_steps = steps};
  (void)priormap::prf::RunMapping(
      run.data, run.options, [](const auto&) {}, session);
  return priormap::fuzz::ReadBytes(priormap::prf::ChainCheckpointPath(dir, 0));
}

constexpr std::size_t kKindSize = 8, kHeaderSize = 8 + 4 + 8 + 8, kStampSize = 8 + 8;

// `payload` with each random generator's state (a Mersenne Twister's 312 words and index as
// text, some 6 KB: a string of digits and spaces after its length) replaced by a short valid
// one, so that the seeds stay small.
std::string ShortenGeneratorStates(std::string payload) {
  std::string short_state = "1";
  for (int i = 1; i < 312; ++i) short_state += " 1";
  short_state += " 312";
  for (std::size_t i = 0; i + 8 <= payload.size(); ++i) {
    std::uint64_t length = 0;
    std::memcpy(&length, payload.data() + i, sizeof length);
    if (length < 1000 || length > payload.size() - i - 8) continue;
    const std::string_view text = std::string_view(payload).substr(i + 8, length);
    if (text.find_first_not_of("0123456789 ") != std::string_view::npos) continue;
    const std::uint64_t short_length = short_state.size();
    payload.replace(i, 8 + length,
                    std::string(reinterpret_cast<const char*>(&short_length), 8) + short_state);
    i += 8 + short_state.size() - 1;
  }
  return payload;
}

const Run& SetUp() {
  static const Run run = [] {
    Run r;
    const fs::path dir = priormap::fuzz::Scratch().path() / "checkpoints";
    // In the burn-in (with the hot replica) and while recording.
    for (const std::uint64_t steps : {std::uint64_t{20}, std::uint64_t{60}}) {
      const std::string sealed = CheckpointAfter(r, steps, dir);
      Check(sealed.size() >= kHeaderSize + kStampSize, "the run writes a checkpoint");
      r.kind = sealed.substr(0, kKindSize);
      std::memcpy(&r.version, sealed.data() + kKindSize, sizeof r.version);
      r.stamp = sealed.substr(kHeaderSize, kStampSize);
      Check(priormap::SealBinary(r.kind, r.version, sealed.substr(kHeaderSize)) == sealed,
            "the harness seals a checkpoint as the writer does");
      r.seed_payloads.push_back(ShortenGeneratorStates(sealed.substr(kHeaderSize + kStampSize)));
    }
    fs::remove_all(dir);
    return r;
  }();
  return run;
}

struct Loaded {
  LoadedChain chain;
  std::unique_ptr<PosteriorEstimates> estimates;
  ChainSummary summary;
};

// The chain in the checkpoint `sealed`, or nullopt when the loader refuses it as it should.
std::optional<Loaded> Load(const Run& run, std::string_view sealed, const std::string& name) {
  const fs::path path = priormap::fuzz::Scratch().Write(name, sealed);
  Loaded loaded;
  loaded.estimates =
      std::make_unique<PosteriorEstimates>(run.data.window, run.options.raster_resolution);
  loaded.summary.point_traces.assign(run.data.trace_points.size(), {});
  std::uint64_t fingerprint = 0;
  std::memcpy(&fingerprint, run.stamp.data(), sizeof fingerprint);
  try {
    loaded.chain = priormap::prf::LoadChainCheckpoint(path, fingerprint, 0, run.data.window,
                                                      run.options, run.data.make_data_term,
                                                      loaded.estimates.get(), &loaded.summary);
  } catch (const priormap::BinaryFormatError&) {
    return std::nullopt;
  } catch (const std::exception& e) {
    Check(false, "LoadChainCheckpoint throws BinaryFormatError only", e.what());
  }
  return loaded;
}

// The checkpoint the writer makes of `loaded`.
std::string Save(const Run& run, const Loaded& loaded, const std::string& name) {
  const fs::path path = priormap::fuzz::Scratch().path() / name;
  std::vector<const PrfSampler*> hot;
  for (const auto& replica : loaded.chain.hot) hot.push_back(replica.get());
  std::uint64_t fingerprint = 0;
  std::memcpy(&fingerprint, run.stamp.data(), sizeof fingerprint);
  priormap::prf::SaveChainCheckpoint(path, fingerprint, 0, *loaded.chain.sampler, hot,
                                     loaded.chain.recording ? loaded.estimates.get() : nullptr,
                                     loaded.summary);
  return priormap::fuzz::ReadBytes(path);
}

}  // namespace

// Checks that the seeds load (else the run's setup or the seal changed and the harness would
// fuzz nothing); with PRIORMAP_FUZZ_WRITE_SEEDS=DIR, writes them into DIR.
extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  const Run& run = SetUp();
  const char* seeds = std::getenv("PRIORMAP_FUZZ_WRITE_SEEDS");
  for (std::size_t k = 0; k < run.seed_payloads.size(); ++k) {
    const std::string& payload = run.seed_payloads[k];
    const std::optional<Loaded> loaded =
        Load(run, priormap::SealBinary(run.kind, run.version, run.stamp + payload), "seed.ckpt");
    Check(loaded.has_value(), "a seed loads");
    // The first in the burn-in, with its hot replica; the second recording.
    Check(loaded->chain.hot.size() == (k == 0 ? 1 : 0) && loaded->chain.recording == (k == 1),
          "the seeds are of the burn-in's ladder and of the recording");
    if (seeds == nullptr) continue;
    std::ofstream out(fs::path(seeds) / ("chain-" + std::to_string(k)), std::ios::binary);
    out << payload;
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const Run& run = SetUp();
  const std::string payload = run.stamp + std::string(reinterpret_cast<const char*>(data), size);
  const std::optional<Loaded> loaded =
      Load(run, priormap::SealBinary(run.kind, run.version, payload), "chain-0.ckpt");
  if (!loaded) return 0;

  const std::uint64_t pairs = static_cast<std::uint64_t>(run.options.burn_in_replicas) - 1;
  Check(loaded->chain.sampler != nullptr, "a loaded chain has its sampler");
  const auto violation = loaded->chain.sampler->coloring().FindInvariantViolation(1e-6);
  Check(!violation, "a loaded chain's coloring is valid", violation.value_or(""));
  Check(loaded->chain.hot.size() <= pairs, "no more replicas than the ladder has");
  for (const auto& replica : loaded->chain.hot)
    Check(replica->steps() == loaded->chain.sampler->steps(), "replicas in step with the chain");
  Check(loaded->summary.swaps.size() <= pairs, "no more swap counts than the ladder has");
  for (const auto& swaps : loaded->summary.swaps)
    Check(swaps.accepted <= swaps.proposed, "no more swaps accepted than offered");

  const std::string saved = Save(run, *loaded, "saved.ckpt");
  const std::optional<Loaded> again = Load(run, saved, "again.ckpt");
  Check(again.has_value(), "a saved chain loads again");
  Check(Save(run, *again, "saved-again.ckpt") == saved, "a saved chain loads the same");
  return 0;
}
