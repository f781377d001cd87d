#pragma once
/// What the MAP scan leaves free and how sure it is (de la Puente & Censi, Sec. IV): the degrees
/// of freedom Free = ker grad f_T, their split into extrinsic (a sensor motion) and intrinsic
/// (the map itself) parts, the shrunk posterior covariance and the scan eigenvariations.
#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>

#include <priormap/core/scan.hpp>
#include <priormap/dsl/prior.hpp>
#include <priormap/priorlets/constraint_kernel.hpp>
#include <priormap/priorlets/engine.hpp>

namespace priormap::priorlets {

/// How the covariance is restricted to Free (N: an orthonormal basis of Free, A = Sigma_0^-1 +
/// Hess h the information of the data, the initial normals and the energies).
enum class CovarianceForm {
  /// N (N^T A N)^-1 N^T: the Gaussian A^-1 conditioned on staying in Free (the Laplace
  /// approximation on the constraint manifold). The default: it weighs every unknown by its own
  /// information, so a range known to 1 cm is not blurred by a normal known to 0.2 rad.
  kConditional,
  /// P_Free A^-1 P_Free^T with P_Free = N N^T, the paper's eq. (10) as written. An orthogonal
  /// projection in a space mixing metres and radians: equal to kConditional when A is a
  /// multiple of the identity on Free, wider otherwise.
  kProjected,
};

struct PosteriorOptions {
  CovarianceForm form = CovarianceForm::kConditional;
  /// Eigenvariations reported (the largest), of Sigma_x and of its intrinsic part.
  int eigenvariations = 5;
  /// The rank decision of Free: KernelOptions::relative_tolerance is this, or 100 times the
  /// solution's largest constraint residual when that is larger (a redundancy that holds only
  /// on the constraint manifold shows singular values of the order of the residual). The rank is
  /// decided with every unknown in metres, a normal times its range (ComputeKernel's variable
  /// scales), so that the same geometry at any scale has the same degrees of freedom; the
  /// summary's singular values (DegreesOfFreedom::kernel) are those of that scaled Jacobian.
  double kernel_tolerance = 1e-9;
  /// The covariance is dense in Free (d x d, eigen-decomposed: O(d^3)): above this dim(Free) only
  /// the degrees of freedom are computed, and, when nothing is constrained (a prior of energies
  /// only: Free is everything, Sigma_x = A^-1, banded), the per-beam standard deviations.
  std::size_t max_free_dimension = 600;
  /// Extr is inside Free when every cosine between them is at least this (Prop. 2 of the paper).
  double pose_independence_cosine = 0.999;
  /// Keep the in-model range covariance (m x m, for figures); not written to JSON.
  bool keep_range_covariance = false;
};

/// dim Free, dim Extr (= rank grad_q r), dim Intr (= dim Free - dim(Extr ∩ Free)).
struct DegreesOfFreedom {
  std::size_t free = 0;
  std::size_t extrinsic = 0;
  std::size_t intrinsic = 0;
  /// Smallest cosine between Extr and Free (1 when Extr is inside Free).
  double min_extrinsic_cosine = 1.0;
  bool pose_independent = true;  ///< min_extrinsic_cosine >= options.pose_independence_cosine
  KernelSummary kernel;          ///< how clear-cut the rank decisions of Free were
};

/// One scan eigenvariation <v, sigma>: the readings vary by t * sigma * v, t ~ N(0, 1).
/// Per-beam vectors have one entry per beam of the scan (NaN outside INMODEL); v is a unit
/// vector over the in-model unknowns (rho and alpha mixed, as in the paper).
struct Eigenvariation {
  double sigma = 0.0;  ///< standard deviation along v
  std::vector<double> rho;
  std::vector<double> alpha;
  double intrinsic_fraction = 0.0;  ///< |P_Intr v|^2: 1 for a pure map change, 0 for a pose change
};

struct Posterior {
  bool computed = false;  ///< false when skipped (see `note`); `dof` is still filled
  std::string note;       ///< why it was skipped, or warnings (e.g. not pose-independent)
  CovarianceForm form = CovarianceForm::kConditional;
  DegreesOfFreedom dof;
  /// Per beam (NaN outside INMODEL): the prior standard deviation of the range (the sensor's
  /// noise model) and of the initial normal, and the posterior ones (sqrt diag Sigma_x).
  std::vector<double> prior_std_rho, prior_std_alpha;
  std::vector<double> posterior_std_rho, posterior_std_alpha;
  /// Largest first.
  std::vector<Eigenvariation> eigenvariations;            ///< of Sigma_x
  std::vector<Eigenvariation> intrinsic_eigenvariations;  ///< of P_Intr Sigma_x P_Intr^T
  /// Covariance of the in-model ranges (INMODEL order), when keep_range_covariance.
  Eigen::MatrixXd range_covariance;
  double seconds = 0.0;
};

/// Sec. IV at the solution `map` of EstimateMapScan(scan, prior, ...) (the map carries what the
/// engine's options decided: bounds, the initial normals and their weak prior).
/// Preconditions: `map` came from such a call.
[[nodiscard]] Posterior AnalysePosterior(const Scan& scan, const dsl::CompiledPrior& prior,
                                         const MapScan& map, const PosteriorOptions& options = {});

}  // namespace priormap::priorlets
