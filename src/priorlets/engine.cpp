// Algorithm 1 of the paper (the discrete optimisation of INMODEL and the topology) around
// Algorithm 2 (inner_solver.cpp), with geometric decisions up front, several breaks per round,
// and a refinement of the region borders once a feasible topology is found.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <span>

#include <priormap/core/angles.hpp>
#include <priormap/core/check.hpp>
#include <priormap/priorlets/engine.hpp>
#include <priormap/priorlets/normal_baselines.hpp>

#include "inner_problem.hpp"
#include "inner_solver.hpp"

namespace priormap::priorlets {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

double DegToRad(double deg) {
  return deg * std::numbers::pi / 180.0;
}

// Links with a penalty above this fraction of the largest form the zones of BreakLinks.
constexpr double kZoneFraction = 0.01;
// Border refinement: points on each side of a border in its local problem, and moves at most.
constexpr int kRefineHalfWindow = 30;
constexpr int kMaxBorderMoves = 8;
// A warm-started solve resumes the penalty homotopy this factor below where the last ended.
constexpr double kWarmLambdaBackoff = 1e-3;

// The state of Algorithm 1: which valid beams are in the model and how consecutive ones relate.
struct Topology {
  std::vector<std::size_t> beams;  // in-model beams, increasing
  std::vector<Link> links;         // links[j] between beams[j] and beams[j + 1]
};

// Maximal runs [first, last] of consecutive points whose links are all `joining` or stricter:
// regions for kSameRegion, surfaces for kDifferentRegion.
std::vector<std::pair<std::size_t, std::size_t>> Runs(const Topology& topology, Link joining) {
  std::vector<std::pair<std::size_t, std::size_t>> runs;
  const std::size_t m = topology.beams.size();
  for (std::size_t j = 0; j < m;) {
    std::size_t e = j;
    while (e + 1 < m && topology.links[e] <= joining) ++e;
    runs.emplace_back(j, e);
    j = e + 1;
  }
  return runs;
}

class Engine {
 public:
  Engine(const Scan& scan, const dsl::CompiledPrior& prior, const EngineOptions& options)
      : scan_(scan), prior_(prior), options_(options) {}

  MapScan Run();

 private:
  // True when readings a < b cannot be on one surface (Fig. 5a): a max-range reading between
  // them, or a range jump no visible surface of curvature <= max_curvature explains even with
  // both ranges moved to their bounds.
  [[nodiscard]] bool GeometricBreak(std::size_t a, std::size_t b) const;
  [[nodiscard]] Link InitialLink(std::size_t a, std::size_t b) const {
    return GeometricBreak(a, b) ? Link::kDifferentSurface : Link::kSameRegion;
  }
  // Initial normals from total-least-squares lines through each point's region neighbours.
  [[nodiscard]] std::vector<ProblemPoint> MakePoints(const Topology& topology) const;
  [[nodiscard]] InnerProblem MakeProblem(const Topology& topology) const;
  // Unknowns of `to` taken from a solution over `from` where the beams agree (else initial).
  [[nodiscard]] Eigen::VectorXd WarmStart(const Topology& from, const Eigen::VectorXd& x,
                                          const Topology& to, const InnerProblem& problem) const;
  // `resume_homotopy`: start the penalty homotopy near where the last solve ended (border
  // refinement) instead of from the data (the greedy rounds, which need the early link
  // penalties).
  InnerResult Solve(const Topology& topology, const Topology* previous,
                    const Eigen::VectorXd* previous_x, bool resume_homotopy);
  // Relaxes the links the penalties point at; false when none can be relaxed any more.
  bool BreakLinks(Topology& topology, const std::vector<double>& penalties) const;
  // Removes points of too-small regions; the link across a removed run is same_region again
  // unless geometry says otherwise.
  bool RemoveLonelyPoints(Topology& topology) const;
  // Removes the point after the link with the largest penalty (when no link can relax).
  void RemoveWorstPoints(Topology& topology, const std::vector<double>& penalties) const;
  // The points with keep[j] set, bridged across removed runs as RemoveLonelyPoints says.
  [[nodiscard]] Topology Keep(const Topology& topology, const std::vector<char>& keep) const;
  void RefineBorders(Topology& topology, InnerResult& solution);
  // Data and energy terms of the last solved problem at its solution.
  [[nodiscard]] double FitCost(const InnerResult& solution);
  // In-model points first..last with their links.
  [[nodiscard]] static Topology Slice(const Topology& topology, std::size_t first,
                                      std::size_t last);

  const Scan& scan_;
  const dsl::CompiledPrior& prior_;
  const EngineOptions& options_;
  EngineStats stats_;
  std::unique_ptr<InnerProblem> problem_;  // of the last solve
  double previous_lambda_ = 0.0;           // where the last solve's homotopy ended
};

bool Engine::GeometricBreak(std::size_t a, std::size_t b) const {
  for (std::size_t i = a + 1; i < b; ++i) {
    if (scan_.status[i] == BeamStatus::kMaxRange) return true;
  }
  const double dphi = std::abs(scan_.angles[b] - scan_.angles[a]);
  const double slack_a = options_.rho_bound_sigmas * scan_.sigma[a];
  const double slack_b = options_.rho_bound_sigmas * scan_.sigma[b];
  const bool a_near = scan_.ranges[a] <= scan_.ranges[b];
  const double near = (a_near ? scan_.ranges[a] + slack_a : scan_.ranges[b] + slack_b);
  const double far = (a_near ? scan_.ranges[b] - slack_b : scan_.ranges[a] - slack_a);
  if (far <= near) return false;
  // A straight surface seen at incidence theta at the far reading and theta - dphi at the near
  // one has far / near = cos(theta - dphi) / cos(theta); curvature lets the surface turn by
  // up to the angle its chord subtends.
  const double chord = std::hypot(far - near, near * dphi);
  const double turn = prior_.max_curvature() > 0.0
                          ? 2.0 * std::asin(std::min(1.0, 0.5 * prior_.max_curvature() * chord))
                          : 0.0;
  const double theta = std::min(DegToRad(options_.max_incidence_deg) + turn, DegToRad(89.9));
  if (dphi >= theta) return false;
  return far / near > std::cos(theta - dphi) / std::cos(theta);
}

std::vector<ProblemPoint> Engine::MakePoints(const Topology& topology) const {
  const std::size_t m = topology.beams.size();
  std::vector<ProblemPoint> points(m);
  // Region of each in-model point.
  std::vector<std::size_t> region_start(m), region_end(m);
  for (const auto& [first, last] : Runs(topology, Link::kSameRegion)) {
    std::fill(region_start.begin() + static_cast<long>(first),
              region_start.begin() + static_cast<long>(last) + 1, first);
    std::fill(region_end.begin() + static_cast<long>(first),
              region_end.begin() + static_cast<long>(last) + 1, last);
  }
  const auto h = static_cast<std::size_t>(std::max(1, options_.normal_half_window));
  const double alpha_bound = DegToRad(options_.alpha_bound_deg);
  for (std::size_t j = 0; j < m; ++j) {
    const std::size_t beam = topology.beams[j];
    ProblemPoint& pt = points[j];
    pt.phi = scan_.angles[beam];
    pt.rho_measured = scan_.ranges[beam];
    const double slack = options_.rho_bound_sigmas * scan_.sigma[beam];
    pt.rho_lower = std::max(pt.rho_measured - slack, 0.5 * pt.rho_measured);
    pt.rho_upper = pt.rho_measured + slack;
    const double facing = pt.phi + std::numbers::pi;  // the normal of a surface seen head-on
    pt.alpha_lower = facing - alpha_bound;
    pt.alpha_upper = facing + alpha_bound;
    // Total least squares line through the region neighbours.
    const std::size_t lo = std::max(region_start[j], j >= h ? j - h : 0);
    const std::size_t hi = std::min(region_end[j], j + h);
    pt.alpha_initial = facing;
    pt.alpha_sigma = std::max(options_.alpha_prior_sigma_min, 0.5);
    if (hi - lo + 1 < 3) continue;
    const std::span<const std::size_t> neighbours(topology.beams.data() + lo, hi - lo + 1);
    if (const std::optional<double> normal = FitLineNormal(scan_, neighbours, beam)) {
      pt.alpha_initial = facing + WrapAngle(*normal - facing);
      pt.alpha_sigma = options_.alpha_prior_sigma_min;
    }
  }
  return points;
}

InnerProblem Engine::MakeProblem(const Topology& topology) const {
  std::vector<double> sigma(topology.beams.size());
  for (std::size_t j = 0; j < sigma.size(); ++j) sigma[j] = scan_.sigma[topology.beams[j]];
  std::optional<SymmetricBandedMatrix> precision;
  if (scan_.precision) {
    // The precision of the in-model readings: the rows and columns of the scan's precision,
    // which is the conditional model given the other readings (an outlier's noise says nothing
    // about its neighbours'); its bandwidth in in-model indices is at most the scan's.
    const std::size_t b = scan_.precision->bandwidth(), m = topology.beams.size();
    SymmetricBandedMatrix sub(m, b);
    for (std::size_t j = 0; j < m; ++j) {
      for (std::size_t q = j; q < std::min(m, j + b + 1); ++q) {
        sub.Set(q, j, (*scan_.precision)(topology.beams[q], topology.beams[j]));
      }
    }
    precision = std::move(sub);
  }
  return InnerProblem(prior_, MakePoints(topology), topology.links, std::move(sigma),
                      std::move(precision));
}

Eigen::VectorXd Engine::WarmStart(const Topology& from, const Eigen::VectorXd& x,
                                  const Topology& to, const InnerProblem& problem) const {
  Eigen::VectorXd start = problem.InitialPoint();
  std::size_t i = 0;
  for (std::size_t j = 0; j < to.beams.size(); ++j) {
    while (i < from.beams.size() && from.beams[i] < to.beams[j]) ++i;
    if (i < from.beams.size() && from.beams[i] == to.beams[j]) {
      start[static_cast<Eigen::Index>(2 * j)] = x[static_cast<Eigen::Index>(2 * i)];
      start[static_cast<Eigen::Index>(2 * j + 1)] = x[static_cast<Eigen::Index>(2 * i + 1)];
    }
  }
  return start;
}

InnerResult Engine::Solve(const Topology& topology, const Topology* previous,
                          const Eigen::VectorXd* previous_x, bool resume_homotopy) {
  problem_ = std::make_unique<InnerProblem>(MakeProblem(topology));
  Eigen::VectorXd start;
  if (previous && previous_x) start = WarmStart(*previous, *previous_x, topology, *problem_);
  // A warm start resumes the homotopy a few stages before where the last solve ended.
  const double lambda_start =
      resume_homotopy && previous_lambda_ > 0.0 ? previous_lambda_ * kWarmLambdaBackoff : 0.0;
  InnerResult result = SolveInner(*problem_, previous ? &start : nullptr, options_, lambda_start);
  previous_lambda_ = result.lambda;
  ++stats_.inner_solves;
  stats_.newton_steps += result.newton_steps;
  return result;
}

bool Engine::BreakLinks(Topology& topology, const std::vector<double>& penalties) const {
  const std::size_t n = topology.links.size();
  const auto relaxable = [&](std::size_t l) {
    return topology.links[l] != Link::kDifferentSurface;
  };
  double worst = 0.0;
  for (std::size_t l = 0; l < n; ++l) {
    if (relaxable(l)) worst = std::max(worst, penalties[l]);
  }
  if (!(worst > 0.0)) return false;
  // The penalty of one wrong link spreads over the links around it (the penalty solution bends
  // the surface within the range bounds), so the links are grouped into zones of non-negligible
  // penalty and only the largest link of a zone breaks. Zones whose peak is far below the
  // largest wait for a later round.
  bool changed = false;
  for (std::size_t l = 0; l < n;) {
    if (!(penalties[l] > kZoneFraction * worst) || !relaxable(l)) {
      ++l;
      continue;
    }
    std::size_t peak = l, e = l;
    while (e < n && penalties[e] > kZoneFraction * worst && relaxable(e)) {
      if (penalties[e] > penalties[peak]) peak = e;
      ++e;
    }
    if (penalties[peak] >= options_.break_ratio * worst) {
      topology.links[peak] = static_cast<Link>(static_cast<int>(topology.links[peak]) + 1);
      changed = true;
    }
    l = e;
  }
  return changed;
}

Topology Engine::Keep(const Topology& topology, const std::vector<char>& keep) const {
  Topology next;
  for (std::size_t j = 0; j < topology.beams.size(); ++j) {
    if (!keep[j]) continue;
    if (!next.beams.empty()) {
      // Kept neighbours keep their link; across a removed run the strictest link is tried again.
      next.links.push_back(keep[j - 1] ? topology.links[j - 1]
                                       : InitialLink(next.beams.back(), topology.beams[j]));
    }
    next.beams.push_back(topology.beams[j]);
  }
  return next;
}

bool Engine::RemoveLonelyPoints(Topology& topology) const {
  std::vector<char> keep(topology.beams.size(), 1);
  bool removed = false;
  for (const auto& [first, last] : Runs(topology, Link::kSameRegion)) {
    if (last - first + 1 >= static_cast<std::size_t>(options_.min_region_points)) continue;
    std::fill(keep.begin() + static_cast<long>(first), keep.begin() + static_cast<long>(last) + 1,
              0);
    removed = true;
  }
  if (removed) topology = Keep(topology, keep);
  return removed;
}

void Engine::RemoveWorstPoints(Topology& topology, const std::vector<double>& penalties) const {
  if (topology.beams.empty()) return;
  // Drop the point after the link with the largest penalty.
  const std::size_t worst = static_cast<std::size_t>(
      std::max_element(penalties.begin(), penalties.end()) - penalties.begin());
  std::vector<char> keep(topology.beams.size(), 1);
  keep[topology.beams.size() == 1 ? 0 : worst + 1] = 0;
  topology = Keep(topology, keep);
}

double Engine::FitCost(const InnerResult& solution) {
  const ObjectiveValue v = problem_->Evaluate(solution.x, 0.0, 0.0, nullptr, nullptr);
  return v.data + v.energy;
}

Topology Engine::Slice(const Topology& topology, std::size_t first, std::size_t last) {
  Topology sub;
  sub.beams.assign(topology.beams.begin() + static_cast<long>(first),
                   topology.beams.begin() + static_cast<long>(last) + 1);
  sub.links.assign(topology.links.begin() + static_cast<long>(first),
                   topology.links.begin() + static_cast<long>(last));
  return sub;
}

void Engine::RefineBorders(Topology& topology, InnerResult& solution) {
  // Each border is judged on the points around it alone (a local problem of the two regions'
  // nearest points): cheap, and a merge that is infeasible locally is infeasible globally.
  const Topology before = topology;
  const auto local_solve = [&](const Topology& sub, const Topology& warm_topology,
                               const Eigen::VectorXd& warm_x, double* cost) {
    ++stats_.refinement_trials;
    InnerResult r = Solve(sub, &warm_topology, &warm_x, true);
    if (cost) *cost = FitCost(r);
    return r;
  };
  const auto half = static_cast<std::size_t>(kRefineHalfWindow);
  for (std::size_t l = 0; l < topology.links.size(); ++l) {
    if (topology.links[l] == Link::kSameRegion) continue;
    if (topology.links[l] == Link::kDifferentSurface &&
        GeometricBreak(topology.beams[l], topology.beams[l + 1])) {
      continue;
    }
    const std::size_t first = l >= half ? l - half + 1 : 0;
    const std::size_t last = std::min(topology.beams.size() - 1, l + half);
    Topology local = Slice(topology, first, last);
    const std::size_t at = l - first;
    double cost = 0.0;
    InnerResult current = local_solve(local, topology, solution.x, &cost);
    if (!current.feasible) continue;
    // Merge back: a feasible stricter topology explains the scan with fewer regions. The
    // strictest is tried first: a wall split by a wrong different_surface link is one region.
    bool merged_back = false;
    for (int stricter = 0; stricter < static_cast<int>(local.links[at]) && !merged_back;
         ++stricter) {
      Topology merged = local;
      merged.links[at] = static_cast<Link>(stricter);
      if (local_solve(merged, local, current.x, nullptr).feasible) {
        local = std::move(merged);
        merged_back = true;
      }
    }
    if (merged_back) {
      topology.links[l] = local.links[at];
      continue;
    }
    // Move the border while the fit improves.
    std::size_t border = at;
    for (int direction : {-1, +1}) {
      for (int moves = 0; moves < kMaxBorderMoves; ++moves) {
        const long to = static_cast<long>(border) + direction;
        if (to < 0 || to >= static_cast<long>(local.links.size())) break;
        const auto t = static_cast<std::size_t>(to);
        if (local.links[t] != Link::kSameRegion) break;
        Topology moved = local;
        moved.links[t] = local.links[border];
        moved.links[border] = Link::kSameRegion;
        double moved_cost = 0.0;
        InnerResult r = local_solve(moved, local, current.x, &moved_cost);
        if (!r.feasible || !(moved_cost < cost - 1e-9 * (1.0 + std::abs(cost)))) break;
        local = std::move(moved);
        current = std::move(r);
        cost = moved_cost;
        border = t;
      }
    }
    for (std::size_t j = 0; j < local.links.size(); ++j) topology.links[first + j] = local.links[j];
    l = std::max(l, first + border);
  }
  if (topology.links == before.links) return;
  InnerResult refined = Solve(topology, &before, &solution.x, true);
  if (refined.feasible) {
    solution = std::move(refined);
  } else {
    topology = before;  // the local decisions did not hold together: keep the greedy result
  }
}

MapScan Engine::Run() {
  const Clock::time_point start = Clock::now();
  Topology topology;
  for (std::size_t i = 0; i < scan_.size(); ++i) {
    if (!scan_.IsValid(i)) continue;
    if (!topology.beams.empty()) topology.links.push_back(InitialLink(topology.beams.back(), i));
    topology.beams.push_back(i);
  }
  // Points that cannot form a region are outliers from the start.
  RemoveLonelyPoints(topology);

  InnerResult solution;
  Topology solved;
  bool have_solution = false;
  const Clock::time_point outer_start = Clock::now();
  for (int round = 0; round < options_.max_outer_rounds; ++round) {
    ++stats_.outer_rounds;
    InnerResult result = Solve(topology, have_solution ? &solved : nullptr,
                               have_solution ? &solution.x : nullptr, false);
    solution = std::move(result);
    solved = topology;
    have_solution = true;
    const std::vector<double>& penalties = solution.early_link_penalties;
    if (solution.feasible || topology.beams.empty()) break;
    bool changed = BreakLinks(topology, penalties);
    changed = RemoveLonelyPoints(topology) || changed;
    if (!changed) RemoveWorstPoints(topology, penalties);
  }
  stats_.seconds_outer = Seconds(outer_start);
  if (solution.feasible && options_.refine_borders) {
    const Clock::time_point refine_start = Clock::now();
    RefineBorders(solved, solution);
    stats_.seconds_refine = Seconds(refine_start);
  }
  // The problem of the final topology, for the objective.
  if (!problem_ || problem_->num_points() != solved.beams.size() ||
      problem_->links() != solved.links) {
    problem_ = std::make_unique<InnerProblem>(MakeProblem(solved));
  }

  MapScan out;
  const std::size_t n = scan_.size();
  out.rho = scan_.ranges;
  out.alpha.assign(n, std::numeric_limits<double>::quiet_NaN());
  out.initial_alpha = out.alpha;
  out.initial_alpha_sigma = out.alpha;
  out.alpha_lower = out.alpha;
  out.alpha_upper = out.alpha;
  out.inmodel.assign(n, 0);
  out.inmodel_beams = solved.beams;
  out.links = solved.links;
  for (std::size_t j = 0; j < solved.beams.size(); ++j) {
    const std::size_t beam = solved.beams[j];
    const ProblemPoint& pt = problem_->points()[j];
    out.rho[beam] = solution.x[static_cast<Eigen::Index>(2 * j)];
    out.alpha[beam] = solution.x[static_cast<Eigen::Index>(2 * j + 1)];
    out.initial_alpha[beam] = pt.alpha_initial;
    out.initial_alpha_sigma[beam] = pt.alpha_sigma;
    out.alpha_lower[beam] = pt.alpha_lower;
    out.alpha_upper[beam] = pt.alpha_upper;
    out.inmodel[beam] = 1;
  }
  for (const auto& [first, last] : Runs(solved, Link::kSameRegion)) {
    out.regions.push_back({solved.beams[first], solved.beams[last]});
  }
  for (const auto& [first, last] : Runs(solved, Link::kDifferentRegion)) {
    out.surfaces.push_back({solved.beams[first], solved.beams[last]});
  }
  out.feasible = solution.feasible;
  out.max_violation = solution.violation.max_residual;
  const double gamma = std::log(options_.beta / (1.0 - options_.beta));
  out.objective = FitCost(solution) - gamma * static_cast<double>(solved.beams.size());
  stats_.seconds_total = Seconds(start);
  out.stats = stats_;
  return out;
}

}  // namespace

MapScan EstimateMapScan(const Scan& scan, const dsl::CompiledPrior& prior,
                        const EngineOptions& options) {
  PRIORMAP_CHECK(prior.order() >= 1, "a prior of order >= 1");
  PRIORMAP_CHECK(options.beta > 0.0 && options.beta < 1.0, "beta in (0, 1)");
  Engine engine(scan, prior, options);
  return engine.Run();
}

}  // namespace priormap::priorlets
