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
#include <vector>

#include <priormap/prf/estimates.hpp>
#include <priormap/prf/laser_data.hpp>
#include <priormap/prf/laser_model.hpp>
#include <priormap/prf/replica_exchange.hpp>
#include <priormap/prf/sampler.hpp>

namespace priormap::prf {

struct MappingOptions;
struct ChainSummary;

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
/// with a data term from `make_data`. BinaryFormatError when the file is damaged, of another
/// run, or of a chain other than `chain` (swapped with, or copied over, another chain's file).
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
