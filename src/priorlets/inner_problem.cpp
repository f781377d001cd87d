#include "inner_problem.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>

#include <priormap/core/check.hpp>
#include <priormap/dsl/penalty.hpp>

namespace priormap::priorlets {
namespace {

// The residual whose square is the term's penalty: f, or max(0, g).
double Residual(const dsl::Term& term, double value) {
  return term.kind == dsl::TermKind::kInequality ? std::max(0.0, value) : value;
}

// Largest residual of one window: plain terms directly, a disjunction by its best branch.
double WindowMaxResidual(const dsl::CompiledBlock& block, const double* values) {
  const std::vector<dsl::Term>& terms = block.terms();
  double worst = 0.0;
  std::array<double, 16> branch_worst{};
  const int groups = block.num_disjunctions();
  for (int g = 0; g < groups; ++g) {
    branch_worst.fill(0.0);
    int branches = 0;
    for (std::size_t t = 0; t < terms.size(); ++t) {
      if (terms[t].disjunction != g || terms[t].branch >= static_cast<int>(branch_worst.size()))
        continue;
      const auto b = static_cast<std::size_t>(terms[t].branch);
      branch_worst[b] = std::max(branch_worst[b], std::abs(Residual(terms[t], values[t])));
      branches = std::max(branches, terms[t].branch + 1);
    }
    if (branches > 0) {
      worst =
          std::max(worst, *std::min_element(branch_worst.begin(), branch_worst.begin() + branches));
    }
  }
  for (std::size_t t = 0; t < terms.size(); ++t) {
    if (terms[t].disjunction >= 0 || terms[t].kind == dsl::TermKind::kEnergy) continue;
    worst = std::max(worst, std::abs(Residual(terms[t], values[t])));
  }
  return worst;
}

bool HasEnergies(const dsl::CompiledBlock& block) {
  return block.summary().energies > 0;
}

// Disjunctions and branches a block may have for the allocation-free penalty below; larger
// blocks go through dsl::AccumulatePenalty.
constexpr int kMaxDisjunctions = 8;
constexpr int kMaxBranches = 8;

bool FitsFastPenalty(const dsl::CompiledBlock& block) {
  if (block.num_disjunctions() > kMaxDisjunctions) return false;
  for (const dsl::Term& term : block.terms()) {
    if (term.branch >= kMaxBranches) return false;
  }
  return true;
}

struct WindowPenalty {
  double constraint = 0.0;
  double energy = 0.0;
  double max_residual = 0.0;
};

// The penalty forms of dsl::AccumulatePenalty (Gauss-Newton, lambda-weighted) for one window,
// without allocating, plus the window's largest residual. `gradient` (nv) and `hessian`
// (nv x nv, column-major, lower triangle used) may be null.
WindowPenalty AccumulateWindow(const dsl::CompiledBlock& block, const double* values,
                               const double* grads, const double* hess, double lambda,
                               double* gradient, double* hessian) {
  const std::vector<dsl::Term>& terms = block.terms();
  const auto nv = static_cast<std::size_t>(block.num_variables());
  WindowPenalty out;
  // Only the first `groups` rows are used (initialised here, not for every window of a block
  // without disjunctions).
  std::array<std::array<double, kMaxBranches>, kMaxDisjunctions> sum, worst;
  std::array<int, kMaxDisjunctions> branches, active;
  const int groups = block.num_disjunctions();
  for (int g = 0; g < groups; ++g) {
    sum[static_cast<std::size_t>(g)].fill(0.0);
    worst[static_cast<std::size_t>(g)].fill(0.0);
    branches[static_cast<std::size_t>(g)] = 0;
    active[static_cast<std::size_t>(g)] = 0;
  }
  for (std::size_t t = 0; groups > 0 && t < terms.size(); ++t) {
    const dsl::Term& term = terms[t];
    if (term.disjunction < 0) continue;
    const auto g = static_cast<std::size_t>(term.disjunction),
               b = static_cast<std::size_t>(term.branch);
    const double r = Residual(term, values[t]);
    sum[g][b] += r * r;
    worst[g][b] = std::max(worst[g][b], std::abs(r));
    branches[g] = std::max(branches[g], term.branch + 1);
  }
  for (int g = 0; g < groups; ++g) {
    const auto gi = static_cast<std::size_t>(g);
    for (int b = 1; b < branches[gi]; ++b) {
      if (sum[gi][static_cast<std::size_t>(b)] < sum[gi][static_cast<std::size_t>(active[gi])])
        active[gi] = b;
    }
    out.constraint += sum[gi][static_cast<std::size_t>(active[gi])];
    out.max_residual = std::max(out.max_residual, worst[gi][static_cast<std::size_t>(active[gi])]);
  }
  for (std::size_t t = 0; t < terms.size(); ++t) {
    const dsl::Term& term = terms[t];
    const double* grad = grads ? grads + t * nv : nullptr;
    if (term.kind == dsl::TermKind::kEnergy) {
      out.energy += values[t];
      if (gradient && grad) {
        for (std::size_t i = 0; i < nv; ++i) gradient[i] += grad[i];
      }
      if (hessian && hess) {
        for (std::size_t i = 0; i < nv * nv; ++i) hessian[i] += hess[t * nv * nv + i];
      }
      continue;
    }
    if (term.disjunction >= 0 && term.branch != active[static_cast<std::size_t>(term.disjunction)])
      continue;
    const double r = Residual(term, values[t]);
    if (term.disjunction < 0) {
      out.constraint += r * r;
      out.max_residual = std::max(out.max_residual, std::abs(r));
    }
    if (r == 0.0 || !grad) continue;
    if (gradient) {
      for (std::size_t i = 0; i < nv; ++i) gradient[i] += 2.0 * lambda * r * grad[i];
    }
    if (hessian) {
      for (std::size_t j = 0; j < nv; ++j) {
        const double gj = 2.0 * lambda * grad[j];
        for (std::size_t i = j; i < nv; ++i) hessian[j * nv + i] += gj * grad[i];
      }
    }
  }
  return out;
}

// Clips the eigenvalues of a small symmetric matrix at zero: the nearest positive
// semi-definite matrix, so that a non-convex energy turns its window's Newton step into a
// gradient step there instead of an ascent direction.
void MakePositiveSemidefinite(Eigen::Ref<Eigen::MatrixXd> h) {
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(h);
  if (eig.eigenvalues().minCoeff() >= 0.0) return;
  const Eigen::VectorXd clipped = eig.eigenvalues().cwiseMax(0.0);
  h = eig.eigenvectors() * clipped.asDiagonal() * eig.eigenvectors().transpose();
}

}  // namespace

const char* ToString(Link link) {
  switch (link) {
    case Link::kSameRegion:
      return "same_region";
    case Link::kDifferentRegion:
      return "different_region";
    case Link::kDifferentSurface:
      return "different_surface";
  }
  return "?";
}

InnerProblem::InnerProblem(const dsl::CompiledPrior& prior, std::vector<ProblemPoint> points,
                           std::vector<Link> links, std::vector<double> range_sigma,
                           std::optional<SymmetricBandedMatrix> range_precision)
    : order_(prior.order()),
      points_(std::move(points)),
      links_(std::move(links)),
      range_sigma_(std::move(range_sigma)),
      range_precision_(std::move(range_precision)) {
  const std::size_t m = points_.size();
  const auto k = static_cast<std::size_t>(order_);
  PRIORMAP_CHECK(links_.size() + 1 == std::max<std::size_t>(m, 1),
                 "one link between consecutive points");
  PRIORMAP_CHECK(range_sigma_.size() == m, "one sigma per point");
  for (int kind = 0; kind < dsl::kNumBlockKinds; ++kind) {
    windows_[static_cast<std::size_t>(kind)].block = prior.block(static_cast<dsl::BlockKind>(kind));
  }
  // A window takes the block of its weakest link: a window across a region border is a
  // different_region window, one across a surface border a different_surface window.
  for (std::size_t first = 0; m >= k && first + k <= m; ++first) {
    Link weakest = Link::kSameRegion;
    for (std::size_t l = first; l + 1 < first + k; ++l) weakest = std::max(weakest, links_[l]);
    BlockWindows& bw = windows_[static_cast<std::size_t>(weakest)];
    if (bw.block == nullptr || bw.block->num_terms() == 0) continue;
    bw.first_point.push_back(first);
    for (std::size_t i = 0; i < k; ++i) bw.phi.push_back(points_[first + i].phi);
  }
  for (BlockWindows& bw : windows_) {
    if (bw.first_point.empty()) continue;
    const std::size_t n = bw.first_point.size(),
                      nt = static_cast<std::size_t>(bw.block->num_terms());
    const std::size_t nv = 2 * k;
    bw.evaluator = std::make_unique<dsl::BlockEvaluator>(*bw.block);
    bw.x.resize(n * nv);
    bw.values.resize(n * nt);
    bw.gradients.resize(n * nt * nv);
    bw.hessians.resize(n * nt * nv * nv);
  }
  for (int v = 0; v < static_cast<int>(2 * k); ++v) global_index_.push_back(GlobalIndex(0, v));
  bandwidth_ = std::max<std::size_t>(1, 2 * k - 1);
  if (range_precision_) {
    PRIORMAP_CHECK(range_precision_->size() == m, "range precision of the wrong size");
    bandwidth_ = std::max(bandwidth_, 2 * range_precision_->bandwidth() + 1);
  }
}

std::size_t InnerProblem::GlobalIndex(std::size_t p, int v) const {
  // Block unknowns are rho_1..rho_k, alpha_1..alpha_k.
  return v < order_ ? 2 * (p + static_cast<std::size_t>(v))
                    : 2 * (p + static_cast<std::size_t>(v - order_)) + 1;
}

Eigen::VectorXd InnerProblem::InitialPoint() const {
  Eigen::VectorXd x(static_cast<Eigen::Index>(num_unknowns()));
  const auto inside = [](double v, double lo, double hi) {
    const double margin = 1e-3 * (hi - lo);
    return std::clamp(v, lo + margin, hi - margin);
  };
  for (std::size_t p = 0; p < points_.size(); ++p) {
    const ProblemPoint& pt = points_[p];
    x[static_cast<Eigen::Index>(2 * p)] = inside(pt.rho_measured, pt.rho_lower, pt.rho_upper);
    x[static_cast<Eigen::Index>(2 * p + 1)] =
        inside(pt.alpha_initial, pt.alpha_lower, pt.alpha_upper);
  }
  return x;
}

bool InnerProblem::StrictlyInside(const Eigen::VectorXd& x) const {
  for (std::size_t p = 0; p < points_.size(); ++p) {
    const ProblemPoint& pt = points_[p];
    const double rho = x[static_cast<Eigen::Index>(2 * p)],
                 alpha = x[static_cast<Eigen::Index>(2 * p + 1)];
    if (!(rho > pt.rho_lower && rho < pt.rho_upper && alpha > pt.alpha_lower &&
          alpha < pt.alpha_upper))
      return false;
  }
  return true;
}

double InnerProblem::MaxStep(const Eigen::VectorXd& x, const Eigen::VectorXd& d,
                             double fraction) const {
  double t = 1.0;
  const auto limit = [&](double v, double dv, double lo, double hi) {
    if (dv > 0.0) t = std::min(t, fraction * (hi - v) / dv);
    if (dv < 0.0) t = std::min(t, fraction * (lo - v) / dv);
  };
  for (std::size_t p = 0; p < points_.size(); ++p) {
    const ProblemPoint& pt = points_[p];
    const auto r = static_cast<Eigen::Index>(2 * p);
    limit(x[r], d[r], pt.rho_lower, pt.rho_upper);
    limit(x[r + 1], d[r + 1], pt.alpha_lower, pt.alpha_upper);
  }
  return t;
}

void InnerProblem::EvaluateWindows(const Eigen::VectorXd& x, int level) {
  const auto k = static_cast<std::size_t>(order_);
  const std::size_t nv = 2 * k;
  for (BlockWindows& bw : windows_) {
    if (bw.first_point.empty()) continue;
    for (std::size_t w = 0; w < bw.first_point.size(); ++w) {
      for (int v = 0; v < static_cast<int>(nv); ++v) {
        bw.x[w * nv + static_cast<std::size_t>(v)] =
            x[static_cast<Eigen::Index>(GlobalIndex(bw.first_point[w], v))];
      }
    }
    bw.evaluator->EvaluateBatch(bw.first_point.size(), bw.x, bw.phi, bw.values.data(),
                                level >= 1 ? bw.gradients.data() : nullptr,
                                level >= 2 ? bw.hessians.data() : nullptr);
  }
}

ObjectiveValue InnerProblem::Evaluate(const Eigen::VectorXd& x, double lambda,
                                      double barrier_weight, Eigen::VectorXd* gradient,
                                      SymmetricBandedMatrix* hessian) {
  ObjectiveValue value;
  const std::size_t m = points_.size();
  if (gradient) gradient->setZero(static_cast<Eigen::Index>(num_unknowns()));
  if (hessian) {
    if (hessian->size() != num_unknowns() || hessian->bandwidth() != bandwidth_) {
      *hessian = SymmetricBandedMatrix(num_unknowns(), bandwidth_);
    } else {
      hessian->SetZero();
    }
  }

  // Measurements (ranges) and the weak prior on the initial normals.
  Eigen::VectorXd range_residual(static_cast<Eigen::Index>(m));
  for (std::size_t p = 0; p < m; ++p) {
    range_residual[static_cast<Eigen::Index>(p)] =
        x[static_cast<Eigen::Index>(2 * p)] - points_[p].rho_measured;
  }
  if (range_precision_) {
    const Eigen::VectorXd wr = range_precision_->Multiply(range_residual);
    value.data += 0.5 * range_residual.dot(wr);
    for (std::size_t p = 0; p < m; ++p) {
      if (gradient)
        (*gradient)[static_cast<Eigen::Index>(2 * p)] += wr[static_cast<Eigen::Index>(p)];
      if (hessian) {
        for (std::size_t q = p; q <= std::min(m - 1, p + range_precision_->bandwidth()); ++q) {
          hessian->Add(2 * q, 2 * p, (*range_precision_)(q, p));
        }
      }
    }
  } else {
    for (std::size_t p = 0; p < m; ++p) {
      const double w = 1.0 / (range_sigma_[p] * range_sigma_[p]);
      const double r = range_residual[static_cast<Eigen::Index>(p)];
      value.data += 0.5 * w * r * r;
      if (gradient) (*gradient)[static_cast<Eigen::Index>(2 * p)] += w * r;
      if (hessian) hessian->Add(2 * p, 2 * p, w);
    }
  }
  for (std::size_t p = 0; p < m; ++p) {
    const double w = 1.0 / (points_[p].alpha_sigma * points_[p].alpha_sigma);
    const double r = x[static_cast<Eigen::Index>(2 * p + 1)] - points_[p].alpha_initial;
    value.data += 0.5 * w * r * r;
    if (gradient) (*gradient)[static_cast<Eigen::Index>(2 * p + 1)] += w * r;
    if (hessian) hessian->Add(2 * p + 1, 2 * p + 1, w);
  }

  // Log barrier of the bounds.
  for (std::size_t p = 0; p < m; ++p) {
    const ProblemPoint& pt = points_[p];
    for (int which = 0; which < 2; ++which) {
      const std::size_t i = 2 * p + static_cast<std::size_t>(which);
      const double v = x[static_cast<Eigen::Index>(i)];
      const double lo = which == 0 ? pt.rho_lower : pt.alpha_lower;
      const double hi = which == 0 ? pt.rho_upper : pt.alpha_upper;
      const double a = v - lo, b = hi - v;
      if (!(a > 0.0 && b > 0.0)) {
        value.barrier = std::numeric_limits<double>::infinity();
        continue;
      }
      value.barrier -= std::log(a * b);
      if (gradient)
        (*gradient)[static_cast<Eigen::Index>(i)] += barrier_weight * (-1.0 / a + 1.0 / b);
      if (hessian) hessian->Add(i, i, barrier_weight * (1.0 / (a * a) + 1.0 / (b * b)));
    }
  }

  // Priorlets.
  const int level = hessian ? 2 : (gradient ? 1 : 0);
  EvaluateWindows(x, level);
  const std::size_t nv = 2 * static_cast<std::size_t>(order_);
  dsl::PenaltyOptions penalty_options;
  penalty_options.lambda = lambda;
  penalty_options.gauss_newton = true;
  Eigen::VectorXd window_gradient(static_cast<Eigen::Index>(nv));
  Eigen::MatrixXd window_hessian(static_cast<Eigen::Index>(nv), static_cast<Eigen::Index>(nv));
  Eigen::MatrixXd energy_hessian(static_cast<Eigen::Index>(nv), static_cast<Eigen::Index>(nv));
  for (BlockWindows& bw : windows_) {
    if (bw.first_point.empty()) continue;
    const std::size_t nt = static_cast<std::size_t>(bw.block->num_terms());
    const bool energies = HasEnergies(*bw.block);
    const bool fast = FitsFastPenalty(*bw.block);
    for (std::size_t w = 0; w < bw.first_point.size(); ++w) {
      const double* values = bw.values.data() + w * nt;
      const double* grads = level >= 1 ? bw.gradients.data() + w * nt * nv : nullptr;
      const double* hess = level >= 2 ? bw.hessians.data() + w * nt * nv * nv : nullptr;
      if (gradient) window_gradient.setZero();
      if (hessian) window_hessian.setZero();
      // Penalties in Gauss-Newton form (positive semi-definite), energies exact.
      if (fast) {
        const WindowPenalty wp = AccumulateWindow(*bw.block, values, grads, hess, lambda,
                                                  gradient ? window_gradient.data() : nullptr,
                                                  hessian ? window_hessian.data() : nullptr);
        value.penalty += wp.constraint;
        value.energy += wp.energy;
        value.max_residual = std::max(value.max_residual, wp.max_residual);
      } else {
        const dsl::PenaltyValue pv = dsl::AccumulatePenalty(
            *bw.block, values, grads, hess, penalty_options,
            gradient ? window_gradient.data() : nullptr, hessian ? window_hessian.data() : nullptr);
        value.penalty += pv.constraint;
        value.energy += pv.energy;
        value.max_residual = std::max(value.max_residual, WindowMaxResidual(*bw.block, values));
      }
      // Energies' Hessians are replaced by their positive semi-definite part.
      if (hessian && energies) {
        energy_hessian.setZero();
        for (std::size_t t = 0; t < nt; ++t) {
          if (bw.block->terms()[t].kind != dsl::TermKind::kEnergy) continue;
          energy_hessian += Eigen::Map<const Eigen::MatrixXd>(
              hess + t * nv * nv, static_cast<Eigen::Index>(nv), static_cast<Eigen::Index>(nv));
        }
        window_hessian -= energy_hessian;
        MakePositiveSemidefinite(energy_hessian);
        window_hessian += energy_hessian;
      }
      if (!gradient && !hessian) continue;
      const std::size_t p = bw.first_point[w];
      const std::size_t* global = global_index_.data();
      for (std::size_t a = 0; a < nv; ++a) {
        const std::size_t ga = 2 * p + global[a];
        if (gradient)
          (*gradient)[static_cast<Eigen::Index>(ga)] +=
              window_gradient[static_cast<Eigen::Index>(a)];
        if (!hessian) continue;
        for (std::size_t b = 0; b <= a; ++b) {
          const double h =
              window_hessian(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b));
          if (h != 0.0) hessian->Add(ga, 2 * p + global[b], h);
        }
      }
    }
  }
  return value;
}

Violation InnerProblem::Violations(const Eigen::VectorXd& x) {
  const ObjectiveValue value = Evaluate(x, 0.0, 0.0, nullptr, nullptr);
  return {value.max_residual, value.penalty};
}

std::vector<double> InnerProblem::LinkPenalties(const Eigen::VectorXd& x) {
  EvaluateWindows(x, 0);
  std::vector<double> penalties(links_.size(), 0.0);
  for (BlockWindows& bw : windows_) {
    if (bw.first_point.empty()) continue;
    const std::size_t nt = static_cast<std::size_t>(bw.block->num_terms());
    for (std::size_t w = 0; w < bw.first_point.size(); ++w) {
      const double c = dsl::AccumulatePenalty(*bw.block, bw.values.data() + w * nt, nullptr,
                                              nullptr, {}, nullptr, nullptr)
                           .constraint;
      const std::size_t first = bw.first_point[w];
      for (std::size_t l = first; l + 1 < first + static_cast<std::size_t>(order_); ++l)
        penalties[l] += c;
      // An order-1 prior has no links inside a window: blame the links around the point.
      if (order_ == 1) {
        if (first > 0) penalties[first - 1] += c;
        if (first < links_.size()) penalties[first] += c;
      }
    }
  }
  return penalties;
}

std::vector<InnerProblem::JacobianRow> InnerProblem::EqualityJacobian(const Eigen::VectorXd& x) {
  EvaluateWindows(x, 1);
  std::vector<JacobianRow> rows;
  const std::size_t nv = 2 * static_cast<std::size_t>(order_);
  std::vector<int> active;
  for (BlockWindows& bw : windows_) {
    if (bw.first_point.empty()) continue;
    const std::size_t nt = static_cast<std::size_t>(bw.block->num_terms());
    const std::vector<dsl::Term>& terms = bw.block->terms();
    for (std::size_t w = 0; w < bw.first_point.size(); ++w) {
      const double* values = bw.values.data() + w * nt;
      dsl::AccumulatePenalty(*bw.block, values, nullptr, nullptr, {}, nullptr, nullptr, &active);
      for (std::size_t t = 0; t < nt; ++t) {
        const dsl::Term& term = terms[t];
        if (term.kind != dsl::TermKind::kEquality) continue;
        if (term.disjunction >= 0 &&
            active[static_cast<std::size_t>(term.disjunction)] != term.branch)
          continue;
        // Reorder the block's unknowns (rho..., alpha...) to the interleaved global order.
        JacobianRow row{2 * bw.first_point[w], std::vector<double>(nv, 0.0)};
        for (int v = 0; v < static_cast<int>(nv); ++v) {
          row.coefficients[GlobalIndex(bw.first_point[w], v) - row.first] =
              bw.gradients[(w * nt + t) * nv + static_cast<std::size_t>(v)];
        }
        rows.push_back(std::move(row));
      }
    }
  }
  std::sort(rows.begin(), rows.end(),
            [](const JacobianRow& a, const JacobianRow& b) { return a.first < b.first; });
  return rows;
}

SymmetricBandedMatrix InnerProblem::EnergyHessian(const Eigen::VectorXd& x) {
  SymmetricBandedMatrix h(num_unknowns(), bandwidth_);
  EvaluateWindows(x, 2);
  const std::size_t nv = 2 * static_cast<std::size_t>(order_);
  Eigen::MatrixXd window(static_cast<Eigen::Index>(nv), static_cast<Eigen::Index>(nv));
  for (BlockWindows& bw : windows_) {
    if (bw.first_point.empty() || !HasEnergies(*bw.block)) continue;
    const std::size_t nt = static_cast<std::size_t>(bw.block->num_terms());
    for (std::size_t w = 0; w < bw.first_point.size(); ++w) {
      window.setZero();
      for (std::size_t t = 0; t < nt; ++t) {
        if (bw.block->terms()[t].kind != dsl::TermKind::kEnergy) continue;
        window += Eigen::Map<const Eigen::MatrixXd>(bw.hessians.data() + (w * nt + t) * nv * nv,
                                                    static_cast<Eigen::Index>(nv),
                                                    static_cast<Eigen::Index>(nv));
      }
      MakePositiveSemidefinite(window);
      const std::size_t p = bw.first_point[w];
      for (int a = 0; a < static_cast<int>(nv); ++a) {
        for (int b = 0; b <= a; ++b) h.Add(GlobalIndex(p, a), GlobalIndex(p, b), window(a, b));
      }
    }
  }
  return h;
}

SymmetricBandedMatrix InnerProblem::DataInformation() const {
  SymmetricBandedMatrix info(num_unknowns(), bandwidth_);
  const std::size_t m = points_.size();
  for (std::size_t p = 0; p < m; ++p) {
    if (range_precision_) {
      for (std::size_t q = p; q <= std::min(m - 1, p + range_precision_->bandwidth()); ++q) {
        info.Add(2 * q, 2 * p, (*range_precision_)(q, p));
      }
    } else {
      info.Add(2 * p, 2 * p, 1.0 / (range_sigma_[p] * range_sigma_[p]));
    }
    info.Add(2 * p + 1, 2 * p + 1, 1.0 / (points_[p].alpha_sigma * points_[p].alpha_sigma));
  }
  return info;
}

}  // namespace priormap::priorlets
