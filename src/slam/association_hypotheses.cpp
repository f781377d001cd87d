#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

#include <priormap/core/check.hpp>
#include <priormap/slam/association_hypotheses.hpp>

namespace priormap::slam {
namespace {

constexpr double kLog2Pi = 1.8378770664093454836;
constexpr double kMinusInf = -std::numeric_limits<double>::infinity();

double LogSumExp(double a, double b) {
  const double m = std::max(a, b);
  if (m == kMinusInf) return m;
  return m + std::log(std::exp(a - m) + std::exp(b - m));
}

// The pairs grouped by line, and each line's log prior factor for every count of active and
// inactive pairs: factor[line][active * (n + 1) + inactive].
struct LinePriors {
  std::vector<int> line_of_pair;
  std::vector<double> p_real;  // per line: p(d_line = 1)
  std::vector<std::vector<double>> factor;
  int stride = 0;
};

LinePriors MakeLinePriors(const HypothesisProblem& problem, const StructurePriors& priors) {
  LinePriors lines;
  std::vector<int> ids;
  for (const auto& pair : problem.pairs) {
    auto it = std::find(ids.begin(), ids.end(), pair.line);
    if (it == ids.end()) it = ids.insert(ids.end(), pair.line);
    lines.line_of_pair.push_back(static_cast<int>(it - ids.begin()));
  }
  const int n = static_cast<int>(problem.pairs.size());
  lines.stride = n + 1;
  const double log_on = std::log(priors.p_point_on_line);
  const double log_off = std::log1p(-priors.p_point_on_line);
  for (int id : ids) {
    const bool known = std::find(problem.lines_known_real.begin(), problem.lines_known_real.end(),
                                 id) != problem.lines_known_real.end();
    const double p_real = known ? 1.0 : priors.p_line_real;
    lines.p_real.push_back(p_real);
    std::vector<double> factor((n + 1) * (n + 1), kMinusInf);
    for (int active = 0; active <= n; ++active) {
      for (int inactive = 0; active + inactive <= n; ++inactive) {
        const double real = std::log(p_real) + active * log_on + inactive * log_off;
        // No point from this line: it is spurious, or real with none of these points on it.
        factor[active * lines.stride + inactive] =
            active > 0 ? real : LogSumExp(std::log1p(-p_real), real);
      }
    }
    lines.factor.push_back(std::move(factor));
  }
  return lines;
}

class Enumerator {
 public:
  Enumerator(const HypothesisProblem& problem, const StructurePriors& priors)
      : problem_(problem),
        lines_(MakeLinePriors(problem, priors)),
        n_(static_cast<int>(problem.pairs.size())),
        L_(Eigen::MatrixXd::Zero(n_, n_)),
        whitened_(n_, 0.0),
        order_(n_, 0),
        row_(n_ * n_, 0.0),
        active_count_(lines_.factor.size(), 0),
        inactive_count_(lines_.factor.size(), 0),
        leaf_log_(std::size_t{1} << n_, kMinusInf),
        one_line_per_point_(priors.one_line_per_point),
        priors_(priors) {
    std::vector<int> points;
    for (const auto& pair : problem.pairs) {
      auto it = std::find(points.begin(), points.end(), pair.point);
      if (it == points.end()) it = points.insert(points.end(), pair.point);
      point_of_pair_.push_back(static_cast<int>(it - points.begin()));
    }
    point_active_.assign(points.size(), false);
    for (int j = 0; j < n_; ++j) {
      const double density =
          problem.null_density.empty() ? priors.unrelated_density : problem.null_density[j];
      log_null_.push_back(std::log(density));
    }
  }

  HypothesisPosterior Run() {
    Recurse(0, 0, 0u, 0.0, 0.0, 0.0);
    const double best = *std::max_element(leaf_log_.begin(), leaf_log_.end());
    double total = 0.0;
    std::vector<double> marginal(n_, 0.0);
    std::size_t best_mask = 0;
    for (std::size_t mask = 0; mask < leaf_log_.size(); ++mask) {
      if (leaf_log_[mask] == kMinusInf) continue;
      const double w = std::exp(leaf_log_[mask] - best);
      total += w;
      for (int j = 0; j < n_; ++j) {
        if (mask >> j & 1u) marginal[j] += w;
      }
      if (leaf_log_[mask] == best) best_mask = mask;
    }
    HypothesisPosterior out;
    out.num_hypotheses = count_;
    out.map_probability = 1.0 / total;
    out.map.resize(n_);
    out.marginals.resize(n_);
    for (int j = 0; j < n_; ++j) {
      out.map[j] = (best_mask >> j & 1u) != 0;
      out.marginals[j] = marginal[j] / total;
    }
    out.structure_marginals = StructureMarginals(best, total);
    return out;
  }

 private:
  // Pairs before `j` are decided: `rank` of them active (in order_), `mask` their bits, `quad`
  // and `log_det` the Gaussian terms of S over them, `log_null` the inactive ones' densities.
  void Recurse(int j, int rank, std::size_t mask, double quad, double log_det, double log_null) {
    if (j == n_) {
      Leaf(rank, mask, quad, log_det, log_null);
      return;
    }
    const int line = lines_.line_of_pair[j];
    ++inactive_count_[line];
    Recurse(j + 1, rank, mask, quad, log_det, log_null + log_null_[j]);
    --inactive_count_[line];

    const int point = point_of_pair_[j];
    if (one_line_per_point_ && point_active_[point]) return;
    // Active: grow the Cholesky factor of S over the active pairs by pair j.
    double* row = &row_[static_cast<std::size_t>(rank) * n_];
    double norm = 0.0;
    double e = problem_.theta[j];
    for (int k = 0; k < rank; ++k) {
      double s = problem_.S(order_[k], j);
      for (int m = 0; m < k; ++m) s -= L_(k, m) * row[m];
      row[k] = s / L_(k, k);
      norm += row[k] * row[k];
      e -= row[k] * whitened_[k];
    }
    const double d = problem_.S(j, j) - norm;
    if (!(d > 1e-300)) return;  // numerically dependent on the active ones: no density
    const double diag = std::sqrt(d);
    for (int k = 0; k < rank; ++k) L_(rank, k) = row[k];
    L_(rank, rank) = diag;
    e /= diag;
    whitened_[rank] = e;
    order_[rank] = j;
    ++active_count_[line];
    point_active_[point] = true;
    Recurse(j + 1, rank + 1, mask | std::size_t{1} << j, quad + e * e,
            log_det + 2.0 * std::log(diag), log_null);
    point_active_[point] = false;
    --active_count_[line];
  }

  // Per (point, structure) with two or more pairs: the mass of the leaves with any of them active
  // (exact whether or not one_line_per_point makes them exclusive).
  std::vector<StructureMarginal> StructureMarginals(double best, double total) const {
    std::vector<StructureMarginal> out;
    for (int j = 0; j < n_; ++j) {
      const auto& pair = problem_.pairs[j];
      for (int structure : pair.structures) {
        auto it = std::find_if(out.begin(), out.end(), [&](const StructureMarginal& m) {
          return m.point == pair.point && m.structure == structure;
        });
        if (it == out.end()) it = out.insert(out.end(), {pair.point, structure, {}, 0.0, {}});
        it->pairs.push_back(j);
      }
    }
    std::erase_if(out, [](const StructureMarginal& m) { return m.pairs.size() < 2; });
    for (StructureMarginal& m : out) {
      std::size_t any = 0;
      for (int j : m.pairs) any |= std::size_t{1} << j;
      double mass = 0.0;
      for (std::size_t mask = 0; mask < leaf_log_.size(); ++mask) {
        if ((mask & any) != 0 && leaf_log_[mask] != kMinusInf) {
          mass += std::exp(leaf_log_[mask] - best);
        }
      }
      m.probability = mass / total;
      // "On s and on none of the others" over "on none": p_real(s) p_on / (q_s null_s), with
      // q = 1 - p_real p_on the line's factor without the point.
      double sum = 0.0;
      for (int j : m.pairs) {
        const double p_real = lines_.p_real[lines_.line_of_pair[j]];
        const double w =
            p_real / ((1.0 - p_real * priors_.p_point_on_line) * std::exp(log_null_[j]));
        m.weights.push_back(w);
        sum += w;
      }
      for (double& w : m.weights) w /= sum;
    }
    std::sort(out.begin(), out.end(), [](const StructureMarginal& a, const StructureMarginal& b) {
      return std::tie(a.point, a.structure) < std::tie(b.point, b.structure);
    });
    return out;
  }

  void Leaf(int rank, std::size_t mask, double quad, double log_det, double log_null) {
    ++count_;
    double log_p = -0.5 * (quad + log_det + rank * kLog2Pi) + log_null;
    for (std::size_t n = 0; n < lines_.factor.size(); ++n) {
      log_p += lines_.factor[n][active_count_[n] * lines_.stride + inactive_count_[n]];
    }
    leaf_log_[mask] = log_p;
  }

  const HypothesisProblem& problem_;
  LinePriors lines_;
  int n_;
  Eigen::MatrixXd L_;
  std::vector<double> whitened_;
  std::vector<int> order_;
  std::vector<double> row_;  // scratch row per depth
  std::vector<int> active_count_, inactive_count_;
  std::vector<double> log_null_;
  std::vector<double> leaf_log_;
  bool one_line_per_point_;
  StructurePriors priors_;
  std::vector<int> point_of_pair_;
  std::vector<bool> point_active_;
  std::size_t count_ = 0;
};

}  // namespace

bool ArePriorsValid(const StructurePriors& priors) {
  return 0.0 < priors.p_point_on_line && priors.p_point_on_line < 1.0 &&
         0.0 <= priors.p_line_real && priors.p_line_real <= 1.0 && 0.0 <= priors.p_accept &&
         priors.p_accept <= 1.0;
}

HypothesisPosterior EnumerateHypotheses(const HypothesisProblem& problem,
                                        const StructurePriors& priors) {
  const auto n = static_cast<Eigen::Index>(problem.pairs.size());
  PRIORMAP_CHECK(n <= kMaxEnumeratedPairs, "too many pairs to enumerate; cap the cluster first");
  PRIORMAP_CHECK(problem.theta.size() == n && problem.S.rows() == n && problem.S.cols() == n,
                 "theta and S must have one entry per pair");
  PRIORMAP_CHECK(
      problem.null_density.empty() || problem.null_density.size() == static_cast<std::size_t>(n),
      "null_density must be empty or have one entry per pair");
  PRIORMAP_CHECK(ArePriorsValid(priors), "StructurePriors out of range (ArePriorsValid)");
  return Enumerator(problem, priors).Run();
}

double LogHypothesisPrior(const HypothesisProblem& problem, const std::vector<bool>& active,
                          const StructurePriors& priors) {
  const LinePriors lines = MakeLinePriors(problem, priors);
  std::vector<int> on(lines.factor.size(), 0), off(lines.factor.size(), 0);
  for (std::size_t j = 0; j < problem.pairs.size(); ++j) {
    (active[j] ? on : off)[lines.line_of_pair[j]]++;
  }
  double log_p = 0.0;
  for (std::size_t n = 0; n < lines.factor.size(); ++n) {
    log_p += lines.factor[n][on[n] * lines.stride + off[n]];
  }
  return log_p;
}

}  // namespace priormap::slam
