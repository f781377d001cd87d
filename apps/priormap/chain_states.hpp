#pragma once
// Each chain's last state as GeoJSON faces (chainK_last.geojson), which `priormap prf` and
// `priormap prf sonar-study` write: where chains end in different modes, or chains started at
// the truth end above those started empty, the states say structure by structure what differs.

#include <cstddef>
#include <filesystem>
#include <string>

#include <priormap/prf/coloring.hpp>
#include <priormap/prf/window.hpp>

namespace priormap::app {

/// The file name of chain `chain`'s last state.
[[nodiscard]] std::string ChainStateFile(std::size_t chain);

/// Writes `last` to dir / ChainStateFile(chain), atomically.
void SaveChainState(const std::filesystem::path& dir, std::size_t chain, const prf::Coloring& last,
                    const prf::Window& window);

}  // namespace priormap::app
