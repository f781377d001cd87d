#include "inner_problem.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numbers>
#include <span>

#include <Eigen/Eigenvalues>

#include <priormap/core/check.hpp>
#include <priormap/dsl/penalty.hpp>

namespace priormap::priorlets {
namespace {

bool HasEnergies(const dsl::CompiledBlock& block) {
  return block.summary().energies > 0;
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

// The sum of the Hessians of a window's energy terms (`hess`: the window's term Hessians).
void SumEnergyHessians(const dsl::CompiledBlock& block, const double* values, const double* hess,
                       Eigen::MatrixXd& out) {
  const auto nv = static_cast<std::size_t>(block.num_variables());
  out.setZero();
  for (std::size_t t = 0; t < block.terms().size(); ++t) {
    if (block.terms()[t].kind != dsl::TermKind::kEnergy) continue;
    // An energy outside its domain adds no derivatives (dsl::AccumulatePenalty): nor here.
    if (std::isnan(values[t])) continue;
    out += Eigen::Map<const Eigen::MatrixXd>(hess + t * nv * nv, out.rows(), out.cols());
  }
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
                           std::optional<SymmetricBandedMatrix> range_precision, bool closed)
    : order_(prior.order()), points_(std::move(points)), links_(std::move(links)), closed_(closed) {
  const std::size_t m = points_.size();
  const auto k = static_cast<std::size_t>(order_);
  if (closed_) {
    PRIORMAP_CHECK(m > k && links_.size() == m,
                   "a closed problem has more points than the prior's order and one link each");
  } else {
    PRIORMAP_CHECK(links_.size() + 1 == std::max<std::size_t>(m, 1),
                   "one link between consecutive points");
  }
  PRIORMAP_CHECK(range_sigma.size() == m, "one sigma per point");
  for (int kind = 0; kind < dsl::kNumBlockKinds; ++kind) {
    windows_[static_cast<std::size_t>(kind)].block = prior.block(static_cast<dsl::BlockKind>(kind));
  }
  // A window takes the block of its weakest link: a window across a region border is a
  // different_region window, one across a surface border a different_surface window. A ring has
  // a window starting at every point; those across the seam see their later points a turn on.
  const std::size_t num_windows = closed_ ? m : (m >= k ? m - k + 1 : 0);
  for (std::size_t first = 0; first < num_windows; ++first) {
    Link weakest = Link::kSameRegion;
    for (std::size_t l = first; l + 1 < first + k; ++l)
      weakest = std::max(weakest, links_[l < m ? l : l - m]);
    BlockWindows& bw = windows_[static_cast<std::size_t>(weakest)];
    if (bw.block == nullptr || bw.block->num_terms() == 0) continue;
    bw.first_point.push_back(first);
    for (std::size_t i = 0; i < k; ++i) {
      const std::size_t q = first + i;
      bw.phi.push_back(q < m ? points_[q].phi : points_[q - m].phi + 2.0 * std::numbers::pi);
    }
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
  for (std::size_t v = 0; v < 2 * k; ++v) global_index_.push_back(v < k ? 2 * v : 2 * (v - k) + 1);
  bandwidth_ = std::max<std::size_t>(1, 2 * k - 1);
  if (range_precision) {
    PRIORMAP_CHECK(range_precision->size() == m, "range precision of the wrong size");
    bandwidth_ = std::max(bandwidth_, 2 * range_precision->bandwidth() + 1);
  }
  // A ring's Hessian order: point p at position 2p in the first half, 2 (m - 1 - p) + 1 in the
  // second. Points d apart along the ring (either way round) are at most 2 d apart there, so
  // a window (d <= k - 1) spans at most 4 k - 3 unknowns, the range precision 4 b + 1.
  std::size_t hessian_bandwidth = bandwidth_;
  if (closed_) {
    hessian_index_.resize(2 * m);
    for (std::size_t p = 0; p < m; ++p) {
      const std::size_t position = 2 * p < m ? 2 * p : 2 * (m - 1 - p) + 1;
      hessian_index_[2 * p] = 2 * position;
      hessian_index_[2 * p + 1] = 2 * position + 1;
    }
    hessian_bandwidth = std::max<std::size_t>(1, 4 * k - 3);
    if (range_precision)
      hessian_bandwidth = std::max(hessian_bandwidth, 4 * range_precision->bandwidth() + 1);
  }
  // The data term is the quadratic 1/2 (x - target)^T information (x - target), fixed for the
  // whole solve.
  data_information_ = SymmetricBandedMatrix(num_unknowns(), bandwidth_);
  data_target_.resize(static_cast<Eigen::Index>(num_unknowns()));
  for (std::size_t p = 0; p < m; ++p) {
    if (range_precision) {
      for (std::size_t q = p; q <= std::min(m - 1, p + range_precision->bandwidth()); ++q) {
        data_information_.Add(2 * q, 2 * p, (*range_precision)(q, p));
      }
    } else {
      data_information_.Add(2 * p, 2 * p, 1.0 / (range_sigma[p] * range_sigma[p]));
    }
    data_information_.Add(2 * p + 1, 2 * p + 1,
                          1.0 / (points_[p].alpha_sigma * points_[p].alpha_sigma));
    data_target_[static_cast<Eigen::Index>(2 * p)] = points_[p].rho_measured;
    data_target_[static_cast<Eigen::Index>(2 * p + 1)] = points_[p].alpha_initial;
  }
  if (closed_) {
    hessian_data_information_ = SymmetricBandedMatrix(num_unknowns(), hessian_bandwidth);
    const std::size_t n = num_unknowns();
    for (std::size_t j = 0; j < n; ++j) {
      for (std::size_t i = j; i <= std::min(n - 1, j + bandwidth_); ++i) {
        const double v = data_information_(i, j);
        if (v != 0.0) hessian_data_information_.Add(hessian_index_[i], hessian_index_[j], v);
      }
    }
  }
  for (BlockWindows& bw : windows_) {
    if (!bw.first_point.empty()) FindRangeScales(bw);
  }
}

Eigen::VectorXd InnerProblem::ToHessianOrder(const Eigen::VectorXd& v) const {
  if (hessian_index_.empty()) return v;
  Eigen::VectorXd out(v.size());
  for (std::size_t u = 0; u < hessian_index_.size(); ++u)
    out[static_cast<Eigen::Index>(hessian_index_[u])] = v[static_cast<Eigen::Index>(u)];
  return out;
}

Eigen::VectorXd InnerProblem::FromHessianOrder(const Eigen::VectorXd& v) const {
  if (hessian_index_.empty()) return v;
  Eigen::VectorXd out(v.size());
  for (std::size_t u = 0; u < hessian_index_.size(); ++u)
    out[static_cast<Eigen::Index>(u)] = v[static_cast<Eigen::Index>(hessian_index_[u])];
  return out;
}

double InnerProblem::data_weight() const {
  double weight = 0.0;
  for (std::size_t i = 0; i < data_information_.size(); ++i) {
    weight = std::max(weight, data_information_(i, i));
  }
  return weight;
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

void InnerProblem::FillWindow(BlockWindows& bw, std::size_t w, const Eigen::VectorXd& x) const {
  const auto k = static_cast<std::size_t>(order_);
  const std::size_t nv = 2 * k, m = points_.size();
  const std::size_t first = bw.first_point[w];
  if (closed_ && first + k > m) {
    // Across the seam: the normals of the points past it a turn on, as their phi.
    for (std::size_t v = 0; v < nv; ++v) {
      const bool later = v >= k && first + (v - k) >= m;
      bw.x[w * nv + v] = x[static_cast<Eigen::Index>(WindowUnknown(first, v))] +
                         (later ? 2.0 * std::numbers::pi : 0.0);
    }
    return;
  }
  for (std::size_t v = 0; v < nv; ++v)
    bw.x[w * nv + v] = x[static_cast<Eigen::Index>(2 * first + global_index_[v])];
}

void InnerProblem::FindRangeScales(BlockWindows& bw) {
  const auto k = static_cast<std::size_t>(order_);
  const std::size_t nv = 2 * k, m = points_.size(), nt = bw.values.size() / bw.first_point.size();
  std::vector<double> scale(bw.first_point.size(), 1.0);
  bool far = false;
  for (std::size_t w = 0; w < scale.size(); ++w) {
    for (std::size_t i = 0; i < k; ++i) {
      const std::size_t q = bw.first_point[w] + i;
      scale[w] = std::max(scale[w], points_[q < m ? q : q - m].rho_measured / kUnitRange);
    }
    far = far || scale[w] > 1.0;
  }
  if (!far) return;
  // Only terms homogeneous in the ranges are rescaled: the normals' constraints are in radians
  // at any scale, and a term with a length of its own (a curvature bound of 10 / m) means it in
  // metres. A term's degree from its values with the ranges doubled and halved (exact in
  // floating point, so a homogeneous term's value scales to rounding), at the first windows
  // where it is not zero; the point is the data's, off the constraints.
  const Eigen::VectorXd x0 = InitialPoint();
  std::vector<int> degree(nt, 0);
  std::vector<char> decided(nt, 0);
  const std::vector<dsl::Term>& terms = bw.block->terms();
  std::array<std::vector<double>, 3> values;
  constexpr std::size_t kWindowsTried = 8;
  for (std::size_t w = 0; w < std::min(kWindowsTried, bw.first_point.size()); ++w) {
    FillWindow(bw, w, x0);
    const std::span<const double> phi(bw.phi.data() + w * k, k);
    for (std::size_t s = 0; s < 3; ++s) {
      const double factor = s == 0 ? 1.0 : (s == 1 ? 2.0 : 0.5);
      std::vector<double> xw(bw.x.begin() + static_cast<std::ptrdiff_t>(w * nv),
                             bw.x.begin() + static_cast<std::ptrdiff_t>((w + 1) * nv));
      for (std::size_t v = 0; v < k; ++v) xw[v] *= factor;
      values[s].assign(nt, 0.0);
      bw.evaluator->Evaluate(xw, phi, values[s].data());
    }
    for (std::size_t t = 0; t < nt; ++t) {
      if (decided[t] || terms[t].kind == dsl::TermKind::kEnergy) continue;
      const double f = values[0][t];
      if (!(std::isfinite(f) && f != 0.0)) continue;
      decided[t] = 1;
      for (const int d : {-2, -1, 1, 2}) {
        const double up = std::ldexp(f, d), down = std::ldexp(f, -d);
        if (std::abs(values[1][t] - up) <= 1e-9 * std::abs(up) &&
            std::abs(values[2][t] - down) <= 1e-9 * std::abs(down)) {
          degree[t] = d;
        }
      }
    }
  }
  if (std::all_of(degree.begin(), degree.end(), [](int d) { return d == 0; })) return;
  bw.range_degree = std::move(degree);
  bw.range_scale = std::move(scale);
}

void InnerProblem::RescaleWindow(BlockWindows& bw, std::size_t w, int level) const {
  const std::size_t nt = bw.range_degree.size(), nv = 2 * static_cast<std::size_t>(order_);
  for (std::size_t t = 0; t < nt; ++t) {
    if (bw.range_degree[t] == 0) continue;
    const double factor = std::pow(bw.range_scale[w], -bw.range_degree[t]);
    bw.values[w * nt + t] *= factor;
    if (level >= 1) {
      double* g = bw.gradients.data() + (w * nt + t) * nv;
      for (std::size_t v = 0; v < nv; ++v) g[v] *= factor;
    }
    if (level >= 2) {
      double* h = bw.hessians.data() + (w * nt + t) * nv * nv;
      for (std::size_t v = 0; v < nv * nv; ++v) h[v] *= factor;
    }
  }
}

void InnerProblem::EvaluateWindows(const Eigen::VectorXd& x, int level) {
  for (BlockWindows& bw : windows_) {
    if (bw.first_point.empty()) continue;
    for (std::size_t w = 0; w < bw.first_point.size(); ++w) FillWindow(bw, w, x);
    bw.evaluator->EvaluateBatch(bw.first_point.size(), bw.x, bw.phi, bw.values.data(),
                                level >= 1 ? bw.gradients.data() : nullptr,
                                level >= 2 ? bw.hessians.data() : nullptr);
    if (bw.range_degree.empty()) continue;
    for (std::size_t w = 0; w < bw.first_point.size(); ++w) RescaleWindow(bw, w, level);
  }
}

ObjectiveValue InnerProblem::Evaluate(const Eigen::VectorXd& x, double lambda,
                                      double barrier_weight, Eigen::VectorXd* gradient,
                                      SymmetricBandedMatrix* hessian) {
  ObjectiveValue value;
  const std::size_t m = points_.size();
  // Measurements and the weak prior on the initial normals.
  const Eigen::VectorXd residual = x - data_target_;
  const Eigen::VectorXd weighted = data_information_.Multiply(residual);
  value.data = 0.5 * residual.dot(weighted);
  if (gradient) *gradient = weighted;
  if (hessian) *hessian = closed_ ? hessian_data_information_ : data_information_;

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
      if (hessian) {
        const std::size_t h = HessianIndex(i);
        hessian->Add(h, h, barrier_weight * (1.0 / (a * a) + 1.0 / (b * b)));
      }
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
    for (std::size_t w = 0; w < bw.first_point.size(); ++w) {
      const double* values = bw.values.data() + w * nt;
      const double* grads = level >= 1 ? bw.gradients.data() + w * nt * nv : nullptr;
      const double* hess = level >= 2 ? bw.hessians.data() + w * nt * nv * nv : nullptr;
      if (gradient) window_gradient.setZero();
      if (hessian) window_hessian.setZero();
      // Penalties in Gauss-Newton form (positive semi-definite), energies exact ...
      const dsl::PenaltyValue pv = dsl::AccumulatePenalty(
          *bw.block, values, grads, hess, penalty_options,
          gradient ? window_gradient.data() : nullptr, hessian ? window_hessian.data() : nullptr);
      value.penalty += pv.constraint;
      value.energy += pv.energy;
      value.max_residual = std::max(value.max_residual, pv.max_residual);
      // ... whose Hessians are replaced by their positive semi-definite part.
      if (hessian && energies) {
        SumEnergyHessians(*bw.block, values, hess, energy_hessian);
        window_hessian -= energy_hessian;
        MakePositiveSemidefinite(energy_hessian);
        window_hessian += energy_hessian;
      }
      if (!gradient && !hessian) continue;
      const std::size_t p = bw.first_point[w];
      for (std::size_t a = 0; a < nv; ++a) {
        const std::size_t ga = WindowUnknown(p, a);
        if (gradient) {
          (*gradient)[static_cast<Eigen::Index>(ga)] +=
              window_gradient[static_cast<Eigen::Index>(a)];
        }
        if (!hessian) continue;
        for (std::size_t b = 0; b <= a; ++b) {
          const double h =
              window_hessian(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b));
          if (h != 0.0) hessian->Add(HessianIndex(ga), HessianIndex(WindowUnknown(p, b)), h);
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

bool InnerProblem::HasEnergyTerms() const {
  return std::any_of(windows_.begin(), windows_.end(), [](const BlockWindows& bw) {
    return !bw.first_point.empty() && HasEnergies(*bw.block);
  });
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
        penalties[l < links_.size() ? l : l - links_.size()] += c;
      // An order-1 prior has no links inside a window: blame the links around the point.
      if (order_ == 1) {
        if (first > 0) penalties[first - 1] += c;
        if (closed_ && first == 0) penalties.back() += c;
        if (first < links_.size()) penalties[first] += c;
      }
    }
  }
  return penalties;
}

std::vector<ConstraintRow> InnerProblem::EqualityRows(const Eigen::VectorXd& x) {
  EvaluateWindows(x, 1);
  const std::size_t nv = 2 * static_cast<std::size_t>(order_);
  std::vector<ConstraintRow> rows;
  std::vector<int> active_branch;
  for (BlockWindows& bw : windows_) {
    if (bw.first_point.empty()) continue;
    const std::size_t nt = static_cast<std::size_t>(bw.block->num_terms());
    const std::vector<dsl::Term>& terms = bw.block->terms();
    for (std::size_t w = 0; w < bw.first_point.size(); ++w) {
      const double* values = bw.values.data() + w * nt;
      const double* grads = bw.gradients.data() + w * nt * nv;
      if (bw.block->num_disjunctions() > 0) {
        (void)dsl::AccumulatePenalty(*bw.block, values, nullptr, nullptr, {}, nullptr, nullptr,
                                     &active_branch);
      }
      for (std::size_t t = 0; t < nt; ++t) {
        const dsl::Term& term = terms[t];
        if (term.kind != dsl::TermKind::kEquality) continue;
        if (term.disjunction >= 0 &&
            active_branch[static_cast<std::size_t>(term.disjunction)] != term.branch) {
          continue;
        }
        ConstraintRow row;
        const std::size_t first = bw.first_point[w];
        if (closed_ && first + static_cast<std::size_t>(order_) > points_.size()) {
          // Across the seam: a row over all unknowns, zero but at both ends.
          row.first = 0;
          row.coefficients.assign(num_unknowns(), 0.0);
          for (std::size_t v = 0; v < nv; ++v)
            row.coefficients[WindowUnknown(first, v)] = grads[t * nv + v];
        } else {
          row.first = 2 * first;
          row.coefficients.assign(nv, 0.0);
          for (std::size_t v = 0; v < nv; ++v)
            row.coefficients[global_index_[v]] = grads[t * nv + v];
        }
        rows.push_back(std::move(row));
      }
    }
  }
  return rows;
}

std::optional<SymmetricBandedMatrix> InModelRangePrecision(const Scan& scan,
                                                           std::span<const std::size_t> beams) {
  if (!scan.precision) return std::nullopt;
  // Its bandwidth in in-model indices is at most the scan's.
  const std::size_t b = scan.precision->bandwidth(), m = beams.size();
  SymmetricBandedMatrix sub(m, b);
  for (std::size_t j = 0; j < m; ++j) {
    for (std::size_t q = j; q < std::min(m, j + b + 1); ++q) {
      sub.Set(q, j, (*scan.precision)(beams[q], beams[j]));
    }
  }
  return sub;
}

}  // namespace priormap::priorlets
