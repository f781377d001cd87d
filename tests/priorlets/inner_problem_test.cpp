// Finite-difference tests of the engine's inner problem (Problem 4 of the paper,
// src/priorlets/inner_problem.hpp): the gradient and the banded Hessian that
// InnerProblem::Evaluate returns, the constraint rows of EqualityRows, and the penalties of
// Violations and LinkPenalties, with priors of priors/ on small simulated scans.
//
// What is checked, and why so:
//  - Evaluate's gradient is claimed to be the exact gradient of Total(lambda, barrier_weight).
//    Total is linear in lambda and in the barrier weight, so the gradient of every piece follows
//    from evaluations at a few weights: penalty = (G(W, 0) - G(0, 0)) / W, barrier =
//    (G(0, W) - G(0, 0)) / W, and data + energy = G(0, 0), split with the data term's
//    documented form 1/2 (x - target)^T data_information (x - target) (target: the measured
//    ranges and initial normals). Each piece, and Total at two engine-like weights, is compared
//    with central differences of the corresponding ObjectiveValue field.
//  - The Hessian is NOT the exact Hessian, and is checked against what it claims to be:
//      data term: exact (a quadratic) -> central differences of the analytic gradient, and
//                 H(0, 0) = data_information() exactly for priors without energies;
//      barrier:   exact -> central differences of the analytic barrier gradient;
//      penalty:   Gauss-Newton, 2 J^T J over the active residuals (f of an equality, max(0, g)
//                 of an inequality, those of the smallest branch of a disjunction). J is taken by
//                 central differences of the residuals, which are evaluated here from the
//                 compiled prior's term values only (never its compiled derivatives). Where
//                 Gauss-Newton is exact, the penalty Hessian must also match central differences
//                 of the analytic gradient: for a prior whose residuals are linear (rectangular,
//                 every window a different_region one) at any point, and for any prior at a
//                 feasible point (every residual zero, so the dropped 2 r Hess r vanishes);
//      energies:  per window, the eigenvalues of the energies' Hessian clipped at zero -> each
//                 window's exact Hessian is taken by central differences of the analytic
//                 gradient of a problem made of that window alone, clipped, and assembled.
//    The Hessian at weights (lambda, w) must be H(0, 0) + lambda Hpen + w Hbarrier, and
//    positive definite (it is factored by Cholesky).
//  - EqualityRows are the Jacobian of the equality residuals (central differences, same order).
//  - Violations and LinkPenalties are the sums of the squared residuals, window by window.
// The points are strictly inside the bounds and away from the places where a term is not
// smooth (a disjunction's branch switch, an inequality's activation, the abs() of
// circular-radius), so that central differences apply.
//
// Tolerances: entries are compared relative to max(1, largest finite-difference entry)
// (JacobiansMatch). The largest errors seen are 2e-8 (gradients) and 5e-8 (Hessians), both the
// barrier's truncation error next to a bound (5% of its width away); every other check stays
// below 2e-9. A tolerance of 1e-6 leaves room for other compilers and libms, while the wrong
// derivatives tried (a flipped sign, a dropped or doubled term, the full Newton Hessian of the
// penalties, unclipped energies, a wrong index) give relative errors from 3e-5 to 1e2.
#include "inner_problem.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <iomanip>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/banded_matrix.hpp>
#include <priormap/core/check.hpp>
#include <priormap/core/rng.hpp>
#include <priormap/core/scan.hpp>
#include <priormap/dsl/prior.hpp>
#include <priormap/dsl/prior_library.hpp>
#include <priormap/priorlets/constraint_kernel.hpp>
#include <priormap/priorlets/engine.hpp>

#include "testing/numeric_diff.hpp"

namespace priormap::priorlets {
namespace {

using Eigen::Index;
using Eigen::MatrixXd;
using Eigen::VectorXd;
using priormap::testing::JacobiansMatch;
using priormap::testing::NumericJacobian;

constexpr double kStep = 1e-6;       // central-difference step (rho in m, alpha in rad)
constexpr double kTolerance = 1e-6;  // relative to max(1, largest finite-difference entry)
// Points keep this fraction of each bound's width from it.
constexpr double kMargin = 0.05;
// Distance from a non-smooth place that keeps the finite-difference stencil (1e-6 wide, terms
// with slopes up to ~1e2) on one side of it.
constexpr double kKinkDistance = 1e-3;

Index I(std::size_t i) {
  return static_cast<Index>(i);
}

// ---------------------------------------------------------------------------------------------
// Scenes: a scan's in-model points with their truth, bounds and initial values as the engine
// makes them (engine.cpp, MakePoints: rho within 4 sigma, alpha within 89 degrees of facing).

enum class Geometry { kCorner, kCircle };
enum class Noise { kIndependent, kCorrelated };

struct TrueBeam {
  double phi = 0.0, rho = 0.0, alpha = 0.0;  // alpha: the normal towards the sensor
};

// Walls x = 3 (normal at pi) and y = 2 (normal at -pi/2), meeting at phi = atan2(2, 3) = 0.588.
std::vector<TrueBeam> CornerBeams() {
  std::vector<TrueBeam> beams;
  for (int i = 0; i < 16; ++i) {
    const double phi = 0.40 + 0.03 * i;
    if (3.0 * std::tan(phi) < 2.0) {
      beams.push_back({phi, 3.0 / std::cos(phi), kPi});
    } else {
      beams.push_back({phi, 2.0 / std::sin(phi), -kPi / 2});
    }
  }
  return beams;
}

// A pillar of radius 0.5 m centred at (2.5, 0.3).
std::vector<TrueBeam> CircleBeams() {
  const Eigen::Vector2d c(2.5, 0.3);
  const double radius = 0.5;
  std::vector<TrueBeam> beams;
  for (int i = 0; i < 15; ++i) {
    const double phi = -0.02 + 0.02 * i;
    const Eigen::Vector2d u(std::cos(phi), std::sin(phi));
    const double uc = u.dot(c);
    const double t = uc - std::sqrt(uc * uc - c.squaredNorm() + radius * radius);
    const Eigen::Vector2d normal = (t * u - c) / radius;
    beams.push_back({phi, t, std::atan2(normal.y(), normal.x())});
  }
  return beams;
}

struct Scene {
  std::vector<ProblemPoint> points;
  std::vector<Link> links;
  std::vector<double> sigma;
  std::optional<SymmetricBandedMatrix> precision;
  VectorXd truth;  // interleaved like the unknowns
};

// `all_different_region`: every link different_region instead of the scene's topology.
Scene MakeScene(Geometry geometry, Noise noise, bool all_different_region = false) {
  const std::vector<TrueBeam> beams = geometry == Geometry::kCorner ? CornerBeams() : CircleBeams();
  const std::size_t n = beams.size();
  Rng rng(geometry == Geometry::kCorner ? 11 : 12);
  Scan scan;
  for (std::size_t i = 0; i < n; ++i) {
    scan.angles.push_back(beams[i].phi);
    scan.sigma.push_back(0.01 * static_cast<double>(1 + i % 3));
    scan.ranges.push_back(beams[i].rho + scan.sigma.back() * std::clamp(rng.Normal(), -2.0, 2.0));
  }
  // Correlated noise: the precision of a process with correlation matrix C^2, C that of an AR(1)
  // process (c = 0.5): D^-1 C^-2 D^-1 = W D W with W = D^-1 C^-1 D^-1. Its bandwidth is 2, so
  // the data term's band (5 unknowns) is wider than an order-2 prior's (3).
  const MatrixXd w = SymmetricBandedMatrix::Ar1Precision(scan.sigma, 0.5).ToDense();
  const MatrixXd d =
      Eigen::Map<const VectorXd>(scan.sigma.data(), I(n)).array().square().matrix().asDiagonal();
  const MatrixXd dense = w * d * w;
  scan.precision = SymmetricBandedMatrix(n, 2);
  for (std::size_t j = 0; j < n; ++j) {
    for (std::size_t i = j; i < std::min(n, j + 3); ++i)
      scan.precision->Set(i, j, dense(I(i), I(j)));
  }

  // One outlier beam (beam 9 of the corner, 5 of the circle) is not in the model.
  const std::size_t outlier = geometry == Geometry::kCorner ? 9 : 5;
  std::vector<std::size_t> inmodel;
  for (std::size_t i = 0; i < n; ++i) {
    if (i != outlier) inmodel.push_back(i);
  }
  Scene scene;
  const std::size_t m = inmodel.size();
  scene.truth.resize(I(2 * m));
  for (std::size_t j = 0; j < m; ++j) {
    const std::size_t b = inmodel[j];
    ProblemPoint pt;
    pt.phi = scan.angles[b];
    pt.rho_measured = scan.ranges[b];
    const double slack = 4.0 * scan.sigma[b];
    pt.rho_lower = std::max(pt.rho_measured - slack, 0.5 * pt.rho_measured);
    pt.rho_upper = pt.rho_measured + slack;
    const double facing = pt.phi + kPi;
    pt.alpha_lower = facing - DegToRad(89.0);
    pt.alpha_upper = facing + DegToRad(89.0);
    const double alpha = facing + WrapAngle(beams[b].alpha - facing);
    pt.alpha_initial = alpha + 0.05 * rng.Normal();
    pt.alpha_sigma = 0.2;
    scene.points.push_back(pt);
    scene.sigma.push_back(scan.sigma[b]);
    scene.truth[I(2 * j)] = beams[b].rho;
    scene.truth[I(2 * j + 1)] = alpha;
  }
  // Links: a corner between the walls (different_region) and a made-up surface break on the
  // second wall; on the pillar a made-up region break. Windows across a link whose block the
  // prior lacks add nothing.
  for (std::size_t j = 0; j + 1 < m; ++j) {
    Link link = Link::kSameRegion;
    if (geometry == Geometry::kCorner) {
      const bool first_wall = beams[inmodel[j]].alpha == kPi;
      const bool next_first_wall = beams[inmodel[j + 1]].alpha == kPi;
      if (first_wall != next_first_wall) link = Link::kDifferentRegion;
      if (j == 11) link = Link::kDifferentSurface;
    } else if (j == 9) {
      link = Link::kDifferentRegion;
    }
    scene.links.push_back(all_different_region ? Link::kDifferentRegion : link);
  }
  if (noise == Noise::kCorrelated) scene.precision = InModelRangePrecision(scan, inmodel);
  return scene;
}

InnerProblem MakeProblem(const dsl::CompiledPrior& prior, const Scene& scene) {
  return InnerProblem(prior, scene.points, scene.links, scene.sigma, scene.precision);
}

// ---------------------------------------------------------------------------------------------
// The prior's windows as InnerProblem forms them (a window of k consecutive points takes the
// block of its weakest link; a block without terms adds nothing), evaluated term by term with
// the compiled prior. Only the terms' values are used: every derivative reference below is a
// finite difference.
class WindowReplica {
 public:
  WindowReplica(const dsl::CompiledPrior& prior, const Scene& scene)
      : order_(static_cast<std::size_t>(prior.order())), points_(scene.points) {
    const std::size_t m = points_.size();
    for (int kind = 0; kind < dsl::kNumBlockKinds; ++kind) {
      const dsl::CompiledBlock* block = prior.block(static_cast<dsl::BlockKind>(kind));
      if (block == nullptr || block->num_terms() == 0) continue;
      evaluators_.push_back(std::make_unique<dsl::BlockEvaluator>(*block));
      for (std::size_t first = 0; first + order_ <= m; ++first) {
        Link weakest = Link::kSameRegion;
        for (std::size_t l = first; l + 1 < first + order_; ++l)
          weakest = std::max(weakest, scene.links[l]);
        if (static_cast<int>(weakest) == kind)
          windows_.push_back({first, block, evaluators_.size() - 1});
      }
    }
  }

  struct Window {
    std::size_t first = 0;
    const dsl::CompiledBlock* block = nullptr;
    std::size_t evaluator = 0;
  };
  [[nodiscard]] const std::vector<Window>& windows() const { return windows_; }
  [[nodiscard]] std::size_t order() const { return order_; }

  // The values of window w's terms at x.
  std::vector<double> Values(std::size_t w, const VectorXd& x) const {
    const Window& window = windows_[w];
    std::vector<double> local(2 * order_), phi(order_);
    for (std::size_t i = 0; i < order_; ++i) {
      local[i] = x[I(2 * (window.first + i))];
      local[order_ + i] = x[I(2 * (window.first + i) + 1)];
      phi[i] = points_[window.first + i].phi;
    }
    std::vector<double> values(static_cast<std::size_t>(window.block->num_terms()));
    evaluators_[window.evaluator]->Evaluate(local, phi, values.data());
    return values;
  }

  // Per window and disjunction, the branch with the smallest sum of squared residuals (the
  // first of equals, as dsl::AccumulatePenalty); `gap`: the smallest margin to the next branch.
  std::vector<std::vector<int>> ActiveBranches(const VectorXd& x, double* gap = nullptr) const {
    std::vector<std::vector<int>> active;
    if (gap) *gap = std::numeric_limits<double>::infinity();
    for (std::size_t w = 0; w < windows_.size(); ++w) {
      const dsl::CompiledBlock& block = *windows_[w].block;
      const std::vector<double> values = Values(w, x);
      std::vector<int> best(static_cast<std::size_t>(block.num_disjunctions()), 0);
      for (int g = 0; g < block.num_disjunctions(); ++g) {
        std::vector<double> sums;
        for (std::size_t t = 0; t < values.size(); ++t) {
          const dsl::Term& term = block.terms()[t];
          if (term.disjunction != g) continue;
          if (sums.size() <= static_cast<std::size_t>(term.branch))
            sums.resize(static_cast<std::size_t>(term.branch) + 1, 0.0);
          const double r = Residual(term, values[t]);
          sums[static_cast<std::size_t>(term.branch)] += r * r;
        }
        const auto it = std::min_element(sums.begin(), sums.end());
        best[static_cast<std::size_t>(g)] = static_cast<int>(it - sums.begin());
        for (std::size_t b = 0; gap && b < sums.size(); ++b) {
          if (b != static_cast<std::size_t>(it - sums.begin()))
            *gap = std::min(*gap, (sums[b] - *it) / (1.0 + *it));
        }
      }
      active.push_back(std::move(best));
    }
    return active;
  }

  // The residuals that enter the penalty, window after window and term after term, with the
  // disjunctions' branches fixed to `active`; only the equalities' with `equalities_only` (the
  // rows of EqualityRows, in its order).
  VectorXd Residuals(const VectorXd& x, const std::vector<std::vector<int>>& active,
                     bool equalities_only) const {
    std::vector<double> residuals;
    for (std::size_t w = 0; w < windows_.size(); ++w) {
      const std::vector<double> values = Values(w, x);
      const dsl::CompiledBlock& block = *windows_[w].block;
      for (std::size_t t = 0; t < values.size(); ++t) {
        const dsl::Term& term = block.terms()[t];
        if (!IsActive(term, active[w])) continue;
        if (equalities_only && term.kind != dsl::TermKind::kEquality) continue;
        residuals.push_back(Residual(term, values[t]));
      }
    }
    return Eigen::Map<const VectorXd>(residuals.data(), I(residuals.size()));
  }

  // The constraint penalty of each window: the sum of its active residuals squared.
  std::vector<double> WindowPenalties(const VectorXd& x) const {
    const std::vector<std::vector<int>> active = ActiveBranches(x);
    std::vector<double> penalties;
    for (std::size_t w = 0; w < windows_.size(); ++w) {
      const std::vector<double> values = Values(w, x);
      double sum = 0.0;
      for (std::size_t t = 0; t < values.size(); ++t) {
        const dsl::Term& term = windows_[w].block->terms()[t];
        if (!IsActive(term, active[w])) continue;
        const double r = Residual(term, values[t]);
        sum += r * r;
      }
      penalties.push_back(sum);
    }
    return penalties;
  }

  // True when the finite-difference stencils around x stay on one side of every non-smooth
  // place: disjunctions' branch switches, inequalities' activation, and the abs(r13) of the
  // order-3 circle priors (where alpha_3 = alpha_1).
  bool KinkFree(const VectorXd& x) const {
    double gap = 0.0;
    (void)ActiveBranches(x, &gap);
    if (gap < kKinkDistance) return false;
    for (std::size_t w = 0; w < windows_.size(); ++w) {
      const std::vector<double> values = Values(w, x);
      for (std::size_t t = 0; t < values.size(); ++t) {
        if (windows_[w].block->terms()[t].kind == dsl::TermKind::kInequality &&
            std::abs(values[t]) < kKinkDistance)
          return false;
      }
      if (order_ == 3) {
        const std::size_t p = windows_[w].first;
        if (std::abs(std::sin((x[I(2 * p + 5)] - x[I(2 * p + 1)]) / 2)) < kKinkDistance)
          return false;
      }
    }
    return true;
  }

 private:
  static double Residual(const dsl::Term& term, double value) {
    return term.kind == dsl::TermKind::kInequality ? std::max(0.0, value) : value;
  }
  static bool IsActive(const dsl::Term& term, const std::vector<int>& active) {
    if (term.kind == dsl::TermKind::kEnergy) return false;
    return term.disjunction < 0 ||
           active[static_cast<std::size_t>(term.disjunction)] == term.branch;
  }

  std::size_t order_;
  std::vector<ProblemPoint> points_;
  std::vector<std::unique_ptr<dsl::BlockEvaluator>> evaluators_;
  std::vector<Window> windows_;
};

// ---------------------------------------------------------------------------------------------
// Evaluation helpers.

struct Derivatives {
  ObjectiveValue value;
  VectorXd gradient;
  MatrixXd hessian;
  std::optional<BandedCholesky> cholesky;
};

Derivatives At(InnerProblem& problem, const VectorXd& x, double lambda, double barrier_weight) {
  Derivatives d;
  SymmetricBandedMatrix hessian;
  d.value = problem.Evaluate(x, lambda, barrier_weight, &d.gradient, &hessian);
  d.hessian = hessian.ToDense();
  d.cholesky = BandedCholesky::Factor(hessian);
  return d;
}

VectorXd GradientAt(InnerProblem& problem, const VectorXd& x, double lambda,
                    double barrier_weight) {
  VectorXd gradient;
  (void)problem.Evaluate(x, lambda, barrier_weight, &gradient, nullptr);
  return gradient;
}

// The gradient and Hessian of the penalty alone and of the barrier alone. Evaluate is linear
// in lambda and in the barrier weight, so a piece's derivatives are the difference of two
// evaluations, with its weight at kPieceWeight and at 0, over kPieceWeight: the large weight
// keeps the rounding of the other pieces (gradients up to ~1e4) out of the difference.
constexpr double kPieceWeight = 1e3;

VectorXd PenaltyGradient(InnerProblem& problem, const VectorXd& x) {
  return (GradientAt(problem, x, kPieceWeight, 0.0) - GradientAt(problem, x, 0.0, 0.0)) /
         kPieceWeight;
}
VectorXd BarrierGradient(InnerProblem& problem, const VectorXd& x) {
  return (GradientAt(problem, x, 0.0, kPieceWeight) - GradientAt(problem, x, 0.0, 0.0)) /
         kPieceWeight;
}
MatrixXd PenaltyHessian(InnerProblem& problem, const VectorXd& x) {
  return (At(problem, x, kPieceWeight, 0.0).hessian - At(problem, x, 0.0, 0.0).hessian) /
         kPieceWeight;
}
MatrixXd BarrierHessian(InnerProblem& problem, const VectorXd& x) {
  return (At(problem, x, 0.0, kPieceWeight).hessian - At(problem, x, 0.0, 0.0).hessian) /
         kPieceWeight;
}

// The data term's target: the measured ranges and the initial normals, interleaved.
VectorXd DataTarget(const InnerProblem& problem) {
  VectorXd target(I(problem.num_unknowns()));
  for (std::size_t p = 0; p < problem.num_points(); ++p) {
    target[I(2 * p)] = problem.points()[p].rho_measured;
    target[I(2 * p + 1)] = problem.points()[p].alpha_initial;
  }
  return target;
}

// Keeps every unknown kMargin of its bounds' width inside them.
VectorXd PullInside(const InnerProblem& problem, VectorXd x) {
  for (std::size_t p = 0; p < problem.num_points(); ++p) {
    const ProblemPoint& pt = problem.points()[p];
    const auto pull = [](double& v, double lo, double hi) {
      v = std::clamp(v, lo + kMargin * (hi - lo), hi - kMargin * (hi - lo));
    };
    pull(x[I(2 * p)], pt.rho_lower, pt.rho_upper);
    pull(x[I(2 * p + 1)], pt.alpha_lower, pt.alpha_upper);
  }
  return x;
}

// The points where the derivatives are checked: the solver's initial point, a point near the
// truth (ranges off by ~sigma, normals by ~2 degrees), and two points drawn uniformly inside the
// bounds (far from feasible: normals up to 85 degrees off). All are strictly inside the bounds
// and kink-free (redrawn otherwise).
std::vector<VectorXd> EvaluationPoints(const InnerProblem& problem, const Scene& scene,
                                       const WindowReplica& replica, std::uint64_t seed) {
  Rng rng(seed);
  const auto near_truth = [&] {
    VectorXd x = scene.truth;
    for (std::size_t p = 0; p < problem.num_points(); ++p) {
      x[I(2 * p)] += scene.sigma[p] * rng.Normal();
      x[I(2 * p + 1)] += 0.03 * rng.Normal();
    }
    return PullInside(problem, x);
  };
  const auto uniform = [&] {
    VectorXd x(I(problem.num_unknowns()));
    for (std::size_t p = 0; p < problem.num_points(); ++p) {
      const ProblemPoint& pt = problem.points()[p];
      x[I(2 * p)] = rng.Uniform(pt.rho_lower, pt.rho_upper);
      x[I(2 * p + 1)] = rng.Uniform(pt.alpha_lower, pt.alpha_upper);
    }
    return PullInside(problem, x);
  };
  std::vector<VectorXd> points;
  points.push_back(problem.InitialPoint());
  const std::vector<std::function<VectorXd()>> draws = {near_truth, uniform, uniform};
  for (const auto& draw : draws) {
    VectorXd x = draw();
    for (int attempt = 0; attempt < 100 && !replica.KinkFree(x); ++attempt) x = draw();
    points.push_back(x);
  }
  for (const VectorXd& x : points) {
    EXPECT_TRUE(problem.StrictlyInside(x));
    EXPECT_TRUE(replica.KinkFree(x)) << "no kink-free point found";
  }
  return points;
}

// max |a - n| / max(1, max |n|): JacobiansMatch's measure, kept to report the worst.
double RelativeError(const MatrixXd& analytic, const MatrixXd& numeric) {
  if (numeric.size() == 0) return 0.0;
  return (analytic - numeric).cwiseAbs().maxCoeff() / std::max(1.0, numeric.cwiseAbs().maxCoeff());
}

// Checks analytic against numeric and keeps the worst error of each kind of check (the text of
// `what` before its first comma), reported as test properties (see --gtest_output=json).
class Checker {
 public:
  Checker() = default;
  Checker(const Checker&) = delete;
  Checker& operator=(const Checker&) = delete;
  ~Checker() {
    for (const auto& [kind, error] : worst_) {
      std::ostringstream text;
      text << std::scientific << std::setprecision(1) << error;
      ::testing::Test::RecordProperty("max_relative_error " + kind, text.str());
    }
  }

  void Expect(const MatrixXd& analytic, const MatrixXd& numeric, const std::string& what) {
    EXPECT_TRUE(JacobiansMatch(analytic, numeric, kTolerance)) << what;
    if (analytic.rows() != numeric.rows() || analytic.cols() != numeric.cols()) return;
    double& worst = worst_[what.substr(0, what.find(','))];
    worst = std::max(worst, RelativeError(analytic, numeric));
  }

 private:
  std::map<std::string, double> worst_;
};

// The window that starts at point `first`, as a problem of its own (its only window takes the
// same block, as its links are the same).
InnerProblem WindowProblem(const dsl::CompiledPrior& prior, const Scene& scene, std::size_t first,
                           std::size_t order) {
  const auto begin = static_cast<std::ptrdiff_t>(first);
  const auto end = static_cast<std::ptrdiff_t>(first + order);
  return InnerProblem(
      prior, std::vector<ProblemPoint>(scene.points.begin() + begin, scene.points.begin() + end),
      std::vector<Link>(scene.links.begin() + begin, scene.links.begin() + end - 1),
      std::vector<double>(scene.sigma.begin() + begin, scene.sigma.begin() + end), std::nullopt);
}

// The energies' Hessian as Evaluate claims it: per window, the exact Hessian (central
// differences of the analytic gradient of that window alone, less its data term's exact
// Hessian) with its negative eigenvalues set to zero. `clipped`: windows that were indefinite.
MatrixXd ClippedEnergyHessian(const dsl::CompiledPrior& prior, const Scene& scene,
                              const WindowReplica& replica, const VectorXd& x, int* clipped) {
  const std::size_t k = replica.order();
  MatrixXd total = MatrixXd::Zero(x.size(), x.size());
  for (const WindowReplica::Window& window : replica.windows()) {
    if (window.block->summary().energies == 0) continue;
    InnerProblem single = WindowProblem(prior, scene, window.first, k);
    const VectorXd xw = x.segment(I(2 * window.first), I(2 * k));
    MatrixXd h = NumericJacobian(
        [&](const VectorXd& v) -> VectorXd { return GradientAt(single, v, 0.0, 0.0); }, xw, kStep);
    h -= single.data_information().ToDense();
    h = 0.5 * (h + h.transpose()).eval();
    const Eigen::SelfAdjointEigenSolver<MatrixXd> eig(h);
    if (eig.eigenvalues().minCoeff() <
        -1e-6 * std::max(1.0, eig.eigenvalues().cwiseAbs().maxCoeff()))
      ++*clipped;
    const MatrixXd psd = eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).asDiagonal() *
                         eig.eigenvectors().transpose();
    total.block(I(2 * window.first), I(2 * window.first), I(2 * k), I(2 * k)) += psd;
  }
  return total;
}

MatrixXd DenseJacobian(std::size_t n, const std::vector<ConstraintRow>& rows) {
  MatrixXd j = MatrixXd::Zero(I(rows.size()), I(n));
  for (std::size_t r = 0; r < rows.size(); ++r) {
    for (std::size_t c = 0; c < rows[r].coefficients.size(); ++c)
      j(I(r), I(rows[r].first + c)) = rows[r].coefficients[c];
  }
  return j;
}

std::string Where(const std::string& prior, std::size_t point) {
  std::ostringstream text;
  text << prior << ", evaluation point " << point;
  return text.str();
}

// ---------------------------------------------------------------------------------------------

struct Case {
  std::string prior;  // a file of priors/
  Geometry geometry;
  Noise noise;
};

std::string CaseName(const ::testing::TestParamInfo<Case>& info) {
  std::string name = info.param.prior + "_" +
                     (info.param.noise == Noise::kIndependent ? "independent" : "correlated");
  std::replace(name.begin(), name.end(), '-', '_');
  return name;
}

class InnerProblemDerivatives : public ::testing::TestWithParam<Case> {
 protected:
  void SetUp() override {
    prior_.emplace(dsl::PriorLibrary().Load(GetParam().prior).value());
    scene_ = MakeScene(GetParam().geometry, GetParam().noise);
  }
  std::optional<dsl::CompiledPrior> prior_;
  Scene scene_;
};

// Every piece of the objective, and Total at two weights, against central differences of the
// objective; the pieces' analytic gradients are separated by the weights (see the top).
TEST_P(InnerProblemDerivatives, GradientOfEveryPieceMatchesCentralDifferences) {
  InnerProblem problem = MakeProblem(*prior_, scene_);
  const WindowReplica replica(*prior_, scene_);
  const double dw = problem.data_weight();
  const double lambda_a = 1e-2 * dw, barrier_a = 1.0;  // the first stage of SolveInner
  const double lambda_b = 1e2 * dw, barrier_b = 1e-3;  // where penalties dominate
  const VectorXd target = DataTarget(problem);
  Checker checker;
  const std::vector<VectorXd> points = EvaluationPoints(problem, scene_, replica, 21);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const VectorXd& x = points[i];
    const auto pieces = [&](const VectorXd& v) -> VectorXd {
      const ObjectiveValue o = problem.Evaluate(v, 0.0, 0.0, nullptr, nullptr);
      VectorXd out(6);
      out << o.data, o.energy, o.penalty, o.barrier, o.Total(lambda_a, barrier_a),
          o.Total(lambda_b, barrier_b);
      return out;
    };
    const MatrixXd numeric = NumericJacobian(pieces, x, kStep);
    const VectorXd g00 = GradientAt(problem, x, 0.0, 0.0);
    const VectorXd data = problem.data_information().Multiply(x - target);
    const std::string where = Where(GetParam().prior, i);
    checker.Expect(data.transpose(), numeric.row(0), "data term, " + where);
    checker.Expect((g00 - data).transpose(), numeric.row(1), "energies, " + where);
    checker.Expect(PenaltyGradient(problem, x).transpose(), numeric.row(2), "penalty, " + where);
    checker.Expect(BarrierGradient(problem, x).transpose(), numeric.row(3), "barrier, " + where);
    checker.Expect(GradientAt(problem, x, lambda_a, barrier_a).transpose(), numeric.row(4),
                   "Total at lambda = 1e-2 data_weight and barrier weight 1, " + where);
    checker.Expect(GradientAt(problem, x, lambda_b, barrier_b).transpose(), numeric.row(5),
                   "Total at lambda = 1e2 data_weight and barrier weight 1e-3, " + where);
  }
}

// The Hessian against what it claims to be, piece by piece (see the top).
TEST_P(InnerProblemDerivatives, HessianIsExactWhereClaimedAndTheDocumentedApproximationElsewhere) {
  InnerProblem problem = MakeProblem(*prior_, scene_);
  const WindowReplica replica(*prior_, scene_);
  const bool energies = problem.HasEnergyTerms();
  const MatrixXd data_information = problem.data_information().ToDense();
  const double dw = problem.data_weight();
  Checker checker;
  int clipped = 0;
  const std::vector<VectorXd> points = EvaluationPoints(problem, scene_, replica, 22);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const VectorXd& x = points[i];
    const std::string where = Where(GetParam().prior, i);
    const Derivatives d00 = At(problem, x, 0.0, 0.0);

    // Data term (+ energies at weights 0, 0).
    if (energies) {
      const MatrixXd reference =
          data_information + ClippedEnergyHessian(*prior_, scene_, replica, x, &clipped);
      checker.Expect(d00.hessian, reference, "data + clipped energies, " + where);
    } else {
      EXPECT_EQ(d00.hessian, data_information) << where;
      checker.Expect(
          d00.hessian,
          NumericJacobian(
              [&](const VectorXd& v) -> VectorXd { return GradientAt(problem, v, 0.0, 0.0); }, x,
              kStep),
          "data term, " + where);
    }

    // Barrier: exact.
    const MatrixXd barrier = BarrierHessian(problem, x);
    checker.Expect(
        barrier,
        NumericJacobian([&](const VectorXd& v) -> VectorXd { return BarrierGradient(problem, v); },
                        x, kStep),
        "barrier, " + where);
    EXPECT_TRUE(barrier.isDiagonal(0.0)) << where;

    // Penalty: Gauss-Newton, 2 J^T J of the active residuals.
    const std::vector<std::vector<int>> active = replica.ActiveBranches(x);
    const MatrixXd j = NumericJacobian(
        [&](const VectorXd& v) -> VectorXd { return replica.Residuals(v, active, false); }, x,
        kStep);
    const MatrixXd penalty = PenaltyHessian(problem, x);
    checker.Expect(penalty, 2.0 * j.transpose() * j, "penalty (Gauss-Newton), " + where);
    // The replica's residuals are the problem's: their squares sum to its penalty.
    EXPECT_NEAR(replica.Residuals(x, active, false).squaredNorm(), d00.value.penalty,
                1e-12 * (1.0 + d00.value.penalty))
        << where;

    // At engine-like weights: the same pieces, weighted, and positive definite.
    for (const auto& [lambda, barrier_weight] :
         {std::pair{1e-2 * dw, 1.0}, std::pair{1e2 * dw, 1e-3}}) {
      const Derivatives d = At(problem, x, lambda, barrier_weight);
      checker.Expect(d.hessian, d00.hessian + lambda * penalty + barrier_weight * barrier,
                     "Total, " + where);
      EXPECT_TRUE(d.cholesky.has_value()) << "not positive definite, " << where;
    }
  }
  // The clipping was exercised: some window's energy Hessian was indefinite.
  if (energies) {
    EXPECT_GT(clipped, 0) << "no indefinite energy window: the clipping went untested";
  }
}

// Gauss-Newton drops 2 lambda sum r Hess r, which vanishes where every residual does: at the
// truth of the scene (the priors match their scenes) the penalty Hessian is the exact one.
TEST_P(InnerProblemDerivatives, PenaltyHessianIsExactAtAFeasiblePoint) {
  InnerProblem problem = MakeProblem(*prior_, scene_);
  const VectorXd& x = scene_.truth;
  ASSERT_TRUE(problem.StrictlyInside(x));
  ASSERT_LT(problem.Violations(x).max_residual, 1e-12);
  Checker checker;
  const MatrixXd penalty = PenaltyHessian(problem, x);
  EXPECT_GT(penalty.cwiseAbs().maxCoeff(), 1.0) << "a satisfied equality keeps its curvature";
  checker.Expect(
      penalty,
      NumericJacobian([&](const VectorXd& v) -> VectorXd { return PenaltyGradient(problem, v); }, x,
                      kStep),
      "penalty at the truth");
}

// EqualityRows: the gradients of every equality (of a disjunction's smallest branch), window
// by window, in the problem's order.
TEST_P(InnerProblemDerivatives, EqualityRowsAreTheJacobianOfTheEqualities) {
  InnerProblem problem = MakeProblem(*prior_, scene_);
  const WindowReplica replica(*prior_, scene_);
  Checker checker;
  const std::vector<VectorXd> points = EvaluationPoints(problem, scene_, replica, 23);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const VectorXd& x = points[i];
    const std::vector<std::vector<int>> active = replica.ActiveBranches(x);
    const MatrixXd numeric = NumericJacobian(
        [&](const VectorXd& v) -> VectorXd { return replica.Residuals(v, active, true); }, x,
        kStep);
    checker.Expect(DenseJacobian(problem.num_unknowns(), problem.EqualityRows(x)), numeric,
                   "equality rows, " + Where(GetParam().prior, i));
  }
}

// Violations and LinkPenalties: the windows' squared residuals, summed over all windows and
// over the windows that contain each link.
TEST_P(InnerProblemDerivatives, ViolationsAndLinkPenaltiesAreTheWindowsSquaredResiduals) {
  InnerProblem problem = MakeProblem(*prior_, scene_);
  const WindowReplica replica(*prior_, scene_);
  const std::vector<VectorXd> points = EvaluationPoints(problem, scene_, replica, 24);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const VectorXd& x = points[i];
    const std::vector<double> windows = replica.WindowPenalties(x);
    std::vector<double> links(scene_.links.size(), 0.0);
    double total = 0.0;
    for (std::size_t w = 0; w < windows.size(); ++w) {
      total += windows[w];
      const std::size_t first = replica.windows()[w].first;
      for (std::size_t l = first; l + 1 < first + replica.order(); ++l) links[l] += windows[w];
    }
    const double max_residual =
        replica.Residuals(x, replica.ActiveBranches(x), false).cwiseAbs().maxCoeff();
    const Violation violation = problem.Violations(x);
    EXPECT_NEAR(violation.penalty, total, 1e-12 * (1.0 + total)) << Where(GetParam().prior, i);
    EXPECT_NEAR(violation.max_residual, max_residual, 1e-12) << Where(GetParam().prior, i);
    const std::vector<double> link_penalties = problem.LinkPenalties(x);
    ASSERT_EQ(link_penalties.size(), links.size());
    for (std::size_t l = 0; l < links.size(); ++l) {
      EXPECT_NEAR(link_penalties[l], links[l], 1e-12 * (1.0 + links[l]))
          << "link " << l << ", " << Where(GetParam().prior, i);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(
    Priors, InnerProblemDerivatives,
    ::testing::Values(
        // Straight walls: equalities with same_region, different_region (linear disjunction,
        // nonlinear sin) and different_surface links, inequalities, an energy across corners.
        Case{"polygonal", Geometry::kCorner, Noise::kIndependent},
        Case{"rectangular", Geometry::kCorner, Noise::kCorrelated},
        Case{"manhattan", Geometry::kCorner, Noise::kIndependent},
        Case{"octagonal", Geometry::kCorner, Noise::kCorrelated},
        Case{"rectangular-relaxed", Geometry::kCorner, Noise::kIndependent},
        Case{"rectangular-relaxed-alternative", Geometry::kCorner, Noise::kCorrelated},
        // Circles: order 3, with and without an energy, a disjunction of nonlinear branches;
        // splines: order 2 with an energy.
        Case{"circular", Geometry::kCircle, Noise::kIndependent},
        Case{"circular", Geometry::kCircle, Noise::kCorrelated},
        Case{"circular-radius", Geometry::kCircle, Noise::kIndependent},
        Case{"straight-or-circular", Geometry::kCircle, Noise::kCorrelated},
        Case{"splines", Geometry::kCircle, Noise::kCorrelated}),
    CaseName);

// The rectangular prior with every link different_region: every window is the disjunction
// alpha_2 = alpha_1 -+ pi/2, whose residuals are linear. Gauss-Newton is then the exact Hessian
// of the penalty at every point, infeasible ones included.
TEST(InnerProblemLinearResiduals, PenaltyHessianIsExactEverywhere) {
  const dsl::CompiledPrior prior = dsl::PriorLibrary().Load("rectangular").value();
  for (const Noise noise : {Noise::kIndependent, Noise::kCorrelated}) {
    const Scene scene = MakeScene(Geometry::kCorner, noise, /*all_different_region=*/true);
    InnerProblem problem = MakeProblem(prior, scene);
    const WindowReplica replica(prior, scene);
    Checker checker;
    const std::vector<VectorXd> points = EvaluationPoints(problem, scene, replica, 25);
    for (std::size_t i = 0; i < points.size(); ++i) {
      const VectorXd& x = points[i];
      EXPECT_GT(problem.Violations(x).max_residual, 1e-3) << "an infeasible point";
      checker.Expect(
          PenaltyHessian(problem, x),
          NumericJacobian(
              [&](const VectorXd& v) -> VectorXd { return PenaltyGradient(problem, v); }, x, kStep),
          "penalty, " + Where("rectangular with every link different_region", i));
    }
  }
}

// An energy outside its domain at some windows (sqrt of a negative number: the wall y = 2 is
// nearer than 3 m) is an infinite cost there and adds no derivatives (dsl::AccumulatePenalty),
// to the Hessian either: its NaN second derivative must not reach the Newton step.
TEST(InnerProblemEnergyDomain, AnEnergyOutsideItsDomainAddsNoDerivatives) {
  const dsl::CompiledPrior prior = dsl::PriorLibrary()
                                       .CompileText(R"(name: Far walls
order: 2
priorlet same_region:
  model_likelihood sqrt(rho_1 - 3)
)",
                                                    "far-walls.prior")
                                       .value();
  const Scene scene = MakeScene(Geometry::kCorner, Noise::kIndependent);
  InnerProblem problem = MakeProblem(prior, scene);
  VectorXd gradient;
  SymmetricBandedMatrix hessian;
  const ObjectiveValue value = problem.Evaluate(scene.truth, 1.0, 0.0, &gradient, &hessian);
  EXPECT_EQ(value.energy, std::numeric_limits<double>::infinity());
  EXPECT_TRUE(gradient.allFinite());
  EXPECT_TRUE(hessian.ToDense().allFinite());
}

// ---------------------------------------------------------------------------------------------
// Closed problems (rings: a scan that covers a full turn). A ring has no first window: moving
// its seam, where the point indices start, renumbers the points and changes nothing else. So a
// ring must be the same problem wherever its seam is (its windows across the seam are computed
// like the others, which the tests above check against central differences), and its
// derivatives must still match central differences.

enum class RingShape { kRoom, kCircle };

// m points a full turn round the sensor, point j at phi = -pi + 2 pi (j + seam) / m and, past the
// original seam (j + seam >= m), a turn on (phi and every normal + 2 pi): the ring with its seam
// moved to original point `seam`. A room [-3, 3] x [-2, 2] seen from (0.2, 0.1), its corners
// different_region links and one made-up different_surface link; or a circle of radius 2 whose
// centre is 0.3 m from the sensor, its links made-up region borders at two places.
Scene MakeRing(RingShape shape, std::size_t m, std::size_t seam) {
  Rng rng(shape == RingShape::kRoom ? 31 : 32);
  std::vector<TrueBeam> beams;
  std::vector<double> noise, normal_noise, sigma;
  for (std::size_t i = 0; i < m; ++i) {
    const double phi = -kPi + kTwoPi * static_cast<double>(i) / static_cast<double>(m);
    const Eigen::Vector2d u(std::cos(phi), std::sin(phi));
    TrueBeam beam{phi, 0.0, 0.0};
    if (shape == RingShape::kRoom) {
      const Eigen::Vector2d p0(0.2, 0.1);
      double best = std::numeric_limits<double>::infinity();
      for (const auto& [axis, wall, normal] :
           {std::tuple{0, 3.0, kPi}, std::tuple{0, -3.0, 0.0}, std::tuple{1, 2.0, -kPi / 2},
            std::tuple{1, -2.0, kPi / 2}}) {
        const double t = (wall - p0[axis]) / u[axis];
        if (t > 0.0 && t < best) {
          best = t;
          beam.alpha = normal;
        }
      }
      beam.rho = best;
    } else {
      const Eigen::Vector2d c(0.3 * std::cos(0.4), 0.3 * std::sin(0.4));
      const double uc = u.dot(c);
      beam.rho = uc + std::sqrt(uc * uc - c.squaredNorm() + 4.0);
      const Eigen::Vector2d inward = (c - beam.rho * u) / 2.0;
      beam.alpha = std::atan2(inward.y(), inward.x());
    }
    beams.push_back(beam);
    sigma.push_back(0.01 * static_cast<double>(1 + i % 3));
    noise.push_back(sigma.back() * std::clamp(rng.Normal(), -2.0, 2.0));
    normal_noise.push_back(0.05 * rng.Normal());
  }
  Scene scene;
  scene.truth.resize(I(2 * m));
  for (std::size_t j = 0; j < m; ++j) {
    const std::size_t i = (j + seam) % m;
    const double turn = j + seam >= m ? kTwoPi : 0.0;
    ProblemPoint pt;
    pt.phi = beams[i].phi + turn;
    pt.rho_measured = beams[i].rho + noise[i];
    const double slack = 4.0 * sigma[i];
    pt.rho_lower = std::max(pt.rho_measured - slack, 0.5 * pt.rho_measured);
    pt.rho_upper = pt.rho_measured + slack;
    const double facing = pt.phi + kPi;
    pt.alpha_lower = facing - DegToRad(89.0);
    pt.alpha_upper = facing + DegToRad(89.0);
    const double alpha = facing + WrapAngle(beams[i].alpha - facing);
    pt.alpha_initial = alpha + normal_noise[i];
    pt.alpha_sigma = 0.2;
    scene.points.push_back(pt);
    scene.sigma.push_back(sigma[i]);
    scene.truth[I(2 * j)] = beams[i].rho;
    scene.truth[I(2 * j + 1)] = alpha;
  }
  // Link l (original numbering) joins original points l and l + 1 mod m.
  for (std::size_t j = 0; j < m; ++j) {
    const std::size_t l = (j + seam) % m;
    Link link = Link::kSameRegion;
    if (shape == RingShape::kRoom) {
      if (beams[l].alpha != beams[(l + 1) % m].alpha) link = Link::kDifferentRegion;
      if (l == m / 2 + 1) link = Link::kDifferentSurface;
    } else if (l == m / 3 || l == m - 1) {
      link = Link::kDifferentRegion;
    }
    scene.links.push_back(link);
  }
  return scene;
}

InnerProblem MakeRingProblem(const dsl::CompiledPrior& prior, const Scene& scene) {
  return InnerProblem(prior, scene.points, scene.links, scene.sigma, scene.precision, true);
}

// Evaluate's Hessian with rows and columns in the order of the unknowns.
MatrixXd NaturalHessian(InnerProblem& problem, const VectorXd& x, double lambda,
                        double barrier_weight, std::size_t* bandwidth = nullptr,
                        bool* positive_definite = nullptr) {
  SymmetricBandedMatrix banded;
  (void)problem.Evaluate(x, lambda, barrier_weight, nullptr, &banded);
  if (bandwidth) *bandwidth = banded.bandwidth();
  if (positive_definite) *positive_definite = BandedCholesky::Factor(banded).has_value();
  const MatrixXd dense = banded.ToDense();
  const std::size_t n = problem.num_unknowns();
  MatrixXd out(I(n), I(n));
  for (std::size_t u = 0; u < n; ++u) {
    for (std::size_t v = 0; v < n; ++v)
      out(I(u), I(v)) = dense(I(problem.HessianIndex(u)), I(problem.HessianIndex(v)));
  }
  return out;
}

// x of the ring with its seam at 0 as x of the ring with its seam at `seam` (MakeRing).
VectorXd MoveSeam(const VectorXd& x, std::size_t seam) {
  const std::size_t m = static_cast<std::size_t>(x.size()) / 2;
  VectorXd out(x.size());
  for (std::size_t j = 0; j < m; ++j) {
    const std::size_t i = (j + seam) % m;
    out[I(2 * j)] = x[I(2 * i)];
    out[I(2 * j + 1)] = x[I(2 * i + 1)] + (j + seam >= m ? kTwoPi : 0.0);
  }
  return out;
}

// Rows and columns of a matrix over the unknowns of the ring with its seam at 0, renumbered as
// those of the ring with its seam at `seam`.
MatrixXd MoveSeam(const MatrixXd& a, std::size_t seam) {
  const std::size_t n = static_cast<std::size_t>(a.rows()), m = n / 2;
  const auto at = [&](std::size_t u) { return 2 * ((u / 2 + seam) % m) + u % 2; };
  MatrixXd out(a.rows(), a.cols());
  for (std::size_t u = 0; u < n; ++u) {
    for (std::size_t v = 0; v < n; ++v) out(I(u), I(v)) = a(I(at(u)), I(at(v)));
  }
  return out;
}

struct RingCase {
  std::string prior;
  RingShape shape;
};

std::string RingCaseName(const ::testing::TestParamInfo<RingCase>& info) {
  std::string name = info.param.prior;
  std::replace(name.begin(), name.end(), '-', '_');
  return name;
}

class ClosedInnerProblem : public ::testing::TestWithParam<RingCase> {
 protected:
  void SetUp() override { prior_.emplace(dsl::PriorLibrary().Load(GetParam().prior).value()); }
  std::optional<dsl::CompiledPrior> prior_;
  static constexpr std::size_t kPoints = 40;
};

TEST_P(ClosedInnerProblem, IsTheSameProblemWhereverItsSeamIs) {
  const Scene base = MakeRing(GetParam().shape, kPoints, 0);
  InnerProblem reference = MakeRingProblem(*prior_, base);
  Rng rng(41);
  VectorXd x = base.truth;
  for (Index u = 0; u < x.size(); ++u) x[u] += (u % 2 == 0 ? 0.01 : 0.02) * rng.Normal();
  ASSERT_TRUE(reference.StrictlyInside(x));
  const double lambda = 1e2 * reference.data_weight(), barrier_weight = 1e-2;
  VectorXd gradient;
  const ObjectiveValue value = reference.Evaluate(x, lambda, barrier_weight, &gradient, nullptr);
  EXPECT_GT(value.penalty, 1e-6) << "an infeasible point: every window's penalty counts";
  const MatrixXd hessian = NaturalHessian(reference, x, lambda, barrier_weight);
  const MatrixXd rows = DenseJacobian(2 * kPoints, reference.EqualityRows(x));
  const std::vector<double> links = reference.LinkPenalties(x);
  for (const std::size_t seam : {1, 7, 20, 39}) {
    SCOPED_TRACE(::testing::Message() << GetParam().prior << ", seam at point " << seam);
    const Scene moved = MakeRing(GetParam().shape, kPoints, seam);
    InnerProblem problem = MakeRingProblem(*prior_, moved);
    const VectorXd y = MoveSeam(x, seam);
    VectorXd g;
    const ObjectiveValue v = problem.Evaluate(y, lambda, barrier_weight, &g, nullptr);
    for (const auto& [a, b] :
         {std::pair{value.data, v.data}, std::pair{value.energy, v.energy},
          std::pair{value.penalty, v.penalty}, std::pair{value.barrier, v.barrier},
          std::pair{value.max_residual, v.max_residual}}) {
      EXPECT_NEAR(a, b, 1e-9 * (1.0 + std::abs(a)));
    }
    // Gradient: a normal's component is that of the same normal (2 pi changes no derivative).
    VectorXd moved_gradient(gradient.size());
    for (std::size_t j = 0; j < kPoints; ++j) {
      for (std::size_t w = 0; w < 2; ++w)
        moved_gradient[I(2 * j + w)] = gradient[I(2 * ((j + seam) % kPoints) + w)];
    }
    EXPECT_TRUE(JacobiansMatch(g.transpose(), moved_gradient.transpose(), 1e-9));
    EXPECT_TRUE(JacobiansMatch(NaturalHessian(problem, y, lambda, barrier_weight),
                               MoveSeam(hessian, seam), 1e-9));
    // The same equality rows, in another order: the same J^T J.
    const MatrixXd j = DenseJacobian(2 * kPoints, problem.EqualityRows(y));
    EXPECT_EQ(j.rows(), rows.rows());
    EXPECT_TRUE(
        JacobiansMatch(j.transpose() * j, MoveSeam(MatrixXd(rows.transpose() * rows), seam), 1e-9));
    const std::vector<double> moved_links = problem.LinkPenalties(y);
    ASSERT_EQ(moved_links.size(), kPoints);
    for (std::size_t l = 0; l < kPoints; ++l) {
      EXPECT_NEAR(moved_links[l], links[(l + seam) % kPoints], 1e-9 * (1.0 + links[l])) << l;
    }
  }
}

TEST_P(ClosedInnerProblem, DerivativesMatchCentralDifferences) {
  const Scene scene = MakeRing(GetParam().shape, kPoints, 3);
  InnerProblem problem = MakeRingProblem(*prior_, scene);
  Rng rng(42);
  VectorXd x = scene.truth;
  for (Index u = 0; u < x.size(); ++u) x[u] += (u % 2 == 0 ? 0.01 : 0.02) * rng.Normal();
  const double lambda = 1e2 * problem.data_weight(), barrier_weight = 1e-2;
  VectorXd gradient;
  (void)problem.Evaluate(x, lambda, barrier_weight, &gradient, nullptr);
  const MatrixXd numeric = NumericJacobian(
      [&](const VectorXd& v) -> VectorXd {
        VectorXd total(1);
        total[0] = problem.Evaluate(v, lambda, barrier_weight, nullptr, nullptr)
                       .Total(lambda, barrier_weight);
        return total;
      },
      x, kStep);
  EXPECT_TRUE(JacobiansMatch(gradient.transpose(), numeric, kTolerance));
  // At the truth every residual vanishes and Gauss-Newton is the exact penalty Hessian: the
  // Hessian (data, penalty; no barrier) is then the derivative of the gradient, for priors
  // without energies (whose Hessians are clipped).
  ASSERT_LT(problem.Violations(scene.truth).max_residual, 1e-12);
  if (!problem.HasEnergyTerms()) {
    const auto gradient_at = [&](const VectorXd& v) -> VectorXd {
      VectorXd g;
      (void)problem.Evaluate(v, lambda, 0.0, &g, nullptr);
      return g;
    };
    EXPECT_TRUE(JacobiansMatch(NaturalHessian(problem, scene.truth, lambda, 0.0),
                               NumericJacobian(gradient_at, scene.truth, kStep), kTolerance));
  }
  // The rows of EqualityRows span the equalities' Jacobian: at the truth, where no branch of a
  // disjunction is near another, J^T J is the penalty's Gauss-Newton Hessian over 2.
  const MatrixXd j = DenseJacobian(problem.num_unknowns(), problem.EqualityRows(scene.truth));
  const MatrixXd penalty = (NaturalHessian(problem, scene.truth, 1.0, 0.0) -
                            NaturalHessian(problem, scene.truth, 0.0, 0.0));
  if (GetParam().prior != "rectangular-relaxed") {  // (its inequalities are no equality rows)
    EXPECT_TRUE(JacobiansMatch(2.0 * j.transpose() * j, penalty, 1e-8));
  }
}

// The Hessian of a ring is banded in its own order: 4 k - 3 unknowns for a window of k points
// (2 k - 1 in a chain), 4 b + 1 for a range precision of bandwidth b; and positive definite.
TEST_P(ClosedInnerProblem, HessianIsBandedInItsOrderAndPositiveDefinite) {
  const std::size_t k = static_cast<std::size_t>(prior_->order());
  for (const Noise noise : {Noise::kIndependent, Noise::kCorrelated}) {
    Scene scene = MakeRing(GetParam().shape, kPoints, 5);
    if (noise == Noise::kCorrelated)
      scene.precision = SymmetricBandedMatrix::Ar1Precision(scene.sigma, 0.5);
    InnerProblem problem = MakeRingProblem(*prior_, scene);
    std::size_t bandwidth = 0;
    bool positive_definite = false;
    const MatrixXd h = NaturalHessian(problem, scene.truth, 1e3 * problem.data_weight(), 1e-2,
                                      &bandwidth, &positive_definite);
    EXPECT_EQ(bandwidth, std::max<std::size_t>(4 * k - 3, noise == Noise::kCorrelated ? 5 : 1));
    EXPECT_TRUE(positive_definite);
    EXPECT_TRUE(h.isApprox(h.transpose(), 0.0));
    // The data term of the ring is that of the chain: no coupling across the seam.
    EXPECT_EQ(problem.data_information().ToDense(),
              InnerProblem(*prior_, scene.points,
                           std::vector<Link>(scene.links.begin(), scene.links.end() - 1),
                           scene.sigma, scene.precision)
                  .data_information()
                  .ToDense());
    // The windows across the seam couple the first points to the last.
    EXPECT_NE(h(1, I(2 * kPoints - 1)), 0.0);
  }
}

INSTANTIATE_TEST_SUITE_P(Priors, ClosedInnerProblem,
                         ::testing::Values(RingCase{"polygonal", RingShape::kRoom},
                                           RingCase{"rectangular", RingShape::kRoom},
                                           RingCase{"manhattan", RingShape::kRoom},
                                           RingCase{"rectangular-relaxed", RingShape::kRoom},
                                           RingCase{"splines", RingShape::kCircle},
                                           RingCase{"circular", RingShape::kCircle},
                                           RingCase{"straight-or-circular", RingShape::kCircle}),
                         RingCaseName);

TEST(ClosedInnerProblemContract, NeedsMorePointsThanTheOrderAndOneLinkPerPoint) {
  const dsl::CompiledPrior prior = dsl::PriorLibrary().Load("circular").value();
  const Scene ring = MakeRing(RingShape::kCircle, 12, 0);
  EXPECT_THROW((void)InnerProblem(prior, ring.points,
                                  std::vector<Link>(ring.links.begin(), ring.links.end() - 1),
                                  ring.sigma, std::nullopt, true),
               ContractError);
  const Scene tiny = MakeRing(RingShape::kCircle, 3, 0);
  EXPECT_THROW((void)InnerProblem(prior, tiny.points, tiny.links, tiny.sigma, std::nullopt, true),
               ContractError);
}

}  // namespace
}  // namespace priormap::priorlets
