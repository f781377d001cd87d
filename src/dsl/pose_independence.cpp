#include <cmath>
#include <map>

#include <priormap/core/angles.hpp>
#include <priormap/core/rng.hpp>
#include <priormap/core/se2.hpp>
#include <priormap/core/types.hpp>
#include <priormap/dsl/pose_independence.hpp>

namespace priormap::dsl {
namespace {

constexpr double kTolerance = 1e-7;

// x = (rho, alpha) and phi of points p with normals alpha.
void Configuration(const std::vector<Vec2>& points, const std::vector<double>& alpha,
                   std::vector<double>& x, std::vector<double>& phi) {
  const std::size_t k = points.size();
  x.assign(2 * k, 0.0);
  phi.assign(k, 0.0);
  for (std::size_t i = 0; i < k; ++i) {
    x[i] = points[i].norm();
    x[k + i] = alpha[i];
    phi[i] = std::atan2(points[i].y(), points[i].x());
  }
}

}  // namespace

PoseIndependenceReport CheckPoseIndependence(const CompiledPrior& prior, int configurations,
                                             std::uint64_t seed) {
  PoseIndependenceReport report;
  report.configurations = configurations;
  Rng rng(seed);
  const std::size_t k = static_cast<std::size_t>(prior.order());
  for (int b = 0; b < kNumBlockKinds; ++b) {
    const CompiledBlock* block = prior.block(static_cast<BlockKind>(b));
    if (!block) continue;
    BlockEvaluator evaluator(*block);
    const std::size_t nt = static_cast<std::size_t>(block->num_terms());
    std::vector<double> before(nt), after(nt), x, phi;
    std::map<int, PoseIndependenceViolation> worst;
    for (int trial = 0; trial < configurations; ++trial) {
      // Points ahead of the sensor, 0.5-5 m away, with arbitrary normals.
      std::vector<Vec2> points(k);
      std::vector<double> alpha(k);
      for (std::size_t i = 0; i < k; ++i) {
        points[i] = rng.Uniform(0.5, 5.0) * UnitVector(rng.Uniform(-kPi / 2, kPi / 2));
        alpha[i] = rng.Uniform(-kPi, kPi);
      }
      const double dx = rng.Uniform(-2, 2), dy = rng.Uniform(-2, 2),
                   dtheta = rng.Uniform(-kPi, kPi);
      Configuration(points, alpha, x, phi);
      evaluator.Evaluate(x, phi, before.data());
      const Se2 motion(dx, dy, dtheta);
      for (std::size_t i = 0; i < k; ++i) {
        points[i] = motion.Transform(points[i]);
        alpha[i] += dtheta;
      }
      Configuration(points, alpha, x, phi);
      evaluator.Evaluate(x, phi, after.data());
      for (std::size_t t = 0; t < nt; ++t) {
        if (!std::isfinite(before[t]) && !std::isfinite(after[t])) {
          ++report.undefined_evaluations;
          continue;
        }
        // A term defined at one pose and not at the other depends on the pose as surely as one
        // whose value moves: its change is infinite.
        const PoseIndependenceViolation candidate{
            static_cast<BlockKind>(b), static_cast<int>(t), before[t], after[t], dx, dy, dtheta};
        const double change = candidate.Change();
        if (std::isfinite(change) && change <= kTolerance * (1.0 + std::abs(before[t]))) continue;
        auto [it, inserted] = worst.try_emplace(static_cast<int>(t), candidate);
        if (!inserted && change > it->second.Change()) it->second = candidate;
      }
    }
    for (auto& [term, violation] : worst) report.violations.push_back(violation);
  }
  return report;
}

}  // namespace priormap::dsl
