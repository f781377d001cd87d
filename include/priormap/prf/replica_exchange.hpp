#pragma once
/// Replica exchange (parallel tempering; Swendsen & Wang 1986, Geyer 1991) of PRF chains: K
/// copies of a chain at temperatures 1 = T₀ < T₁ < … < T_{K−1} run side by side, and adjacent
/// ones offer every so often to swap their states. The hot replicas cross the barriers between
/// the posterior's modes that a single chain at temperature 1 cannot (a phantom wall, a room not
/// yet found); swaps hand what they find down to the cold one. Each swap is a Metropolis step on
/// the product of the tempered targets λ(dχ) · exp(−E(χ)/T_k), so the cold replica's
/// stationary law stays the target at temperature 1.

#include <cstdint>
#include <memory>
#include <vector>

#include <priormap/prf/sampler.hpp>

namespace priormap::prf {

/// T_k = top^(k/(K−1)) for k = 0..K−1: a geometric ladder, {1} for one replica (top > 1 for
/// more than one).
[[nodiscard]] std::vector<double> GeometricLadder(int replicas, double top);

/// The part of the sampler's log-target that a temperature divides: its log-posterior without
/// the log of the Arak reference measure λ (the sampler tempers energy, never λ).
[[nodiscard]] double TemperedLogDensity(const PrfSampler& sampler);

/// log of the Metropolis ratio of swapping a state of tempered log-density `a` at temperature
/// `temperature_a` with one of `b` at `temperature_b`.
[[nodiscard]] double LogSwapRatio(double a, double temperature_a, double b, double temperature_b);

/// Swaps offered and accepted between one pair of adjacent rungs.
struct SwapCounter {
  std::uint64_t proposed = 0;
  std::uint64_t accepted = 0;
  [[nodiscard]] double rate() const {
    return proposed == 0 ? 0.0 : static_cast<double>(accepted) / static_cast<double>(proposed);
  }
};

/// The acceptance rate of each pair's swaps (for the ladder's tuning: rates near 0 ask for more
/// rungs or a lower top).
[[nodiscard]] std::vector<double> SwapRates(const std::vector<SwapCounter>& swaps);

class ReplicaLadder {
 public:
  /// replicas[k] runs at ladder[k] (ladder[0] = 1, increasing); every replica has taken the
  /// same number of steps. `seed` seeds the swap decisions; `swaps` (one per adjacent pair, or
  /// empty) continues the counts of a restored ladder.
  ReplicaLadder(std::vector<std::unique_ptr<PrfSampler>> replicas, std::vector<double> ladder,
                std::uint64_t seed, std::vector<SwapCounter> swaps = {});

  /// Multiplies every rung's temperature (the annealed burn-in's schedule); 1 by default.
  void set_scale(double scale);
  /// `steps` steps of every replica, in parallel.
  void Run(std::uint64_t steps);
  /// Exchange round `round`: the pairs (k, k+1) with k of the round's parity (every pair of a
  /// two-rung ladder), left to right, each offering its swap. The decisions depend only on the
  /// seed, the round and the states, so a resumed ladder goes on exactly.
  void Exchange(std::uint64_t round);

  [[nodiscard]] PrfSampler& cold() { return *replicas_.front(); }
  [[nodiscard]] const std::vector<std::unique_ptr<PrfSampler>>& replicas() const {
    return replicas_;
  }
  /// The replicas above the cold one, hottest last.
  [[nodiscard]] std::vector<const PrfSampler*> hot() const;
  [[nodiscard]] const std::vector<double>& ladder() const { return ladder_; }
  [[nodiscard]] const std::vector<SwapCounter>& swaps() const { return swaps_; }
  /// Ends the ladder: its cold replica, to go on alone.
  [[nodiscard]] std::unique_ptr<PrfSampler> TakeCold() &&;
  /// Ends the ladder: the replica of highest log-posterior (the coldest of equals), to go on
  /// alone at temperature 1 — a best-of-K start for a burn-in, which no longer keeps the ladder's
  /// stationary law (what follows the burn-in must restore it).
  [[nodiscard]] std::unique_ptr<PrfSampler> TakeBest() &&;

 private:
  [[nodiscard]] double temperature(std::size_t rung) const { return scale_ * ladder_[rung]; }

  std::vector<std::unique_ptr<PrfSampler>> replicas_;
  std::vector<double> ladder_;
  std::uint64_t seed_;
  std::vector<SwapCounter> swaps_;
  double scale_ = 1.0;
};

}  // namespace priormap::prf
