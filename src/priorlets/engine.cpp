// Algorithm 1 of the paper (the discrete optimisation of INMODEL and the topology) around
// Algorithm 2 (inner_solver.cpp), with geometric decisions up front, several breaks per round,
// and a refinement of the region borders once a feasible topology is found.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <optional>
#include <span>

#include <priormap/core/angles.hpp>
#include <priormap/core/check.hpp>
#include <priormap/core/types.hpp>
#include <priormap/priorlets/corner_geometry.hpp>
#include <priormap/priorlets/engine.hpp>

#include "inner_problem.hpp"
#include "inner_solver.hpp"

namespace priormap::priorlets {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

// Links with a penalty above this fraction of the largest form the zones of BreakLinks.
constexpr double kZoneFraction = 0.01;
// An infeasible solve that brought the penalty below this fraction of its first stage's is
// near a solution: what is left of the penalty points at what is wrong.
constexpr double kNearlyFeasible = 0.01;
// Border refinement: points on each side of a border in its local problem, and moves at most.
constexpr int kRefineHalfWindow = 30;
constexpr int kMaxBorderMoves = 8;
// A corner's border moves at most this many beams to where the regions' lines meet, and the fit
// may worsen by this much per moved reading (a reading a few millimetres from the corner is
// within about 2 sigma of both lines: up to 2 nats, doubled for the lines' own adjustment).
constexpr int kMaxCornerShift = 3;
constexpr double kCornerCostSlack = 4.0;
// Settling the corners moves lines a little, which may move a corner again: passes at most.
constexpr int kCornerPasses = 2;
// A warm-started refinement solve resumes the penalty homotopy this factor below where the
// greedy solution's ended.
constexpr double kWarmLambdaBackoff = 1e-3;
// The window of an initial normal grows from normal_half_window neighbours on each side up to
// this many times as many while the points fit a line.
constexpr std::size_t kMaxNormalHalfWindow = 16;
// A spike (RemoveSpikes) is judged against the line through this many times normal_half_window
// neighbours on each side, and lies beyond its range bound by this many standard deviations of
// that line's position at its bearing.
constexpr std::size_t kSpikeWindowFactor = 2;
constexpr double kSpikeLineSigmas = 3.0;
// RemoveSpikes passes at most (each after the last one's removals; 1-2 suffice in practice).
constexpr int kSpikePasses = 3;

// Total least squares lines through runs of consecutive points, from prefix sums of the
// weighted moments (O(1) per window).
class LineFitter {
 public:
  struct Fit {
    double normal = 0.0;  // direction of the line's normal (either sense)
    double ssr = 0.0;     // weighted sum of squared orthogonal residuals
    std::size_t n = 0;
    Vec2 centroid = Vec2::Zero();  // weighted
    double weight = 0.0;           // the sum of the weights
    double spread = 0.0;           // weighted sum of squared positions along the line
    // The standard deviation of the line's orthogonal position at `p` (its offset's, 1 /
    // weight, and its direction's, 1 / spread, with the weights 1 / sigma^2).
    [[nodiscard]] double PositionSigma(const Vec2& p) const {
      const double along = (p - centroid).dot(Vec2(-std::sin(normal), std::cos(normal)));
      return std::sqrt(1.0 / weight + along * along / spread);
    }
    // The residual per degree of freedom (about 1 for points on a line).
    [[nodiscard]] double NormalisedResidual() const {
      return n > 2 ? ssr / static_cast<double>(n - 2) : 0.0;
    }
    // True when the residual is within the noise at the 99.9% level (chi-square with n - 2
    // degrees of freedom, Wilson-Hilferty approximation of its quantile).
    [[nodiscard]] bool Consistent() const {
      if (n <= 2) return true;
      const double k = static_cast<double>(n - 2), c = 2.0 / (9.0 * k);
      return ssr <= k * std::pow(1.0 - c + 3.09 * std::sqrt(c), 3);
    }
  };

  // Points in the sensor frame with weights 1 / sigma^2 (the noise is radial; its orthogonal
  // part is smaller, which makes the test lenient at grazing incidence).
  LineFitter(const std::vector<Vec2>& xy, const std::vector<double>& weight)
      : sums_(xy.size() + 1, Moments{}) {
    for (std::size_t j = 0; j < xy.size(); ++j) {
      const double w = weight[j], x = xy[j].x(), y = xy[j].y();
      const Moments& s = sums_[j];
      sums_[j + 1] = {s.w + w,          s.x + w * x,      s.y + w * y,
                      s.xx + w * x * x, s.xy + w * x * y, s.yy + w * y * y};
    }
  }

  // The line through points lo..hi; nullopt for fewer than 3 points or coinciding ones.
  [[nodiscard]] std::optional<Fit> operator()(std::size_t lo, std::size_t hi) const {
    if (hi < lo + 2) return std::nullopt;
    return FitOf(sums_[hi + 1] - sums_[lo], hi - lo + 1);
  }

  // The line through points lo..hi without the points skip_lo..skip_hi inside them.
  [[nodiscard]] std::optional<Fit> Without(std::size_t lo, std::size_t hi, std::size_t skip_lo,
                                           std::size_t skip_hi) const {
    const std::size_t n = (hi - lo + 1) - (skip_hi - skip_lo + 1);
    if (n < 3) return std::nullopt;
    return FitOf((sums_[hi + 1] - sums_[lo]) - (sums_[skip_hi + 1] - sums_[skip_lo]), n);
  }

 private:
  struct Moments {
    double w, x, y, xx, xy, yy;
    Moments operator-(const Moments& o) const {
      return {w - o.w, x - o.x, y - o.y, xx - o.xx, xy - o.xy, yy - o.yy};
    }
  };

  static std::optional<Fit> FitOf(const Moments& m, std::size_t n) {
    const double w = m.w, cx = m.x / w, cy = m.y / w;
    const double sxx = m.xx - w * cx * cx;
    const double sxy = m.xy - w * cx * cy;
    const double syy = m.yy - w * cy * cy;
    if (!(sxx + syy > 0.0)) return std::nullopt;
    Fit fit;
    fit.normal = 0.5 * std::atan2(2.0 * sxy, sxx - syy) + 0.5 * std::numbers::pi;
    const double root = std::hypot(sxx - syy, 2.0 * sxy);
    fit.ssr = std::max(0.0, 0.5 * (sxx + syy - root));
    fit.spread = 0.5 * (sxx + syy + root);
    fit.centroid = Vec2(cx, cy);
    fit.weight = w;
    fit.n = n;
    return fit;
  }

  std::vector<Moments> sums_;
};

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// The state of Algorithm 1: which valid beams are in the model and how consecutive ones relate.
// A closed topology is a ring (the points of a scan that covers a full turn): it has one link
// per point, links.back() relating the last point to the first. An open one is a chain: the
// scan's points in order, or a slice of a ring (RefineBorders, SettleCorners) that may cross
// its seam, continuing from the scan's last beams at its first ones a turn on.
struct Topology {
  std::vector<std::size_t> beams;  // in-model beams in scan order
  std::vector<Link> links;         // links[j] between points j and j + 1 (mod size when closed)
  bool closed = false;

  // 2 pi for the points of an open slice that lie past the seam (their bearings, and normals,
  // are a turn on from the scan's), else 0. Such a slice holds less than a turn, so those are
  // exactly its points of smaller beam index than its first.
  [[nodiscard]] double Turn(std::size_t j) const {
    return !closed && j > 0 && beams[j] < beams[0] ? kTwoPi : 0.0;
  }
  // The link before point j and after it: none (nullopt) at the ends of a chain.
  [[nodiscard]] std::optional<std::size_t> LinkBefore(std::size_t j) const {
    if (j > 0) return j - 1;
    return closed && !beams.empty() ? std::optional<std::size_t>(links.size() - 1) : std::nullopt;
  }
  [[nodiscard]] std::optional<std::size_t> LinkAfter(std::size_t j) const {
    if (j < links.size()) return j;
    return std::nullopt;
  }
  // The point after link l (l + 1, or 0 after a ring's closing link).
  [[nodiscard]] std::size_t PointAfter(std::size_t l) const {
    return l + 1 < beams.size() ? l + 1 : 0;
  }
};

// a mod n for a signed a, n > 0.
std::size_t Mod(long a, std::size_t n) {
  const long r = a % static_cast<long>(n);
  return static_cast<std::size_t>(r < 0 ? r + static_cast<long>(n) : r);
}

// How clearly the largest penalty of a relaxable link stands out: its ratio to the median.
double Prominence(const std::vector<double>& penalties, const Topology& topology) {
  std::vector<double> relaxable;
  double worst = 0.0;
  for (std::size_t l = 0; l < penalties.size(); ++l) {
    if (topology.links[l] == Link::kDifferentSurface) continue;
    relaxable.push_back(penalties[l]);
    worst = std::max(worst, penalties[l]);
  }
  if (relaxable.empty() || !(worst > 0.0)) return 0.0;
  const auto mid = relaxable.begin() + static_cast<long>(relaxable.size() / 2);
  std::nth_element(relaxable.begin(), mid, relaxable.end());
  return worst / std::max(*mid, std::numeric_limits<double>::min());
}

double Sum(const std::vector<double>& values) {
  return std::accumulate(values.begin(), values.end(), 0.0);
}

// Points in the run [first, last] of `topology` (Runs), round the seam of a ring.
std::size_t RunLength(const Topology& topology, std::size_t first, std::size_t last) {
  return last >= first ? last - first + 1 : last + topology.beams.size() - first + 1;
}

// Maximal runs [first, last] of consecutive points whose links are all `joining` or stricter:
// regions for kSameRegion, surfaces for kDifferentRegion. In a ring, the run across the seam has
// first > last and is listed last; a ring without a border is the one run [0, m - 1].
std::vector<std::pair<std::size_t, std::size_t>> Runs(const Topology& topology, Link joining) {
  std::vector<std::pair<std::size_t, std::size_t>> runs;
  const std::size_t m = topology.beams.size();
  if (topology.closed && m > 0) {
    std::vector<std::size_t> borders;
    for (std::size_t l = 0; l < m; ++l) {
      if (topology.links[l] > joining) borders.push_back(l);
    }
    if (borders.empty()) return {{0, m - 1}};
    if (borders.back() == m - 1) runs.emplace_back(0, borders.front());
    for (std::size_t b = 0; b + 1 < borders.size(); ++b)
      runs.emplace_back(borders[b] + 1, borders[b + 1]);
    if (borders.back() != m - 1) runs.emplace_back(borders.back() + 1, borders.front());
    return runs;
  }
  for (std::size_t j = 0; j < m;) {
    std::size_t e = j;
    while (e + 1 < m && topology.links[e] <= joining) ++e;
    runs.emplace_back(j, e);
    j = e + 1;
  }
  return runs;
}

// Moves the border at links[from] to links[to], of the same kind; false (links untouched) when
// `to` is outside the links or another border lies on the way. In a ring (`closed`) `to` counts
// round the seam (mod the number of links), less than a turn away.
bool MoveBorder(std::vector<Link>& links, std::size_t from, long to, bool closed = false) {
  const auto n = static_cast<long>(links.size());
  if (closed) {
    if (to - static_cast<long>(from) >= n || static_cast<long>(from) - to >= n) return false;
  } else if (to < 0 || to >= n) {
    return false;
  }
  const long step = to > static_cast<long>(from) ? 1 : -1;
  for (long k = static_cast<long>(from) + step; k != to + step; k += step) {
    if (links[closed ? Mod(k, links.size()) : static_cast<std::size_t>(k)] != Link::kSameRegion)
      return false;
  }
  const std::size_t target = closed ? Mod(to, links.size()) : static_cast<std::size_t>(to);
  links[target] = links[from];
  links[from] = Link::kSameRegion;
  return true;
}

// The points of the regions on each side of the border at links[border] (link l joins points l
// and l + 1); a slice's end counts as a border. In a ring they count round the seam.
std::pair<std::size_t, std::size_t> RegionsBeside(const std::vector<Link>& links,
                                                  std::size_t border, bool closed = false) {
  std::size_t left = 1, right = 1;
  if (closed) {
    const std::size_t n = links.size();
    while (left < n && links[(border + n - left) % n] == Link::kSameRegion) ++left;
    while (right < n && links[(border + right) % n] == Link::kSameRegion) ++right;
    return {left, right};
  }
  while (left <= border && links[border - left] == Link::kSameRegion) ++left;
  while (border + right < links.size() && links[border + right] == Link::kSameRegion) ++right;
  return {left, right};
}

// MoveBorder that also keeps both regions beside the moved border at min_points or more, as the
// greedy rounds leave every region (RemoveLonelyPoints): false, links untouched, otherwise.
bool MoveBorderKeepingRegions(std::vector<Link>& links, std::size_t from, long to,
                              std::size_t min_points, bool closed = false) {
  if (!MoveBorder(links, from, to, closed)) return false;
  const std::size_t target = closed ? Mod(to, links.size()) : static_cast<std::size_t>(to);
  const auto [left, right] = RegionsBeside(links, target, closed);
  if (left >= min_points && right >= min_points) return true;
  MoveBorder(links, target, static_cast<long>(from) + (static_cast<long>(target) - to), closed);
  return false;
}

class Engine {
 public:
  Engine(const Scan& scan, const dsl::CompiledPrior& prior, const EngineOptions& options)
      : scan_(scan), prior_(prior), options_(options), moved_(scan.size(), 0) {}

  MapScan Run();

 private:
  // True when readings a < b cannot be on one surface (Fig. 5a): a max-range reading between
  // them, or a range jump no visible surface of curvature <= max_curvature explains even with
  // both ranges moved to their bounds. a > b: across the seam of a scan that covers a full
  // turn, from a to the scan's end and on from its start to b.
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
  // `control.lambda_start` > 0: start the penalty homotopy there, near where the solution
  // warm starting it ended (border refinement), instead of from the data (the greedy rounds,
  // which need the early link penalties).
  InnerResult Solve(const Topology& topology, const Topology* previous,
                    const Eigen::VectorXd* previous_x, const InnerControl& control = {});
  // Relaxes the links the penalties point at; false when none can be relaxed any more.
  bool BreakLinks(Topology& topology, const std::vector<double>& penalties) const;
  // Removes points of too-small regions; the link across a removed run is same_region again
  // unless geometry says otherwise. A small run cut off by a link broken this round (`before`:
  // the topology before the breaks) next to an older border is not removed but joins the
  // region across that border (the border moves), once per point: near a corner the first
  // break is often a beam off.
  bool RemoveLonelyPoints(Topology& topology, const Topology* before = nullptr);
  // Removes spikes: runs of fewer than min_region_points readings between neighbours that fit
  // one line within the noise, every reading of the run farther from that line than its range
  // bound lets it move (paper Sec. III-B: such readings make the constraints impossible and are
  // to leave INMODEL). Left in, one costs a break at the first round, whose different_region
  // constraint splits the straight wall around it into regions of alternating normals, and the
  // greedy rounds do not undo that (a region has no cost but the constraints). Judged up front,
  // like GeometricBreak; a spike near a border or next to another outlier, whose neighbours fit
  // no one line, is left to the greedy rounds.
  bool RemoveSpikes(Topology& topology) const;
  // What RemoveLonelyPoints keeps, and so what border moves may leave.
  [[nodiscard]] std::size_t MinRegionPoints() const {
    return static_cast<std::size_t>(std::max(1, options_.min_region_points));
  }
  // Removes the point after the link with the largest penalty (when no link can relax).
  void RemoveWorstPoints(Topology& topology, const std::vector<double>& penalties) const;
  // The points with keep[j] set, bridged across removed runs as RemoveLonelyPoints says.
  [[nodiscard]] Topology Keep(const Topology& topology, const std::vector<char>& keep) const;
  void RefineBorders(Topology& topology, InnerResult& solution);
  // Makes the border at links[border] and the next border in `direction` same_region, joining
  // the region between them and both its neighbours into one; the other border's index, or
  // nullopt (links untouched) when there is none or either is a geometric break.
  [[nodiscard]] std::optional<std::size_t> DissolveRegion(Topology& topology, std::size_t border,
                                                          int direction) const;
  // CheckCorner for the border after point `at` of the slice of `count` points from `first` of
  // `topology` (round the seam of a ring), solved as x.
  [[nodiscard]] CornerCheck CornerAt(const Topology& topology, const Eigen::VectorXd& x,
                                     std::size_t first, std::size_t count, std::size_t at) const;
  // Every different_region link claims a corner: its border moves to where the two regions'
  // lines meet (corner_geometry.hpp; not when that leaves either region below the minimum), or,
  // when they meet nowhere near it, it becomes different_surface (one region hides the other, Fig.
  // 5b); then the whole scan is solved again, and kept when the prior allows it and the fit stays
  // within the noise. Judged on the whole solution: a local problem's lines rest on a few dozen
  // points and place a corner less than a beam precisely, the whole scan's on hundreds.
  void SettleCorners(Topology& topology, InnerResult& solution);
  // The problem of `topology` in problem_ (after local solves it may hold another).
  void UseProblemOf(const Topology& topology);
  // Data and energy terms of the last solved problem at its solution.
  [[nodiscard]] double FitCost(const InnerResult& solution);
  // The measurement and energy terms: what border refinement compares. The weak prior on the
  // initial normals is left out, as its targets are refitted for every topology.
  [[nodiscard]] double ComparableCost(const InnerResult& solution) {
    return ComparableCost(solution.x);
  }
  [[nodiscard]] double ComparableCost(const Eigen::VectorXd& x);
  // The `count` in-model points from `first` on (round the seam of a ring) with the links
  // between them: a chain.
  [[nodiscard]] static Topology Slice(const Topology& topology, std::size_t first,
                                      std::size_t count);
  // The slice of RefineBorders and SettleCorners around link l: up to kRefineHalfWindow points
  // on each side (fewer at a chain's ends; a ring shorter than two half windows whole, cut
  // opposite l). Returns its first point and size, and l's place in it.
  struct SliceAround {
    std::size_t first = 0, count = 0, at = 0;
  };
  [[nodiscard]] static SliceAround Around(const Topology& topology, std::size_t l);
  // x of `slice` (from `first` of `topology`, Slice) pasted into x of `topology`.
  static void Paste(const Topology& topology, const Topology& slice, std::size_t first,
                    const Eigen::VectorXd& slice_x, Eigen::VectorXd& x);
  // The fewest points a ring keeps (fewer: a chain): more than the prior's order, and 3.
  [[nodiscard]] std::size_t MinRingPoints() const {
    return std::max<std::size_t>(3, static_cast<std::size_t>(prior_.order()) + 1);
  }

  const Scan& scan_;
  const dsl::CompiledPrior& prior_;
  const EngineOptions& options_;
  EngineStats stats_;
  std::unique_ptr<InnerProblem> problem_;  // of the last solve
  std::vector<char> moved_;                // per beam: moved across a border once already
};

bool Engine::GeometricBreak(std::size_t a, std::size_t b) const {
  const bool seam = b < a;
  for (std::size_t i = a + 1; i < (seam ? scan_.size() : b); ++i) {
    if (scan_.status[i] == BeamStatus::kMaxRange) return true;
  }
  for (std::size_t i = 0; seam && i < b; ++i) {
    if (scan_.status[i] == BeamStatus::kMaxRange) return true;
  }
  const double dphi = seam ? scan_.angles[b] + kTwoPi - scan_.angles[a]
                           : std::abs(scan_.angles[b] - scan_.angles[a]);
  const double slack_a = options_.rho_bound_sigmas * scan_.sigma[a];
  const double slack_b = options_.rho_bound_sigmas * scan_.sigma[b];
  const bool a_near = scan_.ranges[a] <= scan_.ranges[b];
  const double near = (a_near ? scan_.ranges[a] + slack_a : scan_.ranges[b] + slack_b);
  const double far = (a_near ? scan_.ranges[b] - slack_b : scan_.ranges[a] - slack_a);
  if (far <= near) return false;
  // Readings come from where a surface is seen at an incidence of at most max_incidence, and
  // one surface between two rays that is seen so everywhere has d(ln r)/d(phi) = tan(incidence)
  // <= tan(theta): far / near <= exp(tan(theta) dphi) (a logarithmic spiral; a straight surface,
  // all a prior of curvature 0 allows, reaches only cos(theta - dphi) / cos(theta)). A curved
  // surface could bridge any jump by turning to grazing incidence between the rays, where it
  // returns nothing: that is an unseen stretch, a border of what the scan sees, whatever the
  // prior's max_curvature (with it, the jump at a pillar's edge would be left to the penalties,
  // which on a curvature prior the noise of the normals drowns).
  const double theta = DegToRad(options_.max_incidence_deg);
  if (dphi >= theta) return false;
  const double ratio = prior_.max_curvature() > 0.0 ? std::exp(std::tan(theta) * dphi)
                                                    : std::cos(theta - dphi) / std::cos(theta);
  return far / near > ratio;
}

std::vector<ProblemPoint> Engine::MakePoints(const Topology& topology) const {
  const std::size_t m = topology.beams.size();
  std::vector<ProblemPoint> points(m);
  // Windows are runs of indices into the points; a ring's points are laid out three times over
  // so that a window round its seam is one too: point j at u = j + offset.
  const bool ring = topology.closed;
  const std::size_t offset = ring ? m : 0, copies = ring ? 3 : 1;
  // Region of each in-model point, as indices u.
  std::vector<std::size_t> region_start(m), region_end(m);
  for (const auto& [first, last] : Runs(topology, Link::kSameRegion)) {
    if (!ring) {
      std::fill(region_start.begin() + static_cast<long>(first),
                region_start.begin() + static_cast<long>(last) + 1, first);
      std::fill(region_end.begin() + static_cast<long>(first),
                region_end.begin() + static_cast<long>(last) + 1, last);
      continue;
    }
    const std::size_t length = RunLength(topology, first, last);
    const bool borderless = topology.links[(first + m - 1) % m] == Link::kSameRegion;
    for (std::size_t t = 0; t < length; ++t) {
      const std::size_t j = (first + t) % m;
      // A ring without borders: any m consecutive points, centred on j.
      region_start[j] = borderless ? j + m - (m - 1) / 2 : j + m - t;
      region_end[j] = region_start[j] + (borderless ? m : length) - 1;
    }
  }
  std::vector<Vec2> xy(copies * m);
  std::vector<double> weight(copies * m);
  for (std::size_t u = 0; u < copies * m; ++u) {
    const std::size_t beam = topology.beams[u % m];
    xy[u] = scan_.PointInSensorFrame(beam);
    weight[u] = 1.0 / (scan_.sigma[beam] * scan_.sigma[beam]);
  }
  const LineFitter line_fit(xy, weight);
  const auto h = static_cast<std::size_t>(std::max(1, options_.normal_half_window));
  const double alpha_bound = DegToRad(options_.alpha_bound_deg);
  // Near a region's ends a centred window shrinks to a few beams, a few millimetres apart at
  // close range, which give no normal at all. Under a prior of straight walls only, the window
  // is shifted inside the region instead: a chord's normal is then the wall's. (On a curved
  // wall a shifted chord's normal is biased, and the centred window is kept.)
  const bool shift = prior_.max_curvature() == 0.0;
  for (std::size_t j = 0; j < m; ++j) {
    const std::size_t beam = topology.beams[j];
    ProblemPoint& pt = points[j];
    pt.phi = scan_.angles[beam] + topology.Turn(j);
    pt.rho_measured = scan_.ranges[beam];
    const double slack = options_.rho_bound_sigmas * scan_.sigma[beam];
    pt.rho_lower = std::max(pt.rho_measured - slack, 0.5 * pt.rho_measured);
    pt.rho_upper = pt.rho_measured + slack;
    const double facing = pt.phi + std::numbers::pi;  // the normal of a surface seen head-on
    pt.alpha_lower = facing - alpha_bound;
    pt.alpha_upper = facing + alpha_bound;
    pt.alpha_initial = facing;
    pt.alpha_sigma = std::max(options_.alpha_prior_sigma_min, 0.5);
    // The initial normal: a total least squares line through the region neighbours. The
    // centred window grows while its points fit one line within the noise (a wall's normal,
    // and on a curved wall the normal of the chord, which a centred window does not bias);
    // when not even the smallest one fits (next to a corner or jump the topology does not know
    // yet) the one-sided window that fits best, so that the normals do not smear across it.
    const std::size_t rs = region_start[j], re = region_end[j], u = j + offset;
    std::optional<LineFitter::Fit> fit;
    for (std::size_t half = h; 2 * half <= std::min(re - rs, 2 * kMaxNormalHalfWindow * h);
         half *= 2) {
      const bool centred = u >= rs + half && u + half <= re;
      if (!centred && !shift) break;
      const std::size_t lo = std::clamp(u, rs + half, re - half) - half;
      const std::optional<LineFitter::Fit> wider = line_fit(lo, lo + 2 * half);
      if (!wider || !wider->Consistent()) break;
      fit = wider;
    }
    if (!fit) {
      for (const auto& [lo, hi] : {std::pair{std::max(rs, u >= 2 * h ? u - 2 * h : 0), u},
                                   std::pair{u, std::min(re, u + 2 * h)}}) {
        const std::optional<LineFitter::Fit> side = line_fit(lo, hi);
        if (side && (!fit || side->NormalisedResidual() < fit->NormalisedResidual())) fit = side;
      }
    }
    if (!fit) continue;
    double normal = fit->normal;
    if (std::abs(WrapAngle(normal - facing)) > 0.5 * std::numbers::pi) normal += std::numbers::pi;
    pt.alpha_initial = facing + WrapAngle(normal - facing);
    pt.alpha_sigma = options_.alpha_prior_sigma_min;
  }
  return points;
}

InnerProblem Engine::MakeProblem(const Topology& topology) const {
  std::vector<double> sigma(topology.beams.size());
  for (std::size_t j = 0; j < sigma.size(); ++j) sigma[j] = scan_.sigma[topology.beams[j]];
  return InnerProblem(prior_, MakePoints(topology), topology.links, std::move(sigma),
                      InModelRangePrecision(scan_, topology.beams), topology.closed);
}

Eigen::VectorXd Engine::WarmStart(const Topology& from, const Eigen::VectorXd& x,
                                  const Topology& to, const InnerProblem& problem) const {
  Eigen::VectorXd start = problem.InitialPoint();
  // A point keeps its solution when its links are as they were; one whose region changed
  // starts again from the data and the normal fitted in its new region (its old normal may be
  // the neighbouring wall's, halfway between the branches of a corner constraint).
  // (At the ends of `to`, a slice of `from` in border refinement, only the inner side counts.)
  // Neighbours and links round the seam of a ring count as any others.
  const auto same_link = [&](std::size_t i, std::size_t j, int side) {
    const std::optional<std::size_t> to_link = side < 0 ? to.LinkBefore(j) : to.LinkAfter(j);
    if (!to_link) return true;
    const std::optional<std::size_t> from_link = side < 0 ? from.LinkBefore(i) : from.LinkAfter(i);
    if (!from_link) return false;
    const std::size_t to_other = side < 0 ? *to_link : to.PointAfter(*to_link);
    const std::size_t from_other = side < 0 ? *from_link : from.PointAfter(*from_link);
    return from.beams[from_other] == to.beams[to_other] &&
           from.links[*from_link] == to.links[*to_link];
  };
  constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
  std::vector<std::size_t> index_in_from(scan_.size(), kNone);
  for (std::size_t i = 0; i < from.beams.size(); ++i) index_in_from[from.beams[i]] = i;
  for (std::size_t j = 0; j < to.beams.size(); ++j) {
    const std::size_t i = index_in_from[to.beams[j]];
    if (i != kNone && same_link(i, j, -1) && same_link(i, j, +1)) {
      start[static_cast<Eigen::Index>(2 * j)] = x[static_cast<Eigen::Index>(2 * i)];
      start[static_cast<Eigen::Index>(2 * j + 1)] = x[static_cast<Eigen::Index>(2 * i + 1)];
      // A normal past the seam of a slice is a turn on from the same normal in the ring.
      const double turn = to.Turn(j) - from.Turn(i);
      if (turn != 0.0) start[static_cast<Eigen::Index>(2 * j + 1)] += turn;
    }
  }
  return start;
}

InnerResult Engine::Solve(const Topology& topology, const Topology* previous,
                          const Eigen::VectorXd* previous_x, const InnerControl& control) {
  problem_ = std::make_unique<InnerProblem>(MakeProblem(topology));
  Eigen::VectorXd start;
  if (previous && previous_x) start = WarmStart(*previous, *previous_x, topology, *problem_);
  InnerResult result = SolveInner(*problem_, previous ? &start : nullptr, options_, control);
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
  const double threshold = kZoneFraction * worst;
  // The penalty of one wrong link spreads over the links around it (the penalty solution bends
  // the surface within the range bounds), so the links are grouped into zones of non-negligible
  // penalty and only the largest link of a zone breaks. A zone is weighed by its total penalty
  // (how far it spreads depends on the geometry, what it adds up to much less); zones far below
  // the heaviest wait for a later round.
  struct Zone {
    std::size_t peak;
    double mass;
  };
  const auto in_zone = [&](std::size_t l) { return penalties[l] > threshold && relaxable(l); };
  // A ring's links are visited from one after a link outside every zone, so that no zone is cut
  // at the seam (all in one zone: the whole ring is that zone).
  std::size_t start = 0;
  if (topology.closed) {
    while (start < n && in_zone(start)) ++start;
    start = start < n ? start + 1 : 0;
  }
  const auto link = [&](std::size_t t) { return start + t < n ? start + t : start + t - n; };
  std::vector<Zone> zones;
  for (std::size_t t = 0; t < n;) {
    if (!in_zone(link(t))) {
      ++t;
      continue;
    }
    Zone zone{link(t), 0.0};
    std::size_t e = t;
    while (e < n && in_zone(link(e))) {
      if (penalties[link(e)] > penalties[zone.peak]) zone.peak = link(e);
      zone.mass += penalties[link(e)];
      ++e;
    }
    zones.push_back(zone);
    t = e;
  }
  double heaviest = 0.0;
  for (const Zone& zone : zones) heaviest = std::max(heaviest, zone.mass);
  bool changed = false;
  for (const Zone& zone : zones) {
    if (zone.mass < options_.break_ratio * heaviest) continue;
    topology.links[zone.peak] = static_cast<Link>(static_cast<int>(topology.links[zone.peak]) + 1);
    changed = true;
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
  // A ring stays one while it has enough points; the closing link is kept when both its points
  // are.
  if (topology.closed && next.beams.size() >= MinRingPoints()) {
    next.links.push_back(keep.back() && keep.front()
                             ? topology.links.back()
                             : InitialLink(next.beams.back(), next.beams.front()));
    next.closed = true;
  }
  return next;
}

bool Engine::RemoveLonelyPoints(Topology& topology, const Topology* before) {
  const auto min_points = static_cast<std::size_t>(options_.min_region_points);
  const std::vector<std::pair<std::size_t, std::size_t>> runs = Runs(topology, Link::kSameRegion);
  const auto is_new = [&](std::size_t l) {
    return before != nullptr && before->links[l] != topology.links[l];
  };
  // An older border l that may move: not one geometry demands.
  const auto movable = [&](std::size_t l) {
    return !is_new(l) && topology.links[l] != Link::kSameRegion &&
           !GeometricBreak(topology.beams[l], topology.beams[topology.PointAfter(l)]);
  };
  const std::size_t m = topology.beams.size();
  const auto length = [&](const std::pair<std::size_t, std::size_t>& run) {
    return RunLength(topology, run.first, run.second);
  };
  std::vector<char> keep(m, 1);
  bool changed = false;
  for (std::size_t r = 0; r < runs.size(); ++r) {
    const auto [first, last] = runs[r];
    const std::size_t points = length(runs[r]);
    if (points >= min_points) continue;
    changed = true;
    bool moved_before = false;
    for (std::size_t t = 0; t < points; ++t)
      moved_before = moved_before || moved_[topology.beams[(first + t) % m]];
    // The run joins its neighbour across an older border when the other side is new. (In a
    // ring every run of several lies between two borders.)
    std::optional<std::size_t> old_border, new_border;
    const bool between_borders = topology.closed
                                     ? runs.size() > 1
                                     : first > 0 && r > 0 && last + 1 < m && r + 1 < runs.size();
    if (between_borders) {
      const std::size_t border_before = first > 0 ? first - 1 : m - 1, border_after = last;
      const auto& run_after = runs[r + 1 < runs.size() ? r + 1 : 0];
      const auto& run_before = runs[r > 0 ? r - 1 : runs.size() - 1];
      if (is_new(border_before) && movable(border_after) && length(run_after) >= min_points) {
        new_border = border_before;
        old_border = border_after;
      } else if (is_new(border_after) && movable(border_before) &&
                 length(run_before) >= min_points) {
        new_border = border_after;
        old_border = border_before;
      }
    }
    if (old_border && !moved_before) {
      topology.links[*new_border] =
          std::max(topology.links[*new_border], topology.links[*old_border]);
      topology.links[*old_border] = Link::kSameRegion;
      for (std::size_t t = 0; t < points; ++t) moved_[topology.beams[(first + t) % m]] = 1;
      continue;
    }
    for (std::size_t t = 0; t < points; ++t) keep[(first + t) % m] = 0;
  }
  if (std::find(keep.begin(), keep.end(), 0) != keep.end()) topology = Keep(topology, keep);
  return changed;
}

bool Engine::RemoveSpikes(Topology& topology) const {
  const std::size_t m = topology.beams.size();
  const std::size_t k =
      kSpikeWindowFactor * static_cast<std::size_t>(std::max(1, options_.normal_half_window));
  const auto max_run = static_cast<std::size_t>(std::max(1, options_.min_region_points - 1));
  if (m < 2 * k + 1) return false;
  // Windows are runs of indices u; a ring's points are laid out three times over, point j at
  // u = j + m, so that every point is judged, also next to the seam.
  const bool ring = topology.closed;
  if (ring && m < 2 * k + max_run) return false;
  const std::size_t offset = ring ? m : 0, total = (ring ? 3 : 1) * m;
  std::vector<Vec2> xy(total);
  std::vector<double> weight(total);
  // borders[u]: links before u that are not same_region (a window must not cross one).
  std::vector<std::size_t> borders(total, 0);
  for (std::size_t u = 0; u < total; ++u) {
    const std::size_t beam = topology.beams[u % m];
    xy[u] = scan_.PointInSensorFrame(beam);
    weight[u] = 1.0 / (scan_.sigma[beam] * scan_.sigma[beam]);
    if (u > 0)
      borders[u] = borders[u - 1] + (topology.links[(u - 1) % m] != Link::kSameRegion ? 1 : 0);
  }
  const LineFitter line_fit(xy, weight);
  // How far beyond its range bound reading u lies from `fit`, in sigmas of the line's position
  // there (positive: it cannot reach the line).
  const auto beyond = [&](const LineFitter::Fit& fit, std::size_t u) {
    const std::size_t beam = topology.beams[u % m];
    const Vec2 normal(std::cos(fit.normal), std::sin(fit.normal));
    const Vec2 ray = xy[u] / scan_.ranges[beam];
    const double incidence = std::abs(normal.dot(ray));
    if (incidence < 1e-3) return 0.0;  // the line runs along the ray: no range reaches it
    // The range at which the ray meets the line, and how far the reading is from it.
    const double reach = fit.centroid.dot(normal) / normal.dot(ray);
    const double excess =
        std::abs(scan_.ranges[beam] - reach) - options_.rho_bound_sigmas * scan_.sigma[beam];
    return excess * incidence / fit.PositionSigma(xy[u]);
  };
  std::vector<char> keep(m, 1);
  bool removed = false;
  for (std::size_t j = offset + (ring ? 0 : k); ring ? j < offset + m : j + k < m; ++j) {
    for (std::size_t len = 1; len <= max_run && j + len - 1 + k < total; ++len) {
      const std::size_t lo = j - k, hi = j + len - 1 + k;
      if (borders[hi] != borders[lo]) break;  // the window crosses a border
      bool spike = true;
      for (std::size_t i = lo; i <= hi && spike; ++i)
        spike = keep[i % m] || (i >= j && i < j + len);
      if (!spike) break;  // a spike found already is among the neighbours
      const std::optional<LineFitter::Fit> fit = line_fit.Without(lo, hi, j, j + len - 1);
      if (!fit || !fit->Consistent()) continue;
      for (std::size_t i = j; i < j + len && spike; ++i) spike = beyond(*fit, i) > kSpikeLineSigmas;
      if (!spike) continue;
      for (std::size_t i = j; i < j + len; ++i) keep[i % m] = 0;
      removed = true;
      j += len - 1;
      break;
    }
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
  keep[topology.beams.size() == 1 ? 0 : topology.PointAfter(worst)] = 0;
  topology = Keep(topology, keep);
}

double Engine::FitCost(const InnerResult& solution) {
  const ObjectiveValue v = problem_->Evaluate(solution.x, 0.0, 0.0, nullptr, nullptr);
  return v.data + v.energy;
}

double Engine::ComparableCost(const Eigen::VectorXd& x) {
  Eigen::VectorXd residual = Eigen::VectorXd::Zero(x.size());
  for (std::size_t j = 0; j < problem_->num_points(); ++j) {
    const auto r = static_cast<Eigen::Index>(2 * j);
    residual[r] = x[r] - problem_->points()[j].rho_measured;
  }
  const double ranges = 0.5 * residual.dot(problem_->data_information().Multiply(residual));
  return ranges + problem_->Evaluate(x, 0.0, 0.0, nullptr, nullptr).energy;
}

Topology Engine::Slice(const Topology& topology, std::size_t first, std::size_t count) {
  Topology sub;
  const std::size_t m = topology.beams.size();
  if (first + count <= m) {
    sub.beams.assign(topology.beams.begin() + static_cast<long>(first),
                     topology.beams.begin() + static_cast<long>(first + count));
    sub.links.assign(topology.links.begin() + static_cast<long>(first),
                     topology.links.begin() + static_cast<long>(first + count - 1));
    return sub;
  }
  for (std::size_t t = 0; t < count; ++t) {  // round the seam of a ring
    sub.beams.push_back(topology.beams[(first + t) % m]);
    if (t + 1 < count) sub.links.push_back(topology.links[(first + t) % m]);
  }
  return sub;
}

Engine::SliceAround Engine::Around(const Topology& topology, std::size_t l) {
  const std::size_t m = topology.beams.size(), half = kRefineHalfWindow;
  SliceAround slice;
  if (!topology.closed) {
    slice.first = l >= half ? l - half + 1 : 0;
    slice.count = std::min(m - 1, l + half) - slice.first + 1;
    slice.at = l - slice.first;
    return slice;
  }
  slice.count = std::min(m, 2 * half);
  slice.at = slice.count / 2 - 1;
  slice.first = (l + m - slice.at) % m;
  return slice;
}

void Engine::Paste(const Topology& topology, const Topology& slice, std::size_t first,
                   const Eigen::VectorXd& slice_x, Eigen::VectorXd& x) {
  const std::size_t m = topology.beams.size(), count = slice.beams.size();
  if (first + count <= m && !topology.closed) {
    x.segment(static_cast<Eigen::Index>(2 * first), slice_x.size()) = slice_x;
    return;
  }
  for (std::size_t t = 0; t < count; ++t) {
    const auto j = static_cast<Eigen::Index>((first + t) % m), i = static_cast<Eigen::Index>(t);
    x[2 * j] = slice_x[2 * i];
    x[2 * j + 1] =
        slice_x[2 * i + 1] - (slice.Turn(t) - topology.Turn(static_cast<std::size_t>(j)));
  }
}

std::optional<std::size_t> Engine::DissolveRegion(Topology& topology, std::size_t border,
                                                  int direction) const {
  const auto geometric = [&](std::size_t l) {
    return GeometricBreak(topology.beams[l], topology.beams[l + 1]);
  };
  auto far = static_cast<long>(border) + direction;
  while (far >= 0 && far < static_cast<long>(topology.links.size()) &&
         topology.links[static_cast<std::size_t>(far)] == Link::kSameRegion) {
    far += direction;
  }
  if (far < 0 || far >= static_cast<long>(topology.links.size())) return std::nullopt;
  const auto other = static_cast<std::size_t>(far);
  if (geometric(border) || geometric(other)) return std::nullopt;
  topology.links[border] = Link::kSameRegion;
  topology.links[other] = Link::kSameRegion;
  return other;
}

void Engine::RefineBorders(Topology& topology, InnerResult& solution) {
  // Each border is judged on the points around it alone (a local problem of the two regions'
  // nearest points): cheap, and a merge that is infeasible locally is infeasible globally.
  const Topology before = topology;
  // Every trial starts from the greedy solution: its homotopy resumes a few stages before
  // where that one ended.
  InnerControl resume;
  resume.lambda_start = solution.lambda * kWarmLambdaBackoff;
  const auto local_solve = [&](const Topology& sub, const Topology& warm_topology,
                               const Eigen::VectorXd& warm_x, const InnerControl& control) {
    ++stats_.refinement_trials;
    return Solve(sub, &warm_topology, &warm_x, control);
  };
  // The greedy solution with the local solutions of changed borders pasted in: where the next
  // border's local problem and the final solve start (the greedy solution no longer fits the
  // points a moved border handed to the next region).
  Eigen::VectorXd pasted = solution.x;
  const std::size_t m = topology.beams.size();
  for (std::size_t l = 0; l < topology.links.size(); ++l) {
    if (topology.links[l] == Link::kSameRegion) continue;
    if (topology.links[l] == Link::kDifferentSurface &&
        GeometricBreak(topology.beams[l], topology.beams[topology.PointAfter(l)])) {
      continue;
    }
    const auto [first, count, at] = Around(topology, l);
    Topology local = Slice(topology, first, count);
    // The local problem's own minimum, so that its fit compares with those of the trials,
    // which reach theirs (at the final penalty weight, where it stays feasible).
    InnerControl settle;
    settle.lambda_start = solution.lambda;
    settle.settle = true;
    InnerResult current = local_solve(local, topology, pasted, settle);
    if (!current.feasible) continue;
    double cost = ComparableCost(current);
    // Merge back: a feasible stricter topology explains the scan with fewer regions. The
    // strictest is tried first: a wall split by a wrong different_surface link is one region.
    bool merged_back = false;
    for (int stricter = 0; stricter < static_cast<int>(local.links[at]) && !merged_back;
         ++stricter) {
      Topology merged = local;
      merged.links[at] = static_cast<Link>(stricter);
      InnerResult r = local_solve(merged, local, current.x, resume);
      if (r.feasible) {
        local = std::move(merged);
        current = std::move(r);
        merged_back = true;
      }
    }
    if (merged_back) {
      topology.links[l] = local.links[at];
      Paste(topology, local, first, current.x, pasted);
      continue;
    }
    // Move the border while the fit improves. A trial is abandoned as soon as its fit is
    // worse than the current one (the fit only worsens as the constraints tighten).
    InnerControl move = resume;
    move.abandon = [&](const Eigen::VectorXd& x) { return ComparableCost(x) >= cost; };
    // A one-beam move that fits worse is looked past once: two beams near a corner can each fit
    // the other wall only together (one alone lands on neither line).
    std::size_t border = at;
    bool dissolved = false;
    for (int direction : {-1, +1}) {
      for (int moves = 0; moves < kMaxBorderMoves && !dissolved; ++moves) {
        bool improved = false;
        for (int reach = 1; reach <= 2 && !improved; ++reach) {
          const long to = static_cast<long>(border) + direction * reach;
          Topology moved = local;
          if (!MoveBorder(moved.links, border, to)) break;
          // A move that would leave the region ahead below the minimum takes the whole of it:
          // both its borders become same_region (it and its neighbours become one region), and
          // the move ends there.
          std::optional<std::size_t> far;
          const auto [left, right] = RegionsBeside(moved.links, static_cast<std::size_t>(to));
          if (std::min(left, right) < MinRegionPoints()) {
            moved = local;
            far = DissolveRegion(moved, border, direction);
            if (!far) break;
          }
          // Fewer regions are kept when the prior allows them, as a merge back is.
          InnerResult r = local_solve(moved, local, current.x, far ? resume : move);
          const double moved_cost = r.feasible ? ComparableCost(r) : 0.0;
          if (!r.feasible && !r.abandoned)
            break;  // the move breaks the prior: so would a longer one
          if (!r.feasible || (!far && !(moved_cost < cost - 1e-9 * (1.0 + std::abs(cost))))) {
            continue;
          }
          local = std::move(moved);
          current = std::move(r);
          cost = moved_cost;
          border = far ? *far : static_cast<std::size_t>(to);
          dissolved = far.has_value();
          improved = true;
        }
        if (!improved) break;
      }
      if (border != at) break;  // moved one way: the other way leads back
    }
    for (std::size_t j = 0; j < local.links.size(); ++j)
      topology.links[first + j < m ? first + j : first + j - m] = local.links[j];
    if (border != at) Paste(topology, local, first, current.x, pasted);
    // On after the border's new place (a ring's border moved past the seam ends the pass).
    l = static_cast<std::size_t>(
        std::max(static_cast<long>(l), static_cast<long>(l + border) - static_cast<long>(at)));
  }
  if (topology.links == before.links) return;
  // Only the seams of the pasted pieces are off the constraints: resume at the final weight.
  InnerControl final_solve;
  final_solve.lambda_start = solution.lambda;
  InnerResult refined = Solve(topology, &topology, &pasted, final_solve);
  // Else from the greedy solution, resuming the homotopy earlier.
  if (!refined.feasible) refined = Solve(topology, &before, &solution.x, resume);
  if (refined.feasible) {
    solution = std::move(refined);
  } else {
    topology = before;  // the local decisions did not hold together: keep the greedy result
  }
}

CornerCheck Engine::CornerAt(const Topology& topology, const Eigen::VectorXd& x, std::size_t first,
                             std::size_t count, std::size_t at) const {
  const std::size_t m = topology.beams.size();
  std::vector<double> phi(count), rho(count), alpha(count);
  for (std::size_t j = 0; j < count; ++j) {
    // Past the seam of a ring, bearings and normals go on a turn later.
    const std::size_t p = first + j < m ? first + j : first + j - m;
    const double turn = p < first ? kTwoPi : 0.0;
    const auto k = static_cast<Eigen::Index>(2 * p);
    phi[j] = scan_.angles[topology.beams[p]] + topology.Turn(p) + turn;
    rho[j] = x[k];
    alpha[j] = x[k + 1] + turn;
  }
  return CheckCorner(phi, rho, alpha, at);
}

void Engine::UseProblemOf(const Topology& topology) {
  if (!problem_ || problem_->num_points() != topology.beams.size() ||
      problem_->links() != topology.links) {
    problem_ = std::make_unique<InnerProblem>(MakeProblem(topology));
  }
}

void Engine::SettleCorners(Topology& topology, InnerResult& solution) {
  for (int pass = 0; pass < kCornerPasses; ++pass) {
    Topology settled = topology;
    long moved_beams = 0;
    for (std::size_t l = 0; l < topology.links.size(); ++l) {
      if (topology.links[l] != Link::kDifferentRegion) continue;
      const auto [first, count, at] = Around(topology, l);
      const CornerCheck corner = CornerAt(topology, solution.x, first, count, at);
      if (corner.step ||
          (corner.turned && (!corner.corner || std::abs(corner.shift) > kMaxCornerShift))) {
        settled.links[l] = Link::kDifferentSurface;
        ++moved_beams;
        continue;
      }
      if (!corner.corner || corner.shift == 0) continue;
      if (MoveBorderKeepingRegions(settled.links, l, static_cast<long>(l) + corner.shift,
                                   MinRegionPoints(), topology.closed))
        moved_beams += std::abs(corner.shift);
    }
    if (settled.links == topology.links) return;
    UseProblemOf(topology);
    const double cost = ComparableCost(solution);
    // The lines hardly move: resume at the final weight (a few Newton steps), else earlier.
    InnerControl resume;
    resume.lambda_start = solution.lambda;
    ++stats_.refinement_trials;
    InnerResult r = Solve(settled, &topology, &solution.x, resume);
    if (!r.feasible) {
      resume.lambda_start = solution.lambda * kWarmLambdaBackoff;
      ++stats_.refinement_trials;
      r = Solve(settled, &topology, &solution.x, resume);
    }
    if (!r.feasible ||
        !(ComparableCost(r) <= cost + kCornerCostSlack * static_cast<double>(moved_beams))) {
      return;
    }
    topology = std::move(settled);
    solution = std::move(r);
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
  // A scan that covers a full turn closes into a ring: its last reading and its first are
  // neighbours (the seam is only where the scan's indices start).
  if (options_.close_full_turn && CoversFullTurn(scan_) &&
      topology.beams.size() >= MinRingPoints()) {
    topology.links.push_back(InitialLink(topology.beams.back(), topology.beams.front()));
    topology.closed = true;
  }
  // Points that cannot form a region are outliers from the start, and so are spikes.
  RemoveLonelyPoints(topology);
  // Again without the spikes found: a spike among another's neighbours waits for its removal.
  for (int pass = 0; pass < kSpikePasses; ++pass)
    if (!RemoveSpikes(topology)) break;

  InnerResult solution;
  Topology solved;
  bool have_solution = false;
  const Clock::time_point outer_start = Clock::now();
  for (int round = 0; round < options_.max_outer_rounds; ++round) {
    ++stats_.outer_rounds;
    InnerResult result =
        Solve(topology, have_solution ? &solved : nullptr, have_solution ? &solution.x : nullptr);
    solution = std::move(result);
    solved = topology;
    have_solution = true;
    // Where to break: the link penalties after the first stage (a wrong link stands out there
    // while the rest still fits) or at the end of the solve (a misplaced point stands out there
    // once the rest has been made to fit): the latter when the solve came near a solution or
    // they peak more clearly.
    std::vector<double> late;
    bool use_late = false;
    if (!solution.feasible) {
      late = problem_->LinkPenalties(solution.x);
      const std::vector<double>& early = solution.early_link_penalties;
      use_late = Sum(late) < kNearlyFeasible * Sum(early) ||
                 Prominence(late, topology) > Prominence(early, topology);
    }
    const std::vector<double>& penalties = use_late ? late : solution.early_link_penalties;
    if (solution.feasible || topology.beams.empty()) break;
    bool changed = BreakLinks(topology, penalties);
    changed = RemoveLonelyPoints(topology, &solved) || changed;
    if (!changed) RemoveWorstPoints(topology, penalties);
  }
  stats_.seconds_outer = Seconds(outer_start);
  if (solution.feasible && options_.refine_borders) {
    const Clock::time_point refine_start = Clock::now();
    RefineBorders(solved, solution);
    SettleCorners(solved, solution);
    stats_.seconds_refine = Seconds(refine_start);
  }
  // The problem of the final topology, for the objective.
  UseProblemOf(solved);

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
  out.closed = solved.closed;
  if (solved.closed) {
    out.closing_link = out.links.back();
    out.links.pop_back();
  }
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

bool CoversFullTurn(const Scan& scan) {
  const std::size_t n = scan.angles.size();
  if (scan.sonar || n < 3) return false;
  const double first = scan.angles.front(), last = scan.angles.back();
  if (!std::isfinite(first) || !std::isfinite(last) || !(last > first)) return false;
  const double step = (last - first) / static_cast<double>(n - 1);
  const double gap = first + kTwoPi - last;
  return std::abs(gap - step) <= kFullTurnStepTolerance * step;
}

MapScan EstimateMapScan(const Scan& scan, const dsl::CompiledPrior& prior,
                        const EngineOptions& options) {
  PRIORMAP_CHECK(prior.order() >= 1, "a prior of order >= 1");
  PRIORMAP_CHECK(options.beta > 0.0 && options.beta < 1.0, "beta in (0, 1)");
  PRIORMAP_CHECK(!scan.sonar, "a laser scan: a sonar ring's readings are cones, not rays");
  Engine engine(scan, prior, options);
  return engine.Run();
}

}  // namespace priormap::priorlets
