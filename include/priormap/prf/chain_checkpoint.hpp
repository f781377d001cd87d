#pragma once
/// Checkpoints of a PRF mapping run: one file per chain (its sampler, running estimates and
/// traces) and one for the annealing chain, each sealed with a checksum and stamped with the
/// run's fingerprint, so that a run resumes only from checkpoints of the same data and options.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>

#include <priormap/prf/estimates.hpp>
#include <priormap/prf/laser_data.hpp>
#include <priormap/prf/sampler.hpp>

namespace priormap::prf {

struct MappingOptions;
struct ChainSummary;

/// Hash of everything a chain's course depends on: the beams, the sensors and the options
/// (not the chunk size nor the checkpoint settings, which do not change the result).
[[nodiscard]] std::uint64_t RunFingerprint(const LaserData& data, const MappingOptions& options);

[[nodiscard]] std::filesystem::path ChainCheckpointPath(const std::filesystem::path& directory,
                                                        std::size_t chain);
[[nodiscard]] std::filesystem::path AnnealCheckpointPath(const std::filesystem::path& directory);

/// Writes a chain's state atomically. `estimates` is null before the chain records.
void SaveChainCheckpoint(const std::filesystem::path& path, std::uint64_t fingerprint,
                         const PrfSampler& sampler, const PosteriorEstimates* estimates,
                         const ChainSummary& summary);

struct LoadedChain {
  std::unique_ptr<PrfSampler> sampler;
  bool recording = false;  // the estimates hold samples
};

/// Restores a chain saved by SaveChainCheckpoint into `estimates` and `summary`, with `data`
/// as its data term. BinaryFormatError when the file is damaged or of another run.
[[nodiscard]] LoadedChain LoadChainCheckpoint(const std::filesystem::path& path,
                                              std::uint64_t fingerprint, const Window& window,
                                              const MappingOptions& options,
                                              std::unique_ptr<DataTerm> data,
                                              PosteriorEstimates* estimates, ChainSummary* summary);

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
