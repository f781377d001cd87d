#pragma once
/// A numerical test of pose independence (paper Def. 3), which the degrees-of-freedom analysis
/// assumes: moving the whole local map rigidly (points p_i -> R p_i + t, normals alpha_i ->
/// alpha_i + dtheta, and so rho_i = |p_i| and phi_i = atan2(p_i)) must not change any term.
/// Value invariance is sufficient, not necessary: a constraint can keep its zero set while its
/// value changes, so a failure is a warning to read, not a proof.

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <priormap/dsl/prior.hpp>

namespace priormap::dsl {

struct PoseIndependenceViolation {
  BlockKind block;
  int term = 0;
  double value_before = 0.0;
  double value_after = 0.0;
  double dx = 0.0, dy = 0.0, dtheta = 0.0;  ///< the rigid motion that changed it
  /// |after - before|; infinite when the term is defined (finite) at one pose only.
  [[nodiscard]] double Change() const {
    return std::isfinite(value_before) && std::isfinite(value_after)
               ? std::abs(value_after - value_before)
               : std::numeric_limits<double>::infinity();
  }
};

struct PoseIndependenceReport {
  int configurations = 0;                             ///< random configurations tried per block
  std::vector<PoseIndependenceViolation> violations;  ///< the worst one per term that changed
  /// Term evaluations undefined (NaN or infinite) at both poses, which test nothing.
  int undefined_evaluations = 0;
  [[nodiscard]] bool ok() const { return violations.empty(); }
};

/// Tries `configurations` random local maps and rigid motions per block (reproducible from `seed`).
[[nodiscard]] PoseIndependenceReport CheckPoseIndependence(const CompiledPrior& prior,
                                                           int configurations = 200,
                                                           std::uint64_t seed = 1);

}  // namespace priormap::dsl
