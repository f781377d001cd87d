#pragma once
// The chains' (or the annealing's) part of `priormap prf`'s status line.

#include <string>
#include <vector>

#include <priormap/prf/mapping.hpp>

namespace priormap::app {

/// The chains' latest log posteriors: with up to four chains each in chain order (the order of
/// chainK.png), "..." for one that has not reported yet; with more, the range of each stage's
/// chains and how many have reported. Values of a thinned stage say which fraction of the
/// readings they are of. Empty before any chain has reported.
[[nodiscard]] std::string ChainsLogPosteriors(const std::vector<prf::ChainProgress>& chains);

/// ChainsLogPosteriors of the report's chains while they run; once the annealing reports, its
/// chain, temperature and log posterior ("annealing chain 1 at T 0.25, log posterior 6139.0"),
/// as the chains' values then stand still.
[[nodiscard]] std::string MappingState(const prf::MappingProgress& progress);

}  // namespace priormap::app
