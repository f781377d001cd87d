#pragma once
/// Free = ker grad_x f_T(x) (de la Puente & Censi, Sec. IV-B, eq. (6)): an orthonormal basis of
/// the null space of the constraint Jacobian J of the priorlet engine, and its split into the
/// extrinsic and intrinsic degrees of freedom (eqs. (8), (9)).
///
/// J is banded: a row comes from a window of k consecutive points and touches a short run of
/// variables. A dense SVD (n^3, seconds for n = 2200) ignores that; ComputeKernel works in
/// O(n log n) for a bounded band and a small kernel, in three steps:
///  1. Rows are scaled to unit 2-norm (the kernel does not change, but rows in metres and in
///     radians become comparable) and variables are grouped into components: connected through
///     rows with a nonzero coefficient. A variable in no row is free: a unit vector of the basis.
///  2. Per component, divide and conquer over its variables: a node's kernel is
///     ker [A; B; C] = blockdiag(N_A, N_B) ker(C blockdiag(N_A, N_B)), where A, B are the rows
///     inside the two halves and C the few rows straddling the split; leaves (<= 16 variables)
///     are small dense problems. Kernel directions of a node that vanish (below 1e-3 tol) on the
///     variables that rows outside the node reach are final, as no later row sees them, and are
///     stored as a block over the node's variables; only the others, at most one per reachable
///     variable, travel up. So the work per merge is bounded by the band, and a large kernel
///     (e.g. one constraint per window) costs O(n log n) memory, not n x dim.
///  3. Each small dense problem decides its rank on the diagonal of a pivoted QR, and by an SVD
///     when that diagonal comes near the tolerance (KernelOptions::relative_tolerance).
///
/// The decisions are local: a direction is null when the rows of every subproblem annihilate it
/// to within tol. So each basis vector v has |J_c v| <= tol sqrt(tree depth + 1) (unit rows),
/// exact redundancies (rank deficiency up to rounding) are always found wherever they sit, and
/// rows perturbed by less than ~tol from a degenerate set give that set's kernel. The result is
/// that of a dense SVD with the same tolerance whenever the singular values of J have a gap
/// around tol. A small singular value that only builds up along a whole chain is not a local
/// degeneracy and may be decided differently: rows x_i = 2 x_{i+1} closed by x_39 = 0 have
/// sigma_min ~ 1e-12 over 40 variables, null for a dense SVD at 1e-9; here the kernel stays {0}
/// (smallest kept singular value 5e-7).
/// Dense SVD at n = 2200 takes ~9 s; this takes 1.5-4 ms (m = 1100 points, k = 2, 3).
///
/// Variables may be ordered in any way (the engine interleaves x[2i] = rho_i, x[2i+1] = alpha_i
/// so that a window is a contiguous run); matrices passed in must use the rows' ordering.
///
/// Units. Unit rows make the decision independent of the rows' units, not of the variables':
/// a row whose coefficient of one variable is huge only because of that variable's unit (the
/// collinearity of two hits, d/d alpha ~ rho dphi, next to d/d rho ~ 1: at rho = 1e8 m the rho
/// coefficients are 1e-6 of the row) hides its other coefficients below the tolerance. So
/// ComputeKernel takes optional variable scales s (S = diag s): the rank is decided on J S^-1,
/// the rows in the variables z = S x (for the engine, s = 1 for a range and s = rho for a normal:
/// both in metres), where a uniform change of the scene's scale only scales rows, which unit rows
/// undo. The kernel returned is still ker J = S^-1 ker(J S^-1), orthonormal in x: each block's
/// columns are mapped back and orthonormalised against the blocks of its subtree (the only
/// earlier ones it overlaps), so blocks keep their supports.

#include <cstddef>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace priormap::priorlets {

/// One row of J (n_vars columns): J(row, first + j) = coefficients[j], zero elsewhere. Zero
/// coefficients inside the run are allowed and do not couple their variable.
struct ConstraintRow {
  std::size_t first = 0;
  std::vector<double> coefficients;
};

struct KernelOptions {
  /// The rank decision. After scaling each row to unit 2-norm, a direction z (unit) of a dense
  /// subproblem is null when its singular value is <= tol = relative_tolerance * s_c, where
  /// s_c = sqrt(|J_c|_1 |J_c|_inf) >= |J_c|_2 >= 1 bounds the norm of the (scaled) component
  /// J_c. So null directions have |J_c z| <~ tol at every merge, and every direction with
  /// |J z| ~ rounding (an exact constraint redundancy) is found. 1e-9 sits between the rounding
  /// of Jacobians evaluated in double (~1e-15) and the smallest genuine singular values of
  /// constraint sets over ~1000 points (> 1e-6 in the tests). Rows evaluated at a point that is
  /// only feasible to eps move zero singular values of redundant constraints to ~eps: use a
  /// tolerance above the solver's feasibility. See KernelSummary for the margins observed.
  double relative_tolerance = 1e-9;
  /// Rows with 2-norm <= this, in the caller's units, are ignored as degenerate linearisations
  /// (e.g. the gradient of a squared constraint at its zero). 0 drops only zero rows: scaling
  /// makes any other row a full constraint, and only the caller knows its units.
  double min_row_norm = 0.0;
  /// Nodes with at least this many variables solve their halves in parallel (oneTBB), as
  /// components always are. The result does not depend on it, nor on the number of threads.
  std::size_t parallel_grain = 512;

  [[nodiscard]] bool IsValid(std::string* why) const;
};

/// Kernel columns supported on a few variables: column j of the basis is `basis.col(j)` at the
/// rows `variables`, zero elsewhere.
struct KernelBlock {
  std::vector<std::size_t> variables;  ///< sorted variable indices, the rows of `basis`
  Eigen::MatrixXd basis;               ///< variables.size() x columns, orthonormal columns
  std::size_t component = 0;           ///< index of the component, in order of first variable
};

/// What the rank decisions saw, to judge how clear-cut they were. Values are singular values of
/// the unit-row subproblems (or, where the pivoted QR showed a gap of more than 1e3 either side
/// of tol, its diagonal, which orders and approximates them) divided by s_c, i.e. on the scale
/// of relative_tolerance; the decisions are safe when both are orders of magnitude from it.
struct KernelSummary {
  std::size_t num_variables = 0;
  std::size_t num_rows = 0;        ///< rows used (not dropped by min_row_norm)
  std::size_t num_components = 0;  ///< components of coupled variables (not counting free ones)
  std::size_t num_free_variables = 0;
  std::size_t dimension = 0;  ///< dim Free
  /// Largest singular value that was decided null (0 if none).
  double largest_null_singular_value = 0.0;
  /// Smallest singular value that was decided not null (+inf if none).
  double smallest_kept_singular_value = std::numeric_limits<double>::infinity();
  /// Dense subproblems solved, and how many needed an SVD because the pivoted QR diagonal fell
  /// near the tolerance.
  std::size_t num_subproblems = 0;
  std::size_t num_svd_fallbacks = 0;
};

/// An orthonormal basis N (n_vars x dimension) of Free = ker J, stored as unit vectors for the
/// free variables plus dense blocks. The column order is that of ToDense: the free variables,
/// then the blocks' columns in order.
class ConstraintKernel {
 public:
  /// Zero variables.
  ConstraintKernel() = default;
  /// The kernel of no rows: every variable free.
  explicit ConstraintKernel(std::size_t num_variables);

  [[nodiscard]] std::size_t num_variables() const { return num_variables_; }
  [[nodiscard]] std::size_t dimension() const { return dimension_; }
  /// Variables in no (kept) row: the basis holds e_v for each, sorted.
  [[nodiscard]] const std::vector<std::size_t>& free_variables() const { return free_variables_; }
  [[nodiscard]] const std::vector<KernelBlock>& blocks() const { return blocks_; }
  [[nodiscard]] const KernelSummary& summary() const { return summary_; }

  /// N, n_vars x dimension. Memory n_vars * dimension: for large kernels prefer the functions
  /// below, which cost as much as the blocks.
  [[nodiscard]] Eigen::MatrixXd ToDense() const;
  /// N^T x: coordinates in the basis. x: n_vars x c; result dimension x c.
  [[nodiscard]] Eigen::MatrixXd Coordinates(const Eigen::Ref<const Eigen::MatrixXd>& x) const;
  /// N c. c: dimension x k; result n_vars x k.
  [[nodiscard]] Eigen::MatrixXd Expand(const Eigen::Ref<const Eigen::MatrixXd>& c) const;
  /// P_Free x = N N^T x. x: n_vars x c (e.g. the extrinsic Jacobian, or a covariance, for
  /// P Sigma P^T apply twice with a transpose; Sec. IV-C).
  [[nodiscard]] Eigen::MatrixXd Project(const Eigen::Ref<const Eigen::MatrixXd>& x) const;
  /// P_Constr x = x - P_Free x: the part of x that the constraints forbid.
  [[nodiscard]] Eigen::MatrixXd ProjectOntoComplement(
      const Eigen::Ref<const Eigen::MatrixXd>& x) const;

 private:
  friend ConstraintKernel ComputeKernel(std::size_t, std::span<const ConstraintRow>,
                                        const KernelOptions&, std::span<const double>);

  std::size_t num_variables_ = 0;
  std::size_t dimension_ = 0;
  std::vector<std::size_t> free_variables_;
  std::vector<KernelBlock> blocks_;
  KernelSummary summary_;
};

/// Free = ker J for J given by `rows` over `num_variables` variables (rows in any order).
/// `variable_scales`: empty (the variables' units are comparable), or per variable the size of
/// its unit in common units (see "Units" above): the rank is decided on J S^-1, and the
/// summary's singular values are those of its subproblems; the basis is orthonormal in the
/// variables as given. Preconditions: every row lies inside [0, num_variables) and its
/// coefficients are finite; options.IsValid(); variable_scales empty or num_variables positive
/// finite numbers.
[[nodiscard]] ConstraintKernel ComputeKernel(std::size_t num_variables,
                                             std::span<const ConstraintRow> rows,
                                             const KernelOptions& options = {},
                                             std::span<const double> variable_scales = {});

/// Intr = Free ∩ Extr^perp (eq. (9)), Extr = span of the extrinsic Jacobian's columns. Stored as
/// Free minus r orthonormal directions D = N U_r (n_vars x r), the part of Free that Extr sees,
/// so that it costs no more than Free however large the kernel. U_r: the left singular vectors
/// of N^T E (E an orthonormal basis of Extr) whose singular values, the cosines of the angles
/// between Extr and Free, exceed relative_tolerance. For a pose-independent prior Extr is inside
/// Free (Prop. 2): all cosines are ~1 and D spans Extr; a cosine well below 1 flags a prior or
/// an Extr that breaks that.
class IntrinsicSubspace {
 public:
  /// extrinsic: n_vars x c, columns in any scale (they are normalised; its own rank is decided
  /// with options.relative_tolerance relative to its largest singular value).
  IntrinsicSubspace(ConstraintKernel free, const Eigen::Ref<const Eigen::MatrixXd>& extrinsic,
                    const KernelOptions& options = {});

  [[nodiscard]] const ConstraintKernel& free() const { return free_; }
  [[nodiscard]] std::size_t dimension() const;
  /// D: n_vars x r, orthonormal, inside Free; Free = Intr ⊕ span D.
  [[nodiscard]] const Eigen::MatrixXd& extrinsic_in_free() const { return removed_; }
  /// Singular values of N^T E, descending; size min(rank E, dim Free).
  [[nodiscard]] const Eigen::VectorXd& cosines() const { return cosines_; }

  /// An orthonormal basis of Intr, n_vars x dimension (memory n_vars * dim Free).
  [[nodiscard]] Eigen::MatrixXd ToDense() const;
  /// P_Intr x = P_Free x - D D^T x. x: n_vars x c.
  [[nodiscard]] Eigen::MatrixXd Project(const Eigen::Ref<const Eigen::MatrixXd>& x) const;

 private:
  ConstraintKernel free_;
  Eigen::MatrixXd removed_;              ///< D
  Eigen::MatrixXd removed_coordinates_;  ///< U_r = N^T D, dim Free x r
  Eigen::VectorXd cosines_;
};

}  // namespace priormap::priorlets
