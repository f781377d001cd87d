#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <iterator>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>
#include <fmt/format.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <priormap/core/check.hpp>
#include <priormap/priorlets/constraint_kernel.hpp>

namespace priormap::priorlets {
namespace {

using Eigen::Index;

/// Nodes with at most this many variables are solved densely. Smaller leaves mean more merges;
/// 16 and 24 were the fastest of 8..64 for m = 1100, k = 2, 3 (a 16-column pivoted QR takes ~15 us,
/// a Jacobi SVD of the same size ~200 us, which is why the SVD is the fallback, not the rule).
constexpr std::size_t kLeafVariables = 16;

/// A pivoted-QR diagonal entry within this factor of the tolerance does not decide the rank
/// alone: pivoted QR can misjudge a singular value by a modest factor (Kahan-like matrices),
/// so the SVD of the triangular factor decides whenever the QR shows no clear gap.
constexpr double kAmbiguityFactor = 1e3;

/// A node's kernel column becomes final when its values where outside rows reach are below
/// this times the tolerance. Those values leak into the residual of the outside rows, so they
/// must stay well below it (at tol they cost 1e-7 in subspace accuracy on ill-conditioned
/// chains); a column kept active needlessly only costs work, and never more than one per
/// reachable variable.
constexpr double kEdgeFactor = 1e-3;

Index ToIndex(std::size_t i) {
  return static_cast<Index>(i);
}

struct RankStats {
  double largest_null = 0.0;
  double smallest_kept = std::numeric_limits<double>::infinity();
  std::size_t subproblems = 0;
  std::size_t svd_fallbacks = 0;

  void Add(const RankStats& other) {
    largest_null = std::max(largest_null, other.largest_null);
    smallest_kept = std::min(smallest_kept, other.smallest_kept);
    subproblems += other.subproblems;
    svd_fallbacks += other.svd_fallbacks;
  }
};

/// The null decision of one component: tol = relative_tolerance * scale.
struct RankRule {
  double tol = 0.0;
  double scale = 1.0;  // s_c, to report singular values on the scale of relative_tolerance
};

/// An orthonormal basis (q x d) of the numerical null space of m (p x q). With m^T Pi = Q R
/// (pivoted Householder QR), m Q = Pi R^T: the last q - min(p, q) columns of Q are exactly null,
/// and |R_ii| orders the others like the singular values.
Eigen::MatrixXd NullSpace(const Eigen::MatrixXd& m, const RankRule& rule, RankStats* stats) {
  const Index p = m.rows();
  const Index q = m.cols();
  if (p == 0 || q == 0) return Eigen::MatrixXd::Identity(q, q);
  ++stats->subproblems;
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(m.transpose());
  const Eigen::MatrixXd& r = qr.matrixQR();
  const Index t = std::min(p, q);
  Index rank = 0;
  bool ambiguous = false;
  for (Index i = 0; i < t; ++i) {
    const double d = std::abs(r(i, i));
    if (d > rule.tol && rank == i) ++rank;
    if (d > rule.tol / kAmbiguityFactor && d < rule.tol * kAmbiguityFactor) ambiguous = true;
  }
  Eigen::VectorXd singular_values;
  Eigen::MatrixXd coefficients;  // null directions in the basis Q
  if (!ambiguous) {
    singular_values = r.diagonal().head(t).cwiseAbs();
    coefficients = Eigen::MatrixXd::Identity(q, q).rightCols(q - rank);
  } else {
    // R_top^T (p x t) has the singular values of m; its right singular vectors map through Q.
    ++stats->svd_fallbacks;
    const Eigen::MatrixXd rt =
        r.topRows(t).triangularView<Eigen::Upper>().toDenseMatrix().transpose();
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(rt, Eigen::ComputeFullV);
    singular_values = svd.singularValues();
    rank = (singular_values.array() > rule.tol).count();
    coefficients = Eigen::MatrixXd::Zero(q, q - rank);
    coefficients.topLeftCorner(t, t - rank) = svd.matrixV().rightCols(t - rank);
    coefficients.bottomRightCorner(q - t, q - t).setIdentity();
  }
  for (Index i = 0; i < t; ++i) {
    const double s = singular_values(i) / rule.scale;
    if (i < rank) {
      stats->smallest_kept = std::min(stats->smallest_kept, s);
    } else {
      stats->largest_null = std::max(stats->largest_null, s);
    }
  }
  return qr.householderQ() * coefficients;
}

/// The rows of one component, scaled to unit 2-norm, on local variable indices (positions in
/// the component's sorted variable list), ascending within a row.
struct ComponentRows {
  std::vector<std::size_t> offsets{0};  // row i: entries offsets[i] .. offsets[i + 1] - 1
  std::vector<std::size_t> index;
  std::vector<double> value;

  [[nodiscard]] std::size_t size() const { return offsets.size() - 1; }
  [[nodiscard]] std::size_t first(std::size_t i) const { return index[offsets[i]]; }
  [[nodiscard]] std::size_t last(std::size_t i) const { return index[offsets[i + 1] - 1]; }
};

struct Component {
  std::vector<std::size_t> variables;  // global indices, sorted
  ComponentRows rows;
  double scale = 1.0;  // s_c = sqrt(|J_c|_1 |J_c|_inf) of the scaled rows
};

/// Final kernel columns over the local variables [lo, hi).
struct LocalBlock {
  std::size_t lo = 0;
  std::size_t hi = 0;
  Eigen::MatrixXd basis;
};

/// The kernel of the rows inside a node: final blocks (zero where outside rows reach) and the
/// active part, an orthonormal basis over the node's variables of the rest.
struct NodeResult {
  Eigen::MatrixXd active;
  std::vector<LocalBlock> final_blocks;
  RankStats stats;
};

/// Divide and conquer over one component's variables (see the header).
class ComponentSolver {
 public:
  ComponentSolver(const Component& component, double relative_tolerance, std::size_t parallel_grain)
      : component_(component),
        rule_{relative_tolerance * component.scale, component.scale},
        parallel_grain_(parallel_grain),
        reached_(component.variables.size(), 0) {}

  NodeResult Solve() {
    std::vector<std::size_t> rows(component_.rows.size());
    for (std::size_t i = 0; i < rows.size(); ++i) rows[i] = i;
    return SolveNode(0, component_.variables.size(), std::move(rows));
  }

 private:
  NodeResult SolveNode(std::size_t lo, std::size_t hi, std::vector<std::size_t> rows) {
    if (hi - lo <= kLeafVariables) return SolveLeaf(lo, hi, rows);
    const std::size_t mid = lo + (hi - lo) / 2;
    std::vector<std::size_t> left, right, cross;
    for (std::size_t i : rows) {
      if (component_.rows.last(i) < mid) {
        left.push_back(i);
      } else if (component_.rows.first(i) >= mid) {
        right.push_back(i);
      } else {
        cross.push_back(i);
      }
    }
    // Children write reached_ only inside their own halves, so they may run concurrently.
    Reach(cross, +1);
    NodeResult a, b;
    if (hi - lo >= parallel_grain_) {
      tbb::parallel_invoke([&] { a = SolveNode(lo, mid, std::move(left)); },
                           [&] { b = SolveNode(mid, hi, std::move(right)); });
    } else {
      a = SolveNode(lo, mid, std::move(left));
      b = SolveNode(mid, hi, std::move(right));
    }
    Reach(cross, -1);
    return Merge(lo, mid, hi, cross, std::move(a), std::move(b));
  }

  NodeResult SolveLeaf(std::size_t lo, std::size_t hi, const std::vector<std::size_t>& rows) {
    const ComponentRows& cr = component_.rows;
    Eigen::MatrixXd a = Eigen::MatrixXd::Zero(ToIndex(rows.size()), ToIndex(hi - lo));
    for (std::size_t i = 0; i < rows.size(); ++i) {
      for (std::size_t e = cr.offsets[rows[i]]; e < cr.offsets[rows[i] + 1]; ++e) {
        a(ToIndex(i), ToIndex(cr.index[e] - lo)) = cr.value[e];
      }
    }
    NodeResult result;
    Finish(lo, hi, NullSpace(a, rule_, &result.stats), &result);
    return result;
  }

  // ker [A; B; C] restricted to the active parts: blockdiag(N_a, N_b) ker(C blockdiag(N_a, N_b)).
  NodeResult Merge(std::size_t lo, std::size_t mid, std::size_t hi,
                   const std::vector<std::size_t>& cross, NodeResult a, NodeResult b) {
    NodeResult result;
    result.final_blocks = std::move(a.final_blocks);
    std::move(b.final_blocks.begin(), b.final_blocks.end(),
              std::back_inserter(result.final_blocks));
    result.stats = a.stats;
    result.stats.Add(b.stats);
    const Index na = a.active.cols();
    const Index nb = b.active.cols();
    const ComponentRows& cr = component_.rows;
    Eigen::MatrixXd c_times_n = Eigen::MatrixXd::Zero(ToIndex(cross.size()), na + nb);
    for (std::size_t i = 0; i < cross.size(); ++i) {
      for (std::size_t e = cr.offsets[cross[i]]; e < cr.offsets[cross[i] + 1]; ++e) {
        const std::size_t v = cr.index[e];
        if (v < mid) {
          c_times_n.row(ToIndex(i)).head(na) += cr.value[e] * a.active.row(ToIndex(v - lo));
        } else {
          c_times_n.row(ToIndex(i)).tail(nb) += cr.value[e] * b.active.row(ToIndex(v - mid));
        }
      }
    }
    const Eigen::MatrixXd z = NullSpace(c_times_n, rule_, &result.stats);
    Eigen::MatrixXd kernel(ToIndex(hi - lo), z.cols());
    kernel.topRows(ToIndex(mid - lo)).noalias() = a.active * z.topRows(na);
    kernel.bottomRows(ToIndex(hi - mid)).noalias() = b.active * z.bottomRows(nb);
    Finish(lo, hi, std::move(kernel), &result);
    return result;
  }

  // Rotates the node's kernel (orthonormal, (hi - lo) x d) into columns that outside rows can
  // see and columns that vanish where they reach (final). With E^T Pi = Q R for the reached rows
  // E of the kernel, E Q = Pi R^T: columns of Q past E's numerical rank vanish on E.
  void Finish(std::size_t lo, std::size_t hi, Eigen::MatrixXd kernel, NodeResult* result) const {
    const Index d = kernel.cols();
    std::vector<Index> edge;
    for (std::size_t v = lo; v < hi; ++v) {
      if (reached_[v] > 0) edge.push_back(ToIndex(v - lo));
    }
    Index rank = 0;
    if (d > 0 && !edge.empty()) {
      Eigen::MatrixXd edge_values(d, ToIndex(edge.size()));
      for (std::size_t i = 0; i < edge.size(); ++i) {
        edge_values.col(ToIndex(i)) = kernel.row(edge[i]).transpose();
      }
      const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(edge_values);
      const Index t = std::min(d, ToIndex(edge.size()));
      const double edge_tol = kEdgeFactor * rule_.tol;
      while (rank < t && std::abs(qr.matrixQR()(rank, rank)) > edge_tol) ++rank;
      if (rank > 0 && rank < d) {
        const Eigen::MatrixXd w = qr.householderQ();
        kernel = kernel * w;
      }
    }
    if (rank < d) {
      result->final_blocks.push_back({lo, hi, kernel.rightCols(d - rank)});
    }
    result->active = kernel.leftCols(rank);
  }

  void Reach(const std::vector<std::size_t>& rows, int delta) {
    const ComponentRows& cr = component_.rows;
    for (std::size_t i : rows) {
      for (std::size_t e = cr.offsets[i]; e < cr.offsets[i + 1]; ++e)
        reached_[cr.index[e]] += delta;
    }
  }

  const Component& component_;
  RankRule rule_;
  std::size_t parallel_grain_;
  // Per local variable: how many rows of enclosing nodes reach it (not a vector<bool>: the
  // halves of a node write it concurrently).
  std::vector<int> reached_;
};

class UnionFind {
 public:
  explicit UnionFind(std::size_t n) : parent_(n), size_(n, 1) {
    for (std::size_t i = 0; i < n; ++i) parent_[i] = i;
  }
  std::size_t Find(std::size_t i) {
    while (parent_[i] != i) {
      parent_[i] = parent_[parent_[i]];
      i = parent_[i];
    }
    return i;
  }
  void Unite(std::size_t a, std::size_t b) {
    a = Find(a);
    b = Find(b);
    if (a == b) return;
    if (size_[a] < size_[b]) std::swap(a, b);
    parent_[b] = a;
    size_[a] += size_[b];
  }

 private:
  std::vector<std::size_t> parent_;
  std::vector<std::size_t> size_;
};

/// Step 1: checks and scales the rows, groups the variables into components. `scales`: empty, or
/// per variable the divisor of its column (the rows in the variables z = S x).
std::vector<Component> BuildComponents(std::size_t n, std::span<const ConstraintRow> rows,
                                       double min_row_norm, std::span<const double> scales,
                                       std::vector<std::size_t>* free, std::size_t* num_rows_used) {
  // Coefficient j of a row in the variables z (as given when there are no scales).
  const auto coefficient = [&](const ConstraintRow& row, std::size_t j) {
    return scales.empty() ? row.coefficients[j] : row.coefficients[j] / scales[row.first + j];
  };
  std::vector<double> norms(rows.size(), 0.0);  // 0: row not used
  std::vector<std::uint8_t> used(n, 0);
  UnionFind sets(n);
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const ConstraintRow& row = rows[r];
    PRIORMAP_CHECK(row.coefficients.size() <= n && row.first <= n - row.coefficients.size(),
                   fmt::format("constraint row {} (first {}, {} coefficients) exceeds {} variables",
                               r, row.first, row.coefficients.size(), n));
    double largest = 0.0;
    for (std::size_t j = 0; j < row.coefficients.size(); ++j) {
      // The prior's own terms can leave their domain at the estimate (sqrt of a negative
      // number): the user's prior, not this code, is at fault, and is told so.
      if (!std::isfinite(row.coefficients[j]))
        throw std::domain_error(
            fmt::format("constraint {} of the prior is not finite at the estimate: a term or its "
                        "derivative is not finite there (the square root of a negative number, or "
                        "sqrt(abs(x)) at x = 0, say)",
                        r));
      largest = std::max(largest, std::abs(coefficient(row, j)));
    }
    if (largest == 0.0) continue;
    double sum = 0.0;  // scaled by the largest entry: no overflow or underflow
    for (std::size_t j = 0; j < row.coefficients.size(); ++j) {
      const double c = coefficient(row, j) / largest;
      sum += c * c;
    }
    // min_row_norm is in the caller's units: judged on the row as given.
    const double given_norm = scales.empty()
                                  ? largest * std::sqrt(sum)
                                  : Eigen::Map<const Eigen::VectorXd>(
                                        row.coefficients.data(), ToIndex(row.coefficients.size()))
                                        .stableNorm();
    if (given_norm <= min_row_norm) continue;
    norms[r] = largest * std::sqrt(sum);
    ++*num_rows_used;
    std::size_t previous = n;
    for (std::size_t j = 0; j < row.coefficients.size(); ++j) {
      if (coefficient(row, j) == 0.0) continue;
      used[row.first + j] = 1;
      if (previous != n) sets.Unite(previous, row.first + j);
      previous = row.first + j;
    }
  }

  std::vector<Component> components;
  std::vector<std::size_t> component_of_root(n, n);
  std::vector<std::size_t> local(n, 0);
  for (std::size_t v = 0; v < n; ++v) {
    if (!used[v]) {
      free->push_back(v);
      continue;
    }
    std::size_t& id = component_of_root[sets.Find(v)];
    if (id == n) {
      id = components.size();
      components.emplace_back();
    }
    local[v] = components[id].variables.size();
    components[id].variables.push_back(v);
  }

  std::vector<std::vector<double>> column_sums(components.size());
  for (std::size_t id = 0; id < components.size(); ++id) {
    column_sums[id].assign(components[id].variables.size(), 0.0);
  }
  std::vector<double> row_sum_max(components.size(), 0.0);
  for (std::size_t r = 0; r < rows.size(); ++r) {
    if (norms[r] == 0.0) continue;
    const ConstraintRow& row = rows[r];
    std::size_t id = n;
    double row_sum = 0.0;
    for (std::size_t j = 0; j < row.coefficients.size(); ++j) {
      if (coefficient(row, j) == 0.0) continue;
      const std::size_t v = row.first + j;
      if (id == n) id = component_of_root[sets.Find(v)];
      const double value = coefficient(row, j) / norms[r];
      components[id].rows.index.push_back(local[v]);
      components[id].rows.value.push_back(value);
      column_sums[id][local[v]] += std::abs(value);
      row_sum += std::abs(value);
    }
    components[id].rows.offsets.push_back(components[id].rows.index.size());
    row_sum_max[id] = std::max(row_sum_max[id], row_sum);
  }
  for (std::size_t id = 0; id < components.size(); ++id) {
    const double col_sum_max = *std::max_element(column_sums[id].begin(), column_sums[id].end());
    components[id].scale = std::max(1.0, std::sqrt(col_sum_max * row_sum_max[id]));
  }
  return components;
}

/// Copies rows `variables` of x (n x c) into a |variables| x c matrix; runs of consecutive
/// indices are the common case and a single block copy.
Eigen::MatrixXd GatherRows(const Eigen::Ref<const Eigen::MatrixXd>& x,
                           const std::vector<std::size_t>& variables) {
  const Index s = ToIndex(variables.size());
  if (s > 0 && variables.back() - variables.front() + 1 == variables.size()) {
    return x.middleRows(ToIndex(variables.front()), s);
  }
  Eigen::MatrixXd out(s, x.cols());
  for (Index i = 0; i < s; ++i) out.row(i) = x.row(ToIndex(variables[i]));
  return out;
}

void ScatterAddRows(const Eigen::MatrixXd& y, const std::vector<std::size_t>& variables,
                    Eigen::MatrixXd* x) {
  const Index s = ToIndex(variables.size());
  if (s > 0 && variables.back() - variables.front() + 1 == variables.size()) {
    x->middleRows(ToIndex(variables.front()), s) += y;
    return;
  }
  for (Index i = 0; i < s; ++i) x->row(ToIndex(variables[i])) += y.row(i);
}

/// Blocks of one component's kernel in z = S x (orthonormal there) as an orthonormal basis of
/// the same kernel in x = S^-1 z. Blocks come in post-order of the divide and conquer (a node's
/// after its subtree's): a node's range holds its descendants' ranges, is disjoint from those of
/// the other earlier blocks, and its descendants' blocks are the run of blocks just before it
/// inside its range. So orthonormalising each block against that run (twice: classical
/// Gram-Schmidt with reorthogonalisation), then within itself, gives orthonormal columns that
/// keep every block's support and span S^-1 of the same space.
void MapBackToGivenUnits(const std::vector<std::size_t>& variables, std::span<const double> scales,
                         std::vector<LocalBlock>* blocks) {
  for (std::size_t b = 0; b < blocks->size(); ++b) {
    LocalBlock& block = (*blocks)[b];
    Eigen::MatrixXd& v = block.basis;
    for (std::size_t i = block.lo; i < block.hi; ++i)
      v.row(ToIndex(i - block.lo)) /= scales[variables[i]];
    std::size_t first = b;  // the run of descendants: blocks first .. b - 1
    while (first > 0 && (*blocks)[first - 1].lo >= block.lo && (*blocks)[first - 1].hi <= block.hi)
      --first;
    for (int pass = 0; pass < 2; ++pass) {
      for (std::size_t e = first; e < b; ++e) {
        const LocalBlock& earlier = (*blocks)[e];
        auto rows = v.middleRows(ToIndex(earlier.lo - block.lo), ToIndex(earlier.hi - earlier.lo));
        const Eigen::MatrixXd c = earlier.basis.transpose() * rows;
        rows.noalias() -= earlier.basis * c;
      }
    }
    const Eigen::HouseholderQR<Eigen::MatrixXd> qr(v);
    v = qr.householderQ() * Eigen::MatrixXd::Identity(v.rows(), v.cols());
  }
}

}  // namespace

bool KernelOptions::IsValid(std::string* why) const {
  std::string reason;
  if (!(relative_tolerance > 0.0 && relative_tolerance < 1.0)) {
    reason = fmt::format("relative_tolerance must be in (0, 1) (got {})", relative_tolerance);
  } else if (!(min_row_norm >= 0.0) || !std::isfinite(min_row_norm)) {
    reason = fmt::format("min_row_norm must be finite and >= 0 (got {})", min_row_norm);
  } else if (parallel_grain < 2) {
    reason = fmt::format("parallel_grain must be at least 2 (got {})", parallel_grain);
  }
  if (why) *why = reason;
  return reason.empty();
}

ConstraintKernel::ConstraintKernel(std::size_t num_variables)
    : num_variables_(num_variables), dimension_(num_variables) {
  free_variables_.resize(num_variables);
  for (std::size_t v = 0; v < num_variables; ++v) free_variables_[v] = v;
  summary_.num_variables = num_variables;
  summary_.num_free_variables = num_variables;
  summary_.dimension = num_variables;
}

ConstraintKernel ComputeKernel(std::size_t num_variables, std::span<const ConstraintRow> rows,
                               const KernelOptions& options,
                               std::span<const double> variable_scales) {
  std::string why;
  PRIORMAP_CHECK(options.IsValid(&why), why);
  PRIORMAP_CHECK(
      variable_scales.empty() || variable_scales.size() == num_variables,
      fmt::format("{} variable scales for {} variables", variable_scales.size(), num_variables));
  for (std::size_t v = 0; v < variable_scales.size(); ++v) {
    PRIORMAP_CHECK(variable_scales[v] > 0.0 && std::isfinite(variable_scales[v]),
                   fmt::format("variable scale {} must be positive and finite (got {})", v,
                               variable_scales[v]));
  }
  ConstraintKernel kernel;
  kernel.num_variables_ = num_variables;
  KernelSummary& summary = kernel.summary_;
  summary.num_variables = num_variables;
  const std::vector<Component> components =
      BuildComponents(num_variables, rows, options.min_row_norm, variable_scales,
                      &kernel.free_variables_, &summary.num_rows);

  std::vector<NodeResult> results(components.size());
  tbb::parallel_for(std::size_t{0}, components.size(), [&](std::size_t id) {
    results[id] =
        ComponentSolver(components[id], options.relative_tolerance, options.parallel_grain).Solve();
    if (!variable_scales.empty()) {
      MapBackToGivenUnits(components[id].variables, variable_scales, &results[id].final_blocks);
    }
  });

  RankStats stats;
  std::size_t dimension = kernel.free_variables_.size();
  for (std::size_t id = 0; id < components.size(); ++id) {
    stats.Add(results[id].stats);
    for (LocalBlock& block : results[id].final_blocks) {
      const auto& variables = components[id].variables;
      KernelBlock& out = kernel.blocks_.emplace_back();
      out.variables.assign(variables.begin() + static_cast<std::ptrdiff_t>(block.lo),
                           variables.begin() + static_cast<std::ptrdiff_t>(block.hi));
      out.basis = std::move(block.basis);
      out.component = id;
      dimension += static_cast<std::size_t>(out.basis.cols());
    }
  }
  kernel.dimension_ = dimension;
  summary.num_components = components.size();
  summary.num_free_variables = kernel.free_variables_.size();
  summary.dimension = dimension;
  summary.largest_null_singular_value = stats.largest_null;
  summary.smallest_kept_singular_value = stats.smallest_kept;
  summary.num_subproblems = stats.subproblems;
  summary.num_svd_fallbacks = stats.svd_fallbacks;
  return kernel;
}

Eigen::MatrixXd ConstraintKernel::ToDense() const {
  return Expand(Eigen::MatrixXd::Identity(ToIndex(dimension_), ToIndex(dimension_)));
}

Eigen::MatrixXd ConstraintKernel::Coordinates(const Eigen::Ref<const Eigen::MatrixXd>& x) const {
  PRIORMAP_CHECK(x.rows() == ToIndex(num_variables_),
                 fmt::format("Coordinates: {} rows for {} variables", x.rows(), num_variables_));
  Eigen::MatrixXd out(ToIndex(dimension_), x.cols());
  Index column = 0;
  for (std::size_t v : free_variables_) out.row(column++) = x.row(ToIndex(v));
  for (const KernelBlock& block : blocks_) {
    out.middleRows(column, block.basis.cols()).noalias() =
        block.basis.transpose() * GatherRows(x, block.variables);
    column += block.basis.cols();
  }
  return out;
}

Eigen::MatrixXd ConstraintKernel::Expand(const Eigen::Ref<const Eigen::MatrixXd>& c) const {
  PRIORMAP_CHECK(c.rows() == ToIndex(dimension_),
                 fmt::format("Expand: {} rows for dimension {}", c.rows(), dimension_));
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(ToIndex(num_variables_), c.cols());
  Index column = 0;
  for (std::size_t v : free_variables_) out.row(ToIndex(v)) = c.row(column++);
  for (const KernelBlock& block : blocks_) {
    const Eigen::MatrixXd y = block.basis * c.middleRows(column, block.basis.cols());
    ScatterAddRows(y, block.variables, &out);
    column += block.basis.cols();
  }
  return out;
}

Eigen::MatrixXd ConstraintKernel::Project(const Eigen::Ref<const Eigen::MatrixXd>& x) const {
  return Expand(Coordinates(x));
}

Eigen::MatrixXd ConstraintKernel::ProjectOntoComplement(
    const Eigen::Ref<const Eigen::MatrixXd>& x) const {
  return x - Project(x);
}

IntrinsicSubspace::IntrinsicSubspace(ConstraintKernel free,
                                     const Eigen::Ref<const Eigen::MatrixXd>& extrinsic,
                                     const KernelOptions& options)
    : free_(std::move(free)) {
  std::string why;
  PRIORMAP_CHECK(options.IsValid(&why), why);
  PRIORMAP_CHECK(extrinsic.rows() == ToIndex(free_.num_variables()),
                 fmt::format("IntrinsicSubspace: extrinsic has {} rows for {} variables",
                             extrinsic.rows(), free_.num_variables()));
  PRIORMAP_CHECK(extrinsic.allFinite(), "IntrinsicSubspace: extrinsic is not finite");
  // E: orthonormal basis of Extr. Columns are normalised first (metres vs radians per unit).
  Eigen::MatrixXd columns = extrinsic;
  for (Index j = 0; j < columns.cols(); ++j) {
    const double norm = columns.col(j).stableNorm();
    if (norm > 0.0) columns.col(j) /= norm;
  }
  Index rank_e = 0;
  Eigen::MatrixXd e;
  if (columns.cols() > 0 && columns.rows() > 0) {
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(columns, Eigen::ComputeThinU);
    const Eigen::VectorXd& s = svd.singularValues();
    if (s.size() > 0 && s(0) > 0.0) {
      rank_e = (s.array() > options.relative_tolerance * s(0)).count();
    }
    e = svd.matrixU().leftCols(rank_e);
  }
  const Index dim = ToIndex(free_.dimension());
  if (rank_e == 0 || dim == 0) {
    removed_coordinates_.resize(dim, 0);
    removed_.resize(ToIndex(free_.num_variables()), 0);
    return;
  }
  // N^T E = U S V^T: S are the cosines of the angles between Extr and Free.
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(free_.Coordinates(e), Eigen::ComputeThinU);
  cosines_ = svd.singularValues();
  const Index r = (cosines_.array() > options.relative_tolerance).count();
  removed_coordinates_ = svd.matrixU().leftCols(r);
  removed_ = free_.Expand(removed_coordinates_);
}

std::size_t IntrinsicSubspace::dimension() const {
  return free_.dimension() - static_cast<std::size_t>(removed_.cols());
}

Eigen::MatrixXd IntrinsicSubspace::ToDense() const {
  const Index dim = ToIndex(free_.dimension());
  const Index r = removed_coordinates_.cols();
  if (r == 0) return free_.ToDense();
  // Columns r.. of the Householder Q of U_r span its orthogonal complement in R^dim.
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(removed_coordinates_);
  const Eigen::MatrixXd complement =
      qr.householderQ() * Eigen::MatrixXd::Identity(dim, dim).rightCols(dim - r);
  return free_.Expand(complement);
}

Eigen::MatrixXd IntrinsicSubspace::Project(const Eigen::Ref<const Eigen::MatrixXd>& x) const {
  Eigen::MatrixXd out = free_.Project(x);
  out.noalias() -= removed_ * (removed_.transpose() * x);
  return out;
}

}  // namespace priormap::priorlets
