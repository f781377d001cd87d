#pragma once
// Problem 4 of the paper for a fixed INMODEL and topology: the objective, its gradient and a
// positive definite banded Hessian, the constraint violations, and the link penalties.
//
// Unknowns are interleaved per in-model point, x[2p] = rho_p and x[2p + 1] = alpha_p, so that a
// window of k consecutive points touches 2k consecutive unknowns and every Hessian is banded.
//
// A closed problem (a ring: the points of a scan that covers a full turn, engine.hpp) also has
// the link from its last point to its first, links[m - 1], and the k - 1 windows across it. Such
// a window sees its points past the seam a turn later (phi and alpha + 2 pi), so that angles stay
// unwrapped along it as along every other window. Its unknowns sit at both ends of x, so the
// Hessian of a closed problem is banded in another order of the unknowns: the points folded as
// 0, m - 1, 1, m - 2, 2, ... (ring neighbours d apart are at most 2 d apart there), about twice
// the bandwidth. Evaluate's Hessian is in that order (HessianIndex); x and the gradient are not.
#include <array>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include <Eigen/Core>

#include <priormap/core/banded_matrix.hpp>
#include <priormap/core/scan.hpp>
#include <priormap/dsl/prior.hpp>
#include <priormap/priorlets/constraint_kernel.hpp>
#include <priormap/priorlets/engine.hpp>

namespace priormap::priorlets {

// What one in-model point brings to the problem.
struct ProblemPoint {
  double phi = 0.0;
  double rho_measured = 0.0;
  double rho_lower = 0.0, rho_upper = 0.0;
  double alpha_initial = 0.0;
  double alpha_sigma = 1.0;  // of the initial normal's weak prior
  double alpha_lower = 0.0, alpha_upper = 0.0;
};

// Beyond this distance a constraint homogeneous in the ranges (a length, such as the distance
// of a point from its neighbour's line, or an inverse length, such as a curvature) is measured
// relative to its window's ranges: its residual is divided by (r / kUnitRange)^degree, r the
// largest measured range of the window. A far wall then weighs in the penalty and the
// feasibility test as the same wall kUnitRange away would, against its normals' constraints
// (in radians, whatever the scale) and the data; in metres its residuals grow with the scene's
// scale (1e-6 m on a wall 1e7 m away is 1e-13 of its ranges: the Newton steps along the
// constraints cannot get there). Nearer scenes, and the other constraints, keep their units.
inline constexpr double kUnitRange = 100.0;

struct Violation {
  double max_residual = 0.0;  // largest |f|, max(0, g), or disjunction branch residual
                              // (homogeneous ones relative to far windows' ranges, kUnitRange)
  double penalty = 0.0;       // sum of the squared forms (unweighted)
};

// Objective pieces at one x; the weights of the homotopy stage are passed in.
struct ObjectiveValue {
  double data = 0.0;          // measurement term and the weak prior on the initial normals
  double energy = 0.0;        // prior energies h
  double penalty = 0.0;       // unweighted constraint penalty
  double barrier = 0.0;       // -sum log of the bound slacks (unweighted); +inf outside the bounds
  double max_residual = 0.0;  // of the constraints (see Violation)
  // A weight of 0 means no barrier, also where the barrier is infinite (0 * inf is NaN, which
  // no line search accepts).
  [[nodiscard]] double Total(double lambda, double barrier_weight) const {
    return data + energy + lambda * penalty +
           (barrier_weight == 0.0 ? 0.0 : barrier_weight * barrier);
  }
};

// The information matrix of the ranges of `beams` (increasing) when the scan's readings are
// correlated, else nullopt: the rows and columns of the scan's precision, i.e. the conditional
// model given the other readings (an outlier's noise says nothing about its neighbours').
[[nodiscard]] std::optional<SymmetricBandedMatrix> InModelRangePrecision(
    const Scan& scan, std::span<const std::size_t> beams);

class InnerProblem {
 public:
  // `range_precision`: the information matrix of the in-model ranges (banded), or null for
  // independent noise with the sigmas in `range_sigma`. `closed`: a ring, with one link per
  // point (links[m - 1] joins the last point to the first); it needs more points than the
  // prior's order. Points are in scan order with phi increasing (a ring's last point is a turn
  // short of its first).
  InnerProblem(const dsl::CompiledPrior& prior, std::vector<ProblemPoint> points,
               std::vector<Link> links, std::vector<double> range_sigma,
               std::optional<SymmetricBandedMatrix> range_precision, bool closed = false);

  [[nodiscard]] std::size_t num_points() const { return points_.size(); }
  [[nodiscard]] std::size_t num_unknowns() const { return 2 * points_.size(); }
  [[nodiscard]] const std::vector<ProblemPoint>& points() const { return points_; }
  [[nodiscard]] const std::vector<Link>& links() const { return links_; }
  [[nodiscard]] bool closed() const { return closed_; }

  // Where unknown u sits in the Hessians of Evaluate: u itself, but for a closed problem.
  [[nodiscard]] std::size_t HessianIndex(std::size_t u) const {
    return hessian_index_.empty() ? u : hessian_index_[u];
  }
  // A vector over the unknowns in the Hessians' order, and back.
  [[nodiscard]] Eigen::VectorXd ToHessianOrder(const Eigen::VectorXd& v) const;
  [[nodiscard]] Eigen::VectorXd FromHessianOrder(const Eigen::VectorXd& v) const;

  // The measurements with the initial normals, pulled strictly inside the bounds.
  [[nodiscard]] Eigen::VectorXd InitialPoint() const;
  // True when x is strictly inside every bound.
  [[nodiscard]] bool StrictlyInside(const Eigen::VectorXd& x) const;
  // The largest t in (0, 1] with x + t d inside the bounds, times `fraction` when limited by them.
  [[nodiscard]] double MaxStep(const Eigen::VectorXd& x, const Eigen::VectorXd& d,
                               double fraction) const;

  // Objective pieces; with `gradient`/`hessian`, also the derivatives of
  // Total(lambda, barrier_weight): penalties in Gauss-Newton form, energies with each window's
  // Hessian block made positive semi-definite, so the Hessian is positive definite. The Hessian
  // is in HessianIndex order.
  ObjectiveValue Evaluate(const Eigen::VectorXd& x, double lambda, double barrier_weight,
                          Eigen::VectorXd* gradient, SymmetricBandedMatrix* hessian);

  [[nodiscard]] Violation Violations(const Eigen::VectorXd& x);
  // Per link, the constraint penalty of the windows that contain it.
  [[nodiscard]] std::vector<double> LinkPenalties(const Eigen::VectorXd& x);
  // The rows of grad_x f_T at x (Sec. IV-B): every equality of every window, and within a
  // disjunction those of its smallest branch (inequalities leave directions free).
  [[nodiscard]] std::vector<ConstraintRow> EqualityRows(const Eigen::VectorXd& x);
  // The information of the data term (measurements and the initial normals' weak prior), in
  // the order of x (it couples no ring neighbours across the seam).
  [[nodiscard]] const SymmetricBandedMatrix& data_information() const { return data_information_; }
  // Its largest diagonal entry: the scale at which penalties start to outweigh the data.
  [[nodiscard]] double data_weight() const;
  // True when a window's block has energy terms (h_T), whose size no bound limits.
  [[nodiscard]] bool HasEnergyTerms() const;

 private:
  struct BlockWindows {
    const dsl::CompiledBlock* block = nullptr;
    std::unique_ptr<dsl::BlockEvaluator> evaluator;
    std::vector<std::size_t> first_point;  // window w covers points first_point[w] .. + order - 1
    std::vector<double> phi;               // windows x order
    std::vector<double> x;                 // windows x 2 order, in the block's unknown order
    std::vector<double> values, gradients, hessians;
    // Per term, its degree of homogeneity in the ranges when the block has a window beyond
    // kUnitRange (0: not homogeneous, or not rescaled); per window, max(1, r / kUnitRange)
    // (see kUnitRange). Both empty when no window is that far, so that nearer scenes are solved
    // to the bit as they were.
    std::vector<int> range_degree;
    std::vector<double> range_scale;
  };
  // Fills window w's unknowns (bw.x) from the global ones.
  void FillWindow(BlockWindows& bw, std::size_t w, const Eigen::VectorXd& x) const;
  // Sets bw.range_degree and bw.range_scale (see BlockWindows).
  void FindRangeScales(BlockWindows& bw);
  // Divides window w's constraint terms by range_scale[w]^degree, with the derivatives asked.
  void RescaleWindow(BlockWindows& bw, std::size_t w, int level) const;
  // Fills every block's x from the global unknowns and evaluates up to `level` (0 values,
  // 1 gradients, 2 Hessians).
  void EvaluateWindows(const Eigen::VectorXd& x, int level);
  // Global unknown of block unknown v of the window starting at point p.
  [[nodiscard]] std::size_t WindowUnknown(std::size_t p, std::size_t v) const {
    const std::size_t u = 2 * p + global_index_[v];
    return u < 2 * points_.size() ? u : u - 2 * points_.size();
  }
  int order_;
  std::vector<ProblemPoint> points_;
  std::vector<Link> links_;
  bool closed_ = false;
  std::vector<std::size_t> hessian_index_;  // empty for an open problem
  SymmetricBandedMatrix data_information_;
  SymmetricBandedMatrix hessian_data_information_;  // in Hessian order (closed problems)
  Eigen::VectorXd data_target_;  // measured ranges and initial normals, interleaved
  std::array<BlockWindows, 3> windows_;
  std::size_t bandwidth_ = 1;
  // Block unknown v (rho_1..rho_k, alpha_1..alpha_k) of the window starting at point p is
  // global unknown 2 p + global_index_[v].
  std::vector<std::size_t> global_index_;
};

}  // namespace priormap::priorlets
