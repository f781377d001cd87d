// Checkpoints: the binary encoding refuses damaged data; a saved coloring, sampler and mapping
// run continue exactly as the originals would have.
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <unistd.h>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <priormap/core/binary_io.hpp>
#include <priormap/core/range_sensor.hpp>
#include <priormap/core/rng.hpp>
#include <priormap/core/scene.hpp>
#include <priormap/core/simulate.hpp>
#include <priormap/prf/chain_checkpoint.hpp>
#include <priormap/prf/laser_likelihood.hpp>
#include <priormap/prf/mapping.hpp>
#include <priormap/prf/sampler.hpp>

#include "mapping_testing.hpp"
#include "testing/ended_process.hpp"
#include "testing/temp_dir.hpp"

namespace priormap::prf {
namespace {

using ::testing::HasSubstr;

const Window kUnit{Vec2::Zero(), Vec2::Ones()};

std::string Saved(const PrfSampler& sampler) {
  BinaryWriter out;
  sampler.Save(out);
  return out.TakeBytes();
}

SamplerOptions PriorOptions() {
  SamplerOptions options;
  options.p = 3.0;
  options.birth_scale = 0.3;
  return options;
}

// A short run on RoomData: `steps` of burn-in and as many recorded, chunks of 500 steps.
MappingOptions ShortRun(std::uint64_t steps, int chains, std::uint64_t anneal_steps = 0) {
  MappingOptions options;
  options.sampler.p = 0.5;
  options.samples = steps;
  options.burn_in = steps;
  options.chains = chains;
  options.trace_every = 500;
  options.anneal_steps = anneal_steps;
  options.chunk = 500;
  return options;
}

// The format version of a sealed file: the 32-bit word after the 8-character kind (SealBinary's
// header).
std::uint32_t SealedVersion(const std::string& bytes) {
  return BinaryReader(std::string_view(bytes).substr(8), "header").Get<std::uint32_t>();
}

TEST(BinaryIo, SealedDataRoundTripsAndDamageIsRefused) {
  BinaryWriter out;
  out.Put(1.5);
  out.PutVector(std::vector<std::int32_t>{3, -1, 7});
  out.PutString("chain");
  const std::string sealed = SealBinary("TESTKIND", 2, out.bytes());

  BinaryReader in(UnsealBinary(sealed, "TESTKIND", 2, "t"), "t");
  EXPECT_EQ(in.Get<double>(), 1.5);
  EXPECT_EQ(in.GetVector<std::int32_t>(), (std::vector<std::int32_t>{3, -1, 7}));
  EXPECT_EQ(in.GetString(), "chain");
  EXPECT_TRUE(in.AtEnd());
  EXPECT_THROW((void)in.Get<std::uint8_t>(), BinaryFormatError);

  const auto refused = [&](std::string bytes, std::string_view kind, std::uint32_t version) {
    try {
      (void)UnsealBinary(bytes, kind, version, "t");
    } catch (const BinaryFormatError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_THAT(refused(sealed, "OTHERKND", 2), HasSubstr("not a OTHERKND file"));
  EXPECT_THAT(refused(sealed, "TESTKIND", 3), HasSubstr("version 2"));
  EXPECT_THAT(refused(sealed.substr(0, sealed.size() - 1), "TESTKIND", 2), HasSubstr("truncated"));
  std::string flipped = sealed;
  flipped.back() ^= 1;
  EXPECT_THAT(refused(flipped, "TESTKIND", 2), HasSubstr("checksum"));

  // A generator state of all zeros (a fixed point no seed reaches) is refused.
  BinaryWriter zero_state;
  std::string zeros;
  for (int i = 0; i < 312; ++i) zeros += "0 ";
  zero_state.PutString(zeros + "0");
  zero_state.Put(0.0);
  zero_state.Put<std::uint8_t>(0);
  BinaryReader zero_in(zero_state.bytes(), "rng");
  Rng rng(1);
  EXPECT_THROW(rng.Load(zero_in), BinaryFormatError);

  // A length beyond the data is refused before anything is allocated.
  BinaryWriter lying;
  lying.Put<std::uint64_t>(std::uint64_t{1} << 60);
  BinaryReader short_in(lying.bytes(), "t");
  EXPECT_THROW((void)short_in.GetVector<double>(), BinaryFormatError);
}

// With the default kinds, and with vertex jumps or vertex pairs on, whose counters a chain
// saves only when they are on.
TEST(Checkpoint, ASavedSamplerContinuesExactly) {
  std::vector<std::pair<std::string, SamplerOptions>> variants{{"default kinds", PriorOptions()}};
  for (const MoveKind extra : {MoveKind::kVertexJump, MoveKind::kVertexPair}) {
    SamplerOptions options = PriorOptions();
    options.weights[extra] = 1.0;
    variants.emplace_back(MoveKindName(extra), options);
  }
  for (const auto& [name, options] : variants) {
    PrfSampler original(Coloring(kUnit, 1.0 / 8.0), options, 11);
    original.Run(20000);
    BinaryWriter out;
    original.Save(out);
    BinaryReader in(out.bytes(), "sampler");
    const std::unique_ptr<PrfSampler> restored = PrfSampler::Load(in, kUnit, 1.0 / 8.0, options);
    EXPECT_TRUE(in.AtEnd()) << name;
    EXPECT_EQ(Saved(*restored), out.bytes()) << name;
    ASSERT_GT(original.coloring().stats().edges, 10);
    original.Run(20000);
    restored->Run(20000);
    EXPECT_EQ(Saved(*restored), Saved(original)) << name;
    EXPECT_FALSE(restored->coloring().FindInvariantViolation());
  }
}

TEST(Checkpoint, AColoringOfAnotherWindowOrDamagedIsRefused) {
  PrfSampler sampler(Coloring(kUnit, 1.0 / 8.0), PriorOptions(), 5);
  sampler.Run(5000);
  const std::string bytes = Saved(sampler);
  {
    BinaryReader in(bytes, "c");
    EXPECT_THROW((void)Coloring::Load(in, Window{Vec2::Zero(), Vec2(2.0, 1.0)}, 1.0 / 8.0),
                 BinaryFormatError);
  }
  // Every single-byte corruption of the coloring's part is refused or gives a valid coloring
  // (a changed length or angle cache may still describe one).
  const std::size_t coloring_size = [&] {
    BinaryWriter out;
    sampler.coloring().Save(out);
    return out.bytes().size();
  }();
  int refused = 0;
  for (std::size_t i = 0; i < coloring_size; i += 7) {
    std::string damaged = bytes;
    damaged[i] = static_cast<char>(damaged[i] ^ 0x5a);
    BinaryReader in(damaged, "c");
    try {
      const Coloring c = Coloring::Load(in, kUnit, 1.0 / 8.0);
      EXPECT_FALSE(c.FindInvariantViolation(1e-6)) << "byte " << i;
    } catch (const BinaryFormatError&) {
      ++refused;
    }
  }
  EXPECT_GT(refused, 0);
}

TEST(Checkpoint, AStoppedMappingRunResumesToTheSameResult) {
  const auto data = RoomData();
  MappingOptions options;
  options.sampler.p = 0.5;
  options.samples = 12000;
  options.burn_in = 8000;
  options.chains = 2;
  options.seed = 4;
  options.trace_every = 500;
  options.anneal_steps = 6000;
  options.chunk = 700;
  const MappingResult whole = RunMapping(data, options, {});
  ASSERT_TRUE(whole.complete);

  testing::TempDir dir;
  const auto [part, sessions] =
      RunInSessions(LaserMappingData(data, options), options, 5000, dir.path());
  // 20000 steps a chain in 4 sessions of 5000, the 4th also anneals 5000 of the 6000 steps.
  EXPECT_EQ(sessions, 5);
  EXPECT_EQ(part.black_fraction, whole.black_fraction);
  EXPECT_EQ(part.white_fraction, whole.white_fraction);
  EXPECT_EQ(part.rhat_log_posterior, whole.rhat_log_posterior);
  for (std::size_t c = 0; c < 2; ++c) {
    EXPECT_EQ(part.chains[c].log_posterior_trace, whole.chains[c].log_posterior_trace);
    EXPECT_EQ(part.chains[c].point_traces, whole.chains[c].point_traces);
  }
  ASSERT_TRUE(part.map && whole.map);
  EXPECT_EQ(part.map_log_posterior, whole.map_log_posterior);

  // A stop request (a signal) ends every chain at its next chunk, checkpointed.
  testing::TempDir other;
  std::atomic<bool> stop{true};
  const MappingResult stopped =
      RunMapping(data, options, {}, {.checkpoint_directory = other.path(), .stop = &stop});
  EXPECT_FALSE(stopped.complete);
  EXPECT_TRUE(std::filesystem::exists(ChainCheckpointPath(other.path(), 1)));

  // Checkpoints of other options are refused.
  options.sampler.p = 0.6;
  MappingSession resume = StoppingSession(dir.path(), 5000);
  resume.resume = true;
  EXPECT_THROW((void)RunMapping(data, options, {}, resume), BinaryFormatError);
}

// Checkpoints swapped, or one copied over another (by a script that moves runs around), would
// continue one chain's state as another's: two identical chains, whose R-hat means nothing.
TEST(Checkpoint, AChainCheckpointOfAnotherChainIsRefused) {
  const auto data = RoomData();
  const MappingOptions options = ShortRun(2000, 3);
  const MappingData mapping = LaserMappingData(data, options);
  testing::TempDir dir;
  ASSERT_FALSE(RunMapping(mapping, options, {}, StoppingSession(dir.path(), 1000)).complete);
  const auto chain_path = [&](std::size_t c) { return ChainCheckpointPath(dir.path(), c); };
  const std::string first = testing::ReadAll(chain_path(0));
  const std::string second = testing::ReadAll(chain_path(1));
  const auto refusal = [&] {
    MappingSession resume = StoppingSession(dir.path(), 0);
    resume.resume = true;
    try {
      (void)RunMapping(mapping, options, {}, resume);
    } catch (const BinaryFormatError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };

  testing::WriteAll(chain_path(0), second);
  testing::WriteAll(chain_path(1), first);
  const std::string swapped = refusal();
  EXPECT_THAT(
      swapped,
      ::testing::AnyOf(
          HasSubstr(chain_path(0).string() + ": a checkpoint of chain 1, expected chain 0"),
          HasSubstr(chain_path(1).string() + ": a checkpoint of chain 0, expected chain 1")));

  testing::WriteAll(chain_path(0), first);
  const std::string copied = refusal();
  EXPECT_THAT(copied,
              HasSubstr(chain_path(1).string() + ": a checkpoint of chain 0, expected chain 1"));

  // Put back, the checkpoints resume.
  testing::WriteAll(chain_path(1), second);
  EXPECT_EQ(refusal(), "accepted");
}

// A checkpoint of an earlier format version is refused as such, not misread.
TEST(Checkpoint, AChainCheckpointOfAnEarlierVersionIsRefused) {
  const auto data = RoomData();
  const MappingOptions options = ShortRun(1000, 1);
  const MappingData mapping = LaserMappingData(data, options);
  testing::TempDir dir;
  ASSERT_FALSE(RunMapping(mapping, options, {}, StoppingSession(dir.path(), 500)).complete);
  const std::filesystem::path path = ChainCheckpointPath(dir.path(), 0);
  const std::string bytes = testing::ReadAll(path);
  const std::uint32_t version = SealedVersion(bytes);
  // 4: the last version whose chain checkpoints did not say which chain they hold.
  constexpr std::uint32_t kEarlier = 4;
  ASSERT_GT(version, kEarlier);
  testing::WriteAll(path, SealBinary("PRFCHAIN", kEarlier,
                                     UnsealBinary(bytes, "PRFCHAIN", version, path.string())));
  MappingSession resume = StoppingSession(dir.path(), 0);
  resume.resume = true;
  try {
    (void)RunMapping(mapping, options, {}, resume);
    ADD_FAILURE() << "an earlier version's checkpoint was accepted";
  } catch (const CheckpointMismatchError& e) {
    // Told apart from damage, so that the command can say what to do.
    EXPECT_EQ(e.reason(), CheckpointMismatchError::Reason::kFormatVersion);
    EXPECT_THAT(e.what(),
                HasSubstr(fmt::format("{}: a checkpoint of version {} of the format, "
                                      "which an earlier priormap wrote; this one reads version {}",
                                      path.string(), kEarlier, version)));
  }
  // A later version's, likewise, however much later; damaged, it is damage.
  const std::string later = SealBinary("PRFCHAIN", version + 100,
                                       UnsealBinary(bytes, "PRFCHAIN", version, path.string()));
  testing::WriteAll(path, later);
  try {
    (void)RunMapping(mapping, options, {}, resume);
    ADD_FAILURE() << "a later version's checkpoint was accepted";
  } catch (const CheckpointMismatchError& e) {
    EXPECT_EQ(e.reason(), CheckpointMismatchError::Reason::kFormatVersion);
    EXPECT_THAT(e.what(), HasSubstr("which a later priormap wrote"));
  }
  std::string damaged = later;
  damaged[damaged.size() / 2] ^= 0x10;
  testing::WriteAll(path, damaged);
  try {
    (void)RunMapping(mapping, options, {}, resume);
    ADD_FAILURE() << "a damaged checkpoint was accepted";
  } catch (const CheckpointMismatchError& e) {
    ADD_FAILURE() << "damage taken for a mismatch: " << e.what();
  } catch (const BinaryFormatError& e) {
    EXPECT_THAT(e.what(), HasSubstr("version " + std::to_string(version + 100)));
  }
}

// A checkpoint of another run (other options: another seed) is refused as such, and so is one of
// another chain.
TEST(Checkpoint, ACheckpointOfAnotherRunOrChainSaysWhich) {
  const auto data = RoomData();
  const MappingOptions options = ShortRun(1000, 2);
  testing::TempDir dir;
  ASSERT_FALSE(
      RunMapping(LaserMappingData(data, options), options, {}, StoppingSession(dir.path(), 500))
          .complete);
  const auto reason = [&](const MappingOptions& run) {
    MappingSession resume = StoppingSession(dir.path(), 0);
    resume.resume = true;
    try {
      (void)RunMapping(LaserMappingData(data, run), run, {}, resume);
    } catch (const CheckpointMismatchError& e) {
      return std::pair{e.reason(), std::string(e.what())};
    }
    ADD_FAILURE() << "accepted";
    return std::pair{CheckpointMismatchError::Reason::kFormatVersion, std::string()};
  };
  MappingOptions other_seed = options;
  other_seed.seed += 1;
  const auto [another_run, message] = reason(other_seed);
  EXPECT_EQ(another_run, CheckpointMismatchError::Reason::kAnotherRun);
  EXPECT_THAT(message, HasSubstr("a checkpoint of another run (its data or options differ"));
  testing::WriteAll(ChainCheckpointPath(dir.path(), 1),
                    testing::ReadAll(ChainCheckpointPath(dir.path(), 0)));
  EXPECT_EQ(reason(options).first, CheckpointMismatchError::Reason::kAnotherChain);
}

// The annealing continues the chain that ended highest; an annealing checkpoint of another
// chain (the other chain's copied over it, say) is refused, naming both chains.
TEST(Checkpoint, AnAnnealingCheckpointOfAnotherChainIsRefused) {
  const auto data = RoomData();
  const MappingOptions options = ShortRun(2000, 2, /*anneal_steps=*/2000);
  const MappingData mapping = LaserMappingData(data, options);
  testing::TempDir dir;
  // Sessions of 1500 steps: the third ends the chains' 4000 and anneals 1500 of 2000.
  const std::filesystem::path path = AnnealCheckpointPath(dir.path());
  MappingSession session = StoppingSession(dir.path(), 1500);
  for (int k = 0; k < 3; ++k) {
    ASSERT_FALSE(RunMapping(mapping, options, {}, session).complete);
    session.resume = true;
  }
  ASSERT_TRUE(std::filesystem::exists(path));
  const std::string bytes = testing::ReadAll(path);
  const std::uint32_t version = SealedVersion(bytes);
  std::string payload(UnsealBinary(bytes, "PRFANNEA", version, path.string()));
  // The payload: the run's fingerprint, then the chain (64 bits each).
  BinaryReader header(std::string_view(payload).substr(8, 8), "chain");
  const auto annealed = header.Get<std::uint64_t>();
  ASSERT_LT(annealed, 2u);
  BinaryWriter other;
  other.Put<std::uint64_t>(1 - annealed);
  payload.replace(8, 8, other.bytes());
  testing::WriteAll(path, SealBinary("PRFANNEA", version, payload));

  MappingSession resume = StoppingSession(dir.path(), 0);
  resume.resume = true;
  try {
    (void)RunMapping(mapping, options, {}, resume);
    ADD_FAILURE() << "another chain's annealing was accepted";
  } catch (const BinaryFormatError& e) {
    EXPECT_THAT(e.what(), HasSubstr(fmt::format("{}: the annealing of chain {}, but chain {} ends "
                                                "with the highest log posterior",
                                                path.string(), 1 - annealed, annealed)));
  }
}

// A checkpoint write killed mid-way (SIGKILL, which no handler sees) leaves its temporary file,
// megabytes that no later write replaces. The next session in the directory removes those of
// ended processes, and keeps a running process's and other files.
TEST(Checkpoint, ASessionRemovesTheTemporariesOfKilledCheckpointWrites) {
  const auto data = RoomData();
  const MappingOptions options = ShortRun(2000, 2, /*anneal_steps=*/1000);
  const MappingData mapping = LaserMappingData(data, options);
  testing::TempDir dir;
  ASSERT_FALSE(RunMapping(mapping, options, {}, StoppingSession(dir.path(), 1000)).complete);

  const std::string killed = std::to_string(testing::EndedProcessId());
  const std::vector<std::string> stale = {".chain-1.ckpt.tmp-" + killed + "-0",
                                          ".anneal.ckpt.tmp-" + killed + "-7"};
  const std::vector<std::string> kept = {
      ".chain-0.ckpt.tmp-1-0",                // process 1 runs: it may be writing it
      ".summary.json.tmp-" + killed + "-0",   // not a checkpoint's
      ".chain-01.ckpt.tmp-" + killed + "-0",  // nor is this name
      ".chain-0.ckpt.tmp-" + killed,          // nor one of a temporary file
      "chain-0.ckpt.tmp-" + killed + "-0"};
  for (const std::string& name : stale) testing::WriteAll(dir / name, "half a checkpoint");
  for (const std::string& name : kept) testing::WriteAll(dir / name, "someone else's");
  MappingSession resume = StoppingSession(dir.path(), 0);
  resume.resume = true;
  const MappingResult result = RunMapping(mapping, options, {}, resume);
  ASSERT_TRUE(result.complete);
  EXPECT_EQ(result.resumed_steps, 2u * 1000u);
  for (const std::string& name : stale) EXPECT_FALSE(std::filesystem::exists(dir / name)) << name;
  for (const std::string& name : kept) EXPECT_TRUE(std::filesystem::exists(dir / name)) << name;

  // A fresh run (no --resume) into a directory removes them too.
  testing::TempDir fresh;
  testing::WriteAll(fresh / stale.front(), "half a checkpoint");
  EXPECT_FALSE(RunMapping(mapping, options, {}, StoppingSession(fresh.path(), 500)).complete);
  EXPECT_FALSE(std::filesystem::exists(fresh / stale.front()));
}

// A caller holding the run's directory locked knows that no checkpoint writer runs there: it
// removes their temporaries whatever their PID names now (another process that reused it, a
// zombie), and keeps every other file.
TEST(Checkpoint, UnderTheLockEveryCheckpointTemporaryIsStale) {
  testing::TempDir dir;
  const std::string killed = std::to_string(testing::EndedProcessId());
  const std::vector<std::string> stale = {
      ".chain-0.ckpt.tmp-1-0",  // process 1 runs, but holds no lock of this directory
      ".chain-12.ckpt.tmp-" + killed + "-3", ".anneal.ckpt.tmp-" + killed + "-7",
      ".chain-1.ckpt.tmp-" + std::to_string(::getpid()) + "-0"};
  const std::vector<std::string> kept = {"chain-0.ckpt",          "anneal.ckpt",
                                         ".summary.json.tmp-1-0", ".chain-01.ckpt.tmp-1-0",
                                         ".chain-0.ckpt.tmp-1",   ".chain-0.ckpt.tmp-1-x",
                                         "chain-0.ckpt.tmp-1-0",  "notes.txt"};
  for (const std::string& name : stale) testing::WriteAll(dir / name, "half a checkpoint");
  for (const std::string& name : kept) testing::WriteAll(dir / name, "kept");
  std::filesystem::create_directory(dir / ".chain-2.ckpt.tmp-1-0");  // not a file
  EXPECT_EQ(RemoveCheckpointTemporariesOfEndedWriters(dir.path()), stale.size());
  for (const std::string& name : stale) EXPECT_FALSE(std::filesystem::exists(dir / name)) << name;
  for (const std::string& name : kept) EXPECT_TRUE(std::filesystem::exists(dir / name)) << name;
  EXPECT_TRUE(std::filesystem::is_directory(dir / ".chain-2.ckpt.tmp-1-0"));
  EXPECT_EQ(RemoveCheckpointTemporariesOfEndedWriters(dir / "missing"), 0u);
}

}  // namespace
}  // namespace priormap::prf
