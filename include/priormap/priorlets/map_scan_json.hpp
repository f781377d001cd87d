#pragma once
/// The `priormap.map_scan` JSON document of `priormap scan` (docs/formats.md).
#include <cstddef>
#include <string>

#include <priormap/priorlets/engine.hpp>
#include <priormap/priorlets/posterior.hpp>

namespace priormap::priorlets {

struct MapScanJsonContext {
  std::size_t scan_index = 0;
  std::string prior_name;
  std::string input;
};

/// One JSON object on one line (so that a log's results form JSON Lines); per-beam arrays have
/// one entry per beam, NaN as null. With `posterior`, also the degrees of freedom, the posterior
/// standard deviations and the eigenvariations.
[[nodiscard]] std::string MapScanToJson(const MapScan& map, const MapScanJsonContext& context,
                                        const Posterior* posterior = nullptr);

}  // namespace priormap::priorlets
