#pragma once
// The chains' (or the annealing's) part of `priormap prf`'s status line.

#include <cstdint>
#include <deque>
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

/// Steps per second over at least the last `window_s` seconds of reports (or since the first
/// report, while it is shorter). The chains report in chunks, each when it ends: over the time
/// between two lines alone, a chunk that ended milliseconds after the last line would read as
/// millions of steps per second.
class RecentRate {
 public:
  explicit RecentRate(double window_s = 2.0) : window_s_(window_s) {}

  /// Records that `steps` were done at `seconds` (both non-decreasing) and returns the rate since
  /// the latest report at least window_s earlier, else since the first; 0 without elapsed time.
  double Add(double seconds, std::uint64_t steps);

 private:
  struct Report {
    double seconds;
    std::uint64_t steps;
  };
  double window_s_;
  std::deque<Report> reports_;  // the first kept one is the latest at least window_s old
};

}  // namespace priormap::app
