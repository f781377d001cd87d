#pragma once
/// The data half of the PRF posterior, as the sampler sees it: a log-likelihood of the coloring
/// that an edit changes locally. Implementations keep their own index over the data, so that
/// Evaluate recomputes only what the edit can change (Paskin & Thrun, Sec. 1.3.3 and 2.2).
///
/// Log-likelihoods are kept in fixed point (units of 2^-32 nats, int64): sums are then exact and
/// independent of order, so the incremental total equals the one recomputed from scratch bit for
/// bit, does not drift over millions of moves, and a resumed chain continues exactly.

#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include <priormap/prf/coloring.hpp>

namespace priormap::prf {

using FixedLogLik = std::int64_t;
inline constexpr double kFixedLogLikScale = 4294967296.0;  // 2^32
[[nodiscard]] inline FixedLogLik ToFixed(double log_lik) {
  return std::llround(log_lik * kFixedLogLikScale);
}
[[nodiscard]] inline double FromFixed(FixedLogLik value) {
  return static_cast<double>(value) / kFixedLogLikScale;
}

class DataTerm {
 public:
  virtual ~DataTerm() = default;

  /// Recomputes all state for `coloring`. Returns a message when the coloring has likelihood
  /// zero (a sensor in black, say).
  virtual std::optional<std::string> Reset(const Coloring& coloring) = 0;
  /// The change of the log-likelihood if `edit` (which coloring.Evaluate accepted) were applied;
  /// nullopt when the result would have likelihood zero. Remembers its work for Commit.
  virtual std::optional<FixedLogLik> Evaluate(const Coloring& coloring, const Edit& edit) = 0;
  /// Commits the last Evaluate after coloring.Apply(edit), which returned `added_edges`.
  virtual void Commit(std::span<const EdgeId> added_edges) = 0;

  [[nodiscard]] virtual FixedLogLik log_likelihood() const = 0;
  /// The log-likelihood recomputed from scratch, leaving the incremental state alone (debug).
  [[nodiscard]] virtual FixedLogLik RecomputeLogLikelihood(const Coloring& coloring) const = 0;
  /// Where the incremental state disagrees with a recomputation, if anywhere (debug, tests).
  [[nodiscard]] virtual std::optional<std::string> FindInconsistency(
      const Coloring& coloring) const = 0;

  /// An independent copy (each chain owns one).
  [[nodiscard]] virtual std::unique_ptr<DataTerm> Clone() const = 0;
};

}  // namespace priormap::prf
