// Sec. IV of the paper at the MAP scan: Free from the constraint Jacobian (constraint_kernel),
// Extr in closed form (extrinsic), Intr, and the covariance restricted to Free.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numbers>
#include <optional>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <fmt/format.h>

#include <priormap/core/check.hpp>
#include <priormap/priorlets/extrinsic.hpp>
#include <priormap/priorlets/posterior.hpp>

#include "inner_problem.hpp"
#include "inner_solver.hpp"

namespace priormap::priorlets {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Singular values of grad_q r (columns scaled to unit norm) below this fraction of the largest
// are rank deficiency: a motion that moves the readings by less than 1 % of what the strongest
// does is not observable. The closed form is evaluated at the estimate, not the true scan: for a
// circle seen from off its centre the rotation is a combination of the translations (exactly, by
// ray casting: 4e-11), up to the estimate's error, which leaves 1e-6 at the tightened solution
// (1e-4 at the engine's, feasible to ~1e-7); a genuine third direction is > 0.05 (two circles:
// 0.07, any corner in view: > 0.1).
constexpr double kExtrinsicRankTolerance = 1e-2;

// The problem of the final topology, rebuilt from the map: the same data, initial normals and
// their weak prior the last solve used.
InnerProblem MakeFinalProblem(const Scan& scan, const dsl::CompiledPrior& prior,
                              const MapScan& map) {
  const std::vector<std::size_t>& beams = map.inmodel_beams;
  std::vector<ProblemPoint> points(beams.size());
  std::vector<double> sigma(beams.size());
  for (std::size_t j = 0; j < beams.size(); ++j) {
    const std::size_t b = beams[j];
    ProblemPoint& pt = points[j];
    pt.phi = scan.angles[b];
    pt.rho_measured = scan.ranges[b];
    // Unbounded: TightenFeasibility weighs the barrier by 0 (ObjectiveValue::Total skips it).
    pt.rho_lower = -std::numeric_limits<double>::infinity();
    pt.rho_upper = std::numeric_limits<double>::infinity();
    pt.alpha_initial = map.initial_alpha[b];
    pt.alpha_sigma = map.initial_alpha_sigma[b];
    pt.alpha_lower = pt.rho_lower;
    pt.alpha_upper = pt.rho_upper;
    sigma[j] = scan.sigma[b];
  }
  std::vector<Link> links = map.links;
  if (map.closed) links.push_back(map.closing_link);  // a ring (a full-turn scan)
  return InnerProblem(prior, std::move(points), std::move(links), std::move(sigma),
                      InModelRangePrecision(scan, beams), map.closed);
}

// Curvature d alpha / d s of one region's points by central differences over up to
// kCurvatureReach points on each side: the normals lie on the prior's surface only to the
// solution's feasibility (~1e-7 as the engine leaves it), and a difference between neighbours
// 0.25 deg apart would amplify that to ~1e-3 relative error in kappa (enough to make a circle's
// rotation look independent of its translations).
constexpr std::size_t kCurvatureReach = 8;

void RegionCurvature(std::span<const double> rho, std::span<const double> alpha,
                     std::span<const double> phi, std::span<double> kappa) {
  const std::size_t count = rho.size();
  std::vector<double> arc(count, 0.0);  // polyline length from the first point
  for (std::size_t j = 1; j < count; ++j) {
    arc[j] = arc[j - 1] + std::hypot(rho[j] * std::cos(phi[j]) - rho[j - 1] * std::cos(phi[j - 1]),
                                     rho[j] * std::sin(phi[j]) - rho[j - 1] * std::sin(phi[j - 1]));
  }
  for (std::size_t j = 0; j < count; ++j) {
    const std::size_t lo = j >= kCurvatureReach ? j - kCurvatureReach : 0;
    const std::size_t hi = std::min(count - 1, j + kCurvatureReach);
    const double ds = arc[hi] - arc[lo];
    // alpha grows with s where the surface is concave as seen from the sensor (extrinsic.hpp).
    kappa[j] = hi > lo && ds > 0.0 ? (alpha[hi] - alpha[lo]) / ds : 0.0;
  }
}

// d x / d q at x (interleaved in-model unknowns, the point where Free is decided) in the same
// order, curvature estimated per region from x's normals (which the prior has made smooth).
// Evaluated at the same point as Free, Extr is inside Free up to that point's feasibility: on the
// circle scene at 1 - cos = 7e-13 at the tightened solution, against 1e-8 when evaluated at the
// engine's solution (feasible to ~1e-7) with Free at the tightened one.
Eigen::MatrixXd InterleavedExtrinsicJacobian(const Scan& scan, const MapScan& map,
                                             const Eigen::VectorXd& x) {
  const std::vector<std::size_t>& beams = map.inmodel_beams;
  const std::size_t m = beams.size();
  std::vector<double> rho(m), alpha(m), phi(m), curvature(m, 0.0);
  for (std::size_t j = 0; j < m; ++j) {
    rho[j] = x[static_cast<Eigen::Index>(2 * j)];
    alpha[j] = x[static_cast<Eigen::Index>(2 * j + 1)];
    phi[j] = scan.angles[beams[j]];
  }
  // The region across the seam of a ring (its points from `start` on, round the seam, a turn
  // on past it, reach points more on each side when it has no border): gathered in order.
  const auto ring_region = [&](std::size_t start, std::size_t count, std::size_t reach) {
    const std::size_t total = count + 2 * reach;
    std::vector<double> r(total), a(total), p(total), k(total);
    for (std::size_t t = 0; t < total; ++t) {
      const long u = static_cast<long>(start + t) - static_cast<long>(reach);
      const long turns = u < 0 ? -1 : u / static_cast<long>(m);
      const auto j = static_cast<std::size_t>(u - turns * static_cast<long>(m));
      r[t] = rho[j];
      a[t] = alpha[j] + 2.0 * std::numbers::pi * static_cast<double>(turns);
      p[t] = phi[j] + 2.0 * std::numbers::pi * static_cast<double>(turns);
    }
    RegionCurvature(r, a, p, k);
    for (std::size_t t = 0; t < count; ++t) curvature[(start + t) % m] = k[t + reach];
  };
  std::size_t open_first = 0, open_end = m;  // the points left for the chain loop
  if (map.closed) {
    // Start after the last border; none: the whole ring is one region.
    std::size_t last_border = m;
    for (std::size_t l = m; l-- > 0;) {
      if ((l + 1 < m ? map.links[l] : map.closing_link) != Link::kSameRegion) {
        last_border = l;
        break;
      }
    }
    if (last_border == m) {
      ring_region(0, m, std::min(kCurvatureReach, m / 2));
      open_first = m;
    } else if (last_border + 1 < m) {
      std::size_t e = 0;  // the region across the seam ends at the first border
      while (map.links[e] == Link::kSameRegion) ++e;
      ring_region(last_border + 1, m - last_border + e, 0);
      open_first = e + 1;
      open_end = last_border + 1;
    }
  }
  for (std::size_t j = open_first; j < open_end;) {
    std::size_t e = j;
    while (e + 1 < open_end && map.links[e] == Link::kSameRegion) ++e;
    const std::size_t count = e - j + 1;
    RegionCurvature(std::span(rho).subspan(j, count), std::span(alpha).subspan(j, count),
                    std::span(phi).subspan(j, count), std::span(curvature).subspan(j, count));
    j = e + 1;
  }
  const Eigen::Matrix<double, Eigen::Dynamic, 3> stacked =
      ExtrinsicJacobian(rho, alpha, phi, curvature);
  Eigen::MatrixXd e(static_cast<Eigen::Index>(2 * m), 3);
  for (std::size_t j = 0; j < m; ++j) {
    const auto r = static_cast<Eigen::Index>(j);
    e.row(2 * r) = stacked.row(r);
    e.row(2 * r + 1) = stacked.row(static_cast<Eigen::Index>(m) + r);
  }
  return e;
}

// An orthonormal basis of the column span of e (interleaved rows as InterleavedExtrinsicJacobian's,
// columns dx, dy, dtheta), rank decided relative to its largest singular value after scaling the
// columns to comparable units. The translations share one scale, the norm of their pair: scaled
// one by one, a translation that moves no reading (along a wall that faces the sensor, whose dy
// column is sin(pi) ~ 1e-16) would become a unit column of rounding and a third direction of
// Extr, which then could not lie inside Free. The rotation, in other units, gets its own scale,
// unless it moves the readings by less than kExtrinsicRankTolerance of what its terms would
// without cancelling (the sensor at the centre of a circular room: kappa rho - 1 = 0 in the
// alpha rows, rho tan(beta) = 0 in the range rows); then it is no direction at all.
Eigen::MatrixXd OrthonormalColumnSpan(const Eigen::MatrixXd& e) {
  Eigen::MatrixXd scaled = e;
  const double translation = std::sqrt(0.5) * e.leftCols(2).norm();
  if (translation > 0.0) scaled.leftCols(2) /= translation;
  // The alpha rows are kappa rho / |cos beta| - 1 (extrinsic.hpp): without cancelling, |J + 1| + 1.
  double uncancelled = 0.0;
  for (Eigen::Index r = 0; r < e.rows(); ++r) {
    const double term = r % 2 == 0 ? e(r, 2) : std::abs(e(r, 2) + 1.0) + 1.0;
    uncancelled += term * term;
  }
  const double rotation = e.col(2).norm();
  if (rotation > kExtrinsicRankTolerance * std::sqrt(uncancelled)) {
    scaled.col(2) /= rotation;
  } else {
    scaled.col(2).setZero();
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(scaled, Eigen::ComputeThinU);
  const Eigen::VectorXd& s = svd.singularValues();
  Eigen::Index rank = 0;
  while (rank < s.size() && s[rank] > kExtrinsicRankTolerance * s[0]) ++rank;
  return svd.matrixU().leftCols(rank);
}

// A rank decision of Free at one point.
struct KernelDecision {
  Eigen::VectorXd x;
  KernelOptions options;
  ConstraintKernel kernel;

  /// Largest null over smallest kept singular value (0 when either side is empty).
  [[nodiscard]] double Overlap() const {
    const KernelSummary& s = kernel.summary();
    return s.largest_null_singular_value / s.smallest_kept_singular_value;
  }
  /// Orders of magnitude either side of the tolerance: a null and a kept singular value are more
  /// than 100x apart.
  [[nodiscard]] bool ClearCut() const { return Overlap() < 1e-2; }
};

// True when some set of unknowns that the rows couple has at least as many rows as unknowns.
// Unknowns are grouped by overlapping runs [first nonzero, last nonzero] of the rows: a coarsening
// of ComputeKernel's components (rows that overlap without sharing an unknown are joined), so
// a `true` is certain (rows >= unknowns summed over a group means the same in one of its
// components) and a `false` may miss one.
bool HasOverdeterminedComponent(std::size_t num_unknowns, const std::vector<ConstraintRow>& rows) {
  struct Run {
    std::size_t first, last;
  };
  std::vector<Run> runs;
  std::vector<std::uint8_t> used(num_unknowns, 0);
  for (const ConstraintRow& row : rows) {
    std::optional<Run> run;
    for (std::size_t j = 0; j < row.coefficients.size(); ++j) {
      if (row.coefficients[j] == 0.0) continue;
      used[row.first + j] = 1;
      if (!run) run = Run{row.first + j, row.first + j};
      run->last = row.first + j;
    }
    if (run) runs.push_back(*run);
  }
  std::sort(runs.begin(), runs.end(), [](const Run& a, const Run& b) { return a.first < b.first; });
  for (std::size_t i = 0; i < runs.size();) {
    const std::size_t first = runs[i].first;
    std::size_t last = runs[i].last, count = 0;
    for (; i < runs.size() && runs[i].first <= last; ++i, ++count)
      last = std::max(last, runs[i].last);
    const auto unknowns = static_cast<std::size_t>(
        std::count(used.begin() + static_cast<std::ptrdiff_t>(first),
                   used.begin() + static_cast<std::ptrdiff_t>(last) + 1, std::uint8_t{1}));
    if (count >= unknowns) return true;
  }
  return false;
}

// Per-beam entries of an interleaved vector over the in-model unknowns.
void Scatter(const MapScan& map, const Eigen::Ref<const Eigen::VectorXd>& v,
             std::vector<double>& rho, std::vector<double>& alpha) {
  rho.assign(map.rho.size(), kNaN);
  alpha.assign(map.rho.size(), kNaN);
  for (std::size_t j = 0; j < map.inmodel_beams.size(); ++j) {
    rho[map.inmodel_beams[j]] = v[static_cast<Eigen::Index>(2 * j)];
    alpha[map.inmodel_beams[j]] = v[static_cast<Eigen::Index>(2 * j + 1)];
  }
}

// The largest `count` eigenpairs of the symmetric c (coordinates in the basis n) as
// eigenvariations; `extrinsic_coordinates` (N^T D) gives their intrinsic fraction.
std::vector<Eigenvariation> Eigenvariations(const MapScan& map, const Eigen::MatrixXd& n,
                                            const Eigen::MatrixXd& c,
                                            const Eigen::MatrixXd& extrinsic_coordinates,
                                            int count) {
  std::vector<Eigenvariation> out;
  if (c.rows() == 0) return out;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(c);
  for (Eigen::Index k = c.rows() - 1; k >= 0 && static_cast<int>(out.size()) < count; --k) {
    const double variance = eig.eigenvalues()[k];
    if (!(variance > 0.0)) break;
    const Eigen::VectorXd u = eig.eigenvectors().col(k);
    Eigenvariation ev;
    ev.sigma = std::sqrt(variance);
    Eigen::VectorXd v = n * u;
    // A sign convention, so that the output does not flip with rounding: the largest entry > 0.
    double largest = 0.0;
    for (const double entry : v) {
      if (std::abs(entry) > std::abs(largest)) largest = entry;
    }
    if (largest < 0.0) v = -v;
    Scatter(map, v, ev.rho, ev.alpha);
    const double extrinsic = extrinsic_coordinates.cols() > 0
                                 ? (extrinsic_coordinates.transpose() * u).squaredNorm()
                                 : 0.0;
    ev.intrinsic_fraction = std::clamp(1.0 - extrinsic, 0.0, 1.0);
    out.push_back(std::move(ev));
  }
  return out;
}

// sqrt of the diagonal of the inverse of a banded precision (marginal standard deviations).
std::vector<double> MarginalStd(const SymmetricBandedMatrix& precision) {
  const std::size_t m = precision.size();
  std::vector<double> out(m, kNaN);
  const std::optional<BandedCholesky> chol = BandedCholesky::Factor(precision);
  if (!chol) return out;
  Eigen::VectorXd e = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(m));
  for (std::size_t i = 0; i < m; ++i) {
    const auto r = static_cast<Eigen::Index>(i);
    e[r] = 1.0;
    out[i] = std::sqrt(chol->Solve(e)[r]);
    e[r] = 0.0;
  }
  return out;
}

}  // namespace

Posterior AnalysePosterior(const Scan& scan, const dsl::CompiledPrior& prior, const MapScan& map,
                           const PosteriorOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  Posterior out;
  out.form = options.form;
  const std::size_t n = scan.size(), m = map.inmodel_beams.size();
  PRIORMAP_CHECK(map.rho.size() == n && map.links.size() + 1 == std::max<std::size_t>(m, 1),
                 "a MapScan of this scan");
  out.prior_std_rho.assign(n, kNaN);
  out.prior_std_alpha.assign(n, kNaN);
  out.posterior_std_rho.assign(n, kNaN);
  out.posterior_std_alpha.assign(n, kNaN);
  const auto finish = [&] {
    out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return out;
  };
  if (m == 0) {
    out.note = "no in-model points";
    return finish();
  }
  // The kernel's null threshold is 100 v (below): at v >= 0.01 it would reach the singular
  // values' own scale, and a v that is not finite is a term outside its domain at the MAP.
  if (!(100.0 * map.max_violation < 1.0)) {
    out.note = fmt::format(
        "the MAP estimate violates the prior by {} (at least 0.01): its degrees of freedom and "
        "posterior are not defined there",
        map.max_violation);
    return finish();
  }

  InnerProblem problem = MakeFinalProblem(scan, prior, map);
  Eigen::VectorXd x(static_cast<Eigen::Index>(2 * m));
  for (std::size_t j = 0; j < m; ++j) {
    x[static_cast<Eigen::Index>(2 * j)] = map.rho[map.inmodel_beams[j]];
    x[static_cast<Eigen::Index>(2 * j + 1)] = map.alpha[map.inmodel_beams[j]];
  }

  // Free = ker grad f_T at a point feasible to v, null below relative_tolerance = max(1e-9, 100 v)
  // (see PosteriorOptions::kernel_tolerance). Directions that are null only because rows are
  // redundant on the constraint manifold (a circle: three rows per window, rank 2m - 3) are not
  // null off it: the subproblems of ComputeKernel see them at up to ~100 v (2.8e-5 at the
  // engine's v = 3.7e-7 on the circle scene), while genuinely weak directions, deformations of a
  // long smooth region whose rows see them only through differences between neighbours, have
  // singular values that fall as (beam spacing / region length)^2: 3e-5 in the subproblems (6.5e-6
  // in the whole J) for 1081 points of a circle. At the engine's feasibility the two overlap, and
  // the rank decision takes a weak deformation for a kernel direction (the circle's Free then
  // missed Extr by cos 0.95). TightenFeasibility takes x to v ~ 1e-11 near the same optimum; there
  // the null ones are ~10 v (6e-11) and the tolerance, 1e-9, sits more than 10x above them and
  // 10^4 below the weak ones. It costs about as much as one kernel, so it is done first when a
  // group of coupled unknowns has at least as many rows as unknowns (then any kernel there is a
  // redundancy, almost always one that holds only on the manifold), and otherwise only when the
  // decision at the engine's point is not clear-cut. The tightened point is kept only when its
  // decision is clear-cut: a prior that does not fit the scene (circles on straight walls) has a
  // continuum of singular values that no point separates, and its decision at the tighter
  // tolerance is as arbitrary, so the engine's point, which the JSON's max_violation describes,
  // is kept for it.
  // The rank is decided with every unknown in metres (ComputeKernel's variable scales): a range
  // as it is, a normal times its range (how far a turn of it moves the surface at the hit).
  // Otherwise the normals' coefficients, ~ rho dphi, hide the ranges' as the scene grows: a
  // straight wall seen by 200 beams over 1 rad keeps its two degrees of freedom up to 2e6 m and
  // has 18 at 2e7 m, 200 at 2e8 m.
  const auto decide = [&](Eigen::VectorXd at, double violation,
                          const std::vector<ConstraintRow>& rows) {
    KernelDecision d{std::move(at), {}, {}};
    d.options.relative_tolerance = std::max(options.kernel_tolerance, 100.0 * violation);
    std::vector<double> scales(2 * m, 1.0);
    for (std::size_t j = 0; j < m; ++j) {
      const double rho = std::abs(d.x[static_cast<Eigen::Index>(2 * j)]);
      if (rho > 0.0 && std::isfinite(rho)) scales[2 * j + 1] = rho;
    }
    d.kernel = ComputeKernel(2 * m, rows, d.options, scales);
    return d;
  };
  const auto decide_tightened = [&]() -> std::optional<KernelDecision> {
    double violation = map.max_violation;
    Eigen::VectorXd tight = TightenFeasibility(problem, x, &violation);
    if (!(violation < map.max_violation)) return std::nullopt;
    const std::vector<ConstraintRow> rows = problem.EqualityRows(tight);
    return decide(std::move(tight), violation, rows);
  };
  const std::vector<ConstraintRow> rows = problem.EqualityRows(x);
  const bool tighten_first = HasOverdeterminedComponent(2 * m, rows);
  std::optional<KernelDecision> tightened;
  if (tighten_first) tightened = decide_tightened();
  KernelDecision decision = tightened && tightened->ClearCut() ? std::move(*tightened)
                                                               : decide(x, map.max_violation, rows);
  if (!decision.ClearCut() && !tighten_first) {
    tightened = decide_tightened();
    if (tightened && tightened->ClearCut()) decision = std::move(*tightened);
  }
  x = std::move(decision.x);
  ConstraintKernel kernel = std::move(decision.kernel);
  const KernelOptions kernel_options = decision.options;
  out.dof.kernel = kernel.summary();
  out.dof.free = kernel.dimension();

  // Extr = span grad_q r; Intr = Free minus what Extr sees of it.
  const Eigen::MatrixXd extrinsic =
      OrthonormalColumnSpan(InterleavedExtrinsicJacobian(scan, map, x));
  out.dof.extrinsic = static_cast<std::size_t>(extrinsic.cols());
  const IntrinsicSubspace intrinsic(std::move(kernel), extrinsic, kernel_options);
  out.dof.intrinsic = intrinsic.dimension();
  const Eigen::VectorXd& cosines = intrinsic.cosines();
  out.dof.min_extrinsic_cosine =
      cosines.size() < extrinsic.cols() ? 0.0 : (cosines.size() ? cosines.minCoeff() : 1.0);
  out.dof.pose_independent = out.dof.min_extrinsic_cosine >= options.pose_independence_cosine;
  if (!out.dof.pose_independent) {
    out.note = fmt::format(
        "the prior is not pose-independent here: Extr is not inside Free (smallest cosine {:.3g})",
        out.dof.min_extrinsic_cosine);
  }

  // Prior standard deviations: the sensor's noise model and the initial normals' weak prior.
  const std::optional<SymmetricBandedMatrix> precision =
      InModelRangePrecision(scan, map.inmodel_beams);
  const std::vector<double> range_std = precision ? MarginalStd(*precision) : std::vector<double>{};
  for (std::size_t j = 0; j < m; ++j) {
    const std::size_t b = map.inmodel_beams[j];
    out.prior_std_rho[b] = precision ? range_std[j] : scan.sigma[b];
    out.prior_std_alpha[b] = map.initial_alpha_sigma[b];
  }

  // A = Sigma_0^-1 + Hess h (energies made convex per window, as in the solve), in the
  // problem's Hessian order (that of the unknowns, but for a ring: InnerProblem::HessianIndex).
  SymmetricBandedMatrix information;
  (void)problem.Evaluate(x, 0.0, 0.0, nullptr, &information);

  const ConstraintKernel& free = intrinsic.free();
  if (free.dimension() > options.max_free_dimension) {
    if (!out.note.empty()) out.note += "; ";
    out.note += fmt::format("dim Free = {} > {}: no eigenvariations or covariance matrix",
                            free.dimension(), options.max_free_dimension);
    if (free.dimension() == free.num_variables()) {
      // Nothing constrained: Sigma_x = A^-1, whose diagonal banded solves give in O(n^2 b).
      const std::vector<double> std_x = MarginalStd(information);
      for (std::size_t j = 0; j < m; ++j) {
        out.posterior_std_rho[map.inmodel_beams[j]] = std_x[problem.HessianIndex(2 * j)];
        out.posterior_std_alpha[map.inmodel_beams[j]] = std_x[problem.HessianIndex(2 * j + 1)];
      }
    } else {
      out.note += " nor standard deviations";
    }
    return finish();
  }
  const Eigen::MatrixXd basis = free.ToDense();  // N, 2m x d
  const auto d = static_cast<Eigen::Index>(free.dimension());
  Eigen::MatrixXd c(d, d);  // Sigma_x = N c N^T
  if (options.form == CovarianceForm::kConditional) {
    Eigen::MatrixXd an(basis.rows(), d);
    for (Eigen::Index k = 0; k < d; ++k) {
      an.col(k) =
          problem.FromHessianOrder(information.Multiply(problem.ToHessianOrder(basis.col(k))));
    }
    const Eigen::MatrixXd reduced = basis.transpose() * an;
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(reduced);
    c = ldlt.solve(Eigen::MatrixXd::Identity(d, d));
  } else {
    const std::optional<BandedCholesky> chol = BandedCholesky::Factor(information);
    PRIORMAP_CHECK(chol.has_value(), "the data information is positive definite");
    Eigen::MatrixXd solved(basis.rows(), d);
    for (Eigen::Index k = 0; k < d; ++k) {
      solved.col(k) = problem.FromHessianOrder(chol->Solve(problem.ToHessianOrder(basis.col(k))));
    }
    c = basis.transpose() * solved;
  }
  c = 0.5 * (c + c.transpose());

  const Eigen::MatrixXd nc = basis * c;
  for (std::size_t j = 0; j < m; ++j) {
    const std::size_t b = map.inmodel_beams[j];
    const auto r = static_cast<Eigen::Index>(2 * j);
    out.posterior_std_rho[b] = std::sqrt(std::max(0.0, nc.row(r).dot(basis.row(r))));
    out.posterior_std_alpha[b] = std::sqrt(std::max(0.0, nc.row(r + 1).dot(basis.row(r + 1))));
  }

  // Eigenvariations of Sigma_x, and of its intrinsic part Q c Q (Q = I - G G^T, G = N^T D the
  // extrinsic directions inside Free in coordinates).
  const Eigen::MatrixXd g = free.Coordinates(intrinsic.extrinsic_in_free());
  out.eigenvariations = Eigenvariations(map, basis, c, g, options.eigenvariations);
  const Eigen::MatrixXd q = Eigen::MatrixXd::Identity(d, d) - g * g.transpose();
  // Q c Q has rank dim Intr; its other eigenvalues are rounding.
  out.intrinsic_eigenvariations =
      Eigenvariations(map, basis, q * c * q, g,
                      std::min(options.eigenvariations, static_cast<int>(out.dof.intrinsic)));

  if (options.keep_range_covariance) {
    Eigen::MatrixXd ranges(static_cast<Eigen::Index>(m), d);
    for (std::size_t j = 0; j < m; ++j) {
      ranges.row(static_cast<Eigen::Index>(j)) = basis.row(static_cast<Eigen::Index>(2 * j));
    }
    out.range_covariance = ranges * c * ranges.transpose();
  }
  out.computed = true;
  return finish();
}

}  // namespace priormap::priorlets
