#pragma once
/// Checkpoints of a PRF mapping run: one file per chain (its sampler, running estimates and
/// traces) and one for the annealing chain, each sealed with a checksum and stamped with the
/// run's fingerprint, so that a run resumes only from checkpoints of the same data and options.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include <priormap/core/binary_io.hpp>
#include <priormap/prf/estimates.hpp>
#include <priormap/prf/laser_data.hpp>
#include <priormap/prf/laser_model.hpp>
#include <priormap/prf/replica_exchange.hpp>
#include <priormap/prf/sampler.hpp>

namespace priormap::prf {

struct MappingOptions;
struct ChainSummary;

/// A checkpoint that is whole (its checksum holds) but cannot continue this run: written in
/// another version of the format (by another version of priormap), for another run (other data
/// or options: its fingerprint differs), or for another chain. A command tells the user what to
/// do by the reason; any other BinaryFormatError of a checkpoint is damage.
class CheckpointMismatchError : public BinaryFormatError {
 public:
  enum class Reason { kFormatVersion, kAnotherRun, kAnotherChain };
  CheckpointMismatchError(Reason reason, const std::string& message)
      : BinaryFormatError(message), reason_(reason) {}
  [[nodiscard]] Reason reason() const { return reason_; }

 private:
  Reason reason_;
};

/// A checkpoint that is there but cannot be read (no permission, a directory in its place, an
/// I/O error). Not damage: what it holds may be whole, so a command must not have it removed.
class CheckpointReadError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Hash of everything a chain's course depends on: the beams, the sensors and the options
/// (not the chunk size nor the checkpoint settings, which do not change the result).
[[nodiscard]] std::uint64_t RunFingerprint(const LaserData& data, const MappingOptions& options);

/// Hash of the beams, the sensors and the laser model alone (MappingData::data_fingerprint).
[[nodiscard]] std::uint64_t LaserDataFingerprint(const LaserData& data, const LaserModel& model);

[[nodiscard]] std::filesystem::path ChainCheckpointPath(const std::filesystem::path& directory,
                                                        std::size_t chain);
[[nodiscard]] std::filesystem::path AnnealCheckpointPath(const std::filesystem::path& directory);

/// Removes the temporary files of chain and annealing checkpoints in `directory` whose writer is
/// no longer running (RemoveStaleTemporaryFiles): a write killed mid-way (SIGKILL, a crash)
/// leaves one, megabytes, that no later write replaces. Returns how many were removed.
std::size_t RemoveStaleCheckpointTemporaries(const std::filesystem::path& directory);

/// Removes every temporary file of a chain or annealing checkpoint in `directory`
/// (".chain-K.ckpt.tmp-PID-N", ".anneal.ckpt.tmp-PID-N"), whatever process its PID names now: for
/// a caller that holds the run's directory locked (the command's DirectoryLock) and has not begun
/// the run. Every writer of those checkpoints held that lock, so none is writing: the PID is that
/// of a writer killed mid-write, which RemoveStaleCheckpointTemporaries keeps while the PID runs
/// (reused by another process, or a zombie not yet reaped). Returns how many were removed.
std::size_t RemoveCheckpointTemporariesOfEndedWriters(const std::filesystem::path& directory);

/// Writes a chain's state atomically: its sampler, the hot replicas of its burn-in's ladder
/// (none outside one; in one file with the rest, so that they cannot fall out of step) and its
/// summary (traces and swap counts), stamped with the run's `fingerprint` and the `chain`'s
/// index. `estimates` is null before the chain records.
void SaveChainCheckpoint(const std::filesystem::path& path, std::uint64_t fingerprint,
                         std::size_t chain, const PrfSampler& sampler,
                         std::span<const PrfSampler* const> hot,
                         const PosteriorEstimates* estimates, const ChainSummary& summary);

struct LoadedChain {
  std::unique_ptr<PrfSampler> sampler;
  std::vector<std::unique_ptr<PrfSampler>> hot;  ///< the ladder's other replicas, hotter and hotter
  bool recording = false;                        ///< the estimates hold samples
};

/// Restores a chain saved by SaveChainCheckpoint into `estimates` and `summary`, each sampler
/// with a data term from `make_data`. CheckpointMismatchError when the file is of another version
/// of the format, of another run, or of a chain other than `chain` (swapped with, or copied over,
/// another chain's file); BinaryFormatError when it is damaged.
[[nodiscard]] LoadedChain LoadChainCheckpoint(
    const std::filesystem::path& path, std::uint64_t fingerprint, std::size_t chain,
    const Window& window, const MappingOptions& options,
    const std::function<std::unique_ptr<DataTerm>()>& make_data, PosteriorEstimates* estimates,
    ChainSummary* summary);

/// The annealing chain: which chain it started from, and its sampler.
void SaveAnnealCheckpoint(const std::filesystem::path& path, std::uint64_t fingerprint,
                          std::size_t chain, const PrfSampler& sampler);
struct LoadedAnneal {
  std::size_t chain = 0;
  std::unique_ptr<PrfSampler> sampler;
};
[[nodiscard]] LoadedAnneal LoadAnnealCheckpoint(const std::filesystem::path& path,
                                                std::uint64_t fingerprint, const Window& window,
                                                const MappingOptions& options,
                                                std::unique_ptr<DataTerm> data);

}  // namespace priormap::prf
