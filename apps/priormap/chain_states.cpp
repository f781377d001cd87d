#include "chain_states.hpp"

#include <fmt/format.h>

#include <priormap/core/file_io.hpp>
#include <priormap/prf/polygon_map.hpp>

namespace priormap::app {

std::string ChainStateFile(std::size_t chain) {
  return fmt::format("chain{}_last.geojson", chain);
}

void SaveChainState(const std::filesystem::path& dir, std::size_t chain, const prf::Coloring& last,
                    const prf::Window& window) {
  WriteTextFileAtomically(dir / ChainStateFile(chain),
                          prf::FacesToGeoJson(prf::ExtractFaces(last), window));
}

}  // namespace priormap::app
