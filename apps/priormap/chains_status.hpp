#pragma once
// The chains' part of `priormap prf`'s status line.

#include <string>
#include <vector>

#include <priormap/prf/mapping.hpp>

namespace priormap::app {

/// The chains' latest log posteriors: with up to four chains each in chain order (the order of
/// chainK.png), "..." for one that has not reported yet; with more, the range of each stage's
/// chains and how many have reported. Values of a thinned stage say which fraction of the
/// readings they are of. Empty before any chain has reported.
[[nodiscard]] std::string ChainsLogPosteriors(const std::vector<prf::ChainProgress>& chains);

}  // namespace priormap::app
