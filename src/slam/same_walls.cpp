#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>

#include <Eigen/Eigenvalues>

#include <priormap/slam/same_walls.hpp>

namespace priormap::slam {
namespace {

// d^T C^-1 d for the perpendicular distances of `points`' endpoints from `line`'s line (the
// header's test, one direction).
double EndpointsOffLine(const PriorSegment& line, const PriorSegment& points) {
  const Vec2 d = line.b - line.a;
  const double length2 = d.squaredNorm();
  const Vec2 normal = Vec2(-d.y(), d.x()) / std::sqrt(length2);
  const Vec2 off(normal.dot(points.a - line.a), normal.dot(points.b - line.a));
  const Vec2 t((points.a - line.a).dot(d) / length2, (points.b - line.a).dot(d) / length2);
  const double line_var = line.std * line.std;
  const double point_var = points.std * points.std;
  Mat2 C;
  C(0, 0) = point_var + line_var * ((1 - t[0]) * (1 - t[0]) + t[0] * t[0]);
  C(1, 1) = point_var + line_var * ((1 - t[1]) * (1 - t[1]) + t[1] * t[1]);
  C(0, 1) = C(1, 0) = line_var * ((1 - t[0]) * (1 - t[1]) + t[0] * t[1]);
  return off.dot(C.ldlt().solve(off));
}

// The length along the longer segment's line that both cover, over the shorter one's length.
double OverlapFraction(const PriorSegment& a, const PriorSegment& b) {
  const double la = (a.b - a.a).norm(), lb = (b.b - b.a).norm();
  const PriorSegment& longer = la >= lb ? a : b;
  const PriorSegment& shorter = la >= lb ? b : a;
  const Vec2 u = (longer.b - longer.a) / std::max(la, lb);
  const double s0 = u.dot(shorter.a - longer.a), s1 = u.dot(shorter.b - longer.a);
  const double overlap =
      std::min(std::max(la, lb), std::max(s0, s1)) - std::max(0.0, std::min(s0, s1));
  return overlap / std::min(la, lb);
}

// The turn from the line of `a` to the line of `b`, in (-pi / 2, pi / 2]: lines have no direction.
double LineTurn(const PriorSegment& a, const PriorSegment& b) {
  const Vec2 u = (a.b - a.a).normalized(), v = (b.b - b.a).normalized();
  const double angle = std::atan2(u.x() * v.y() - u.y() * v.x(), u.dot(v));
  if (angle > std::numbers::pi / 2) return angle - std::numbers::pi;
  if (angle <= -std::numbers::pi / 2) return angle + std::numbers::pi;
  return angle;
}

constexpr double kMaxContinuedTurn = kMaxContinuedTurnDeg * std::numbers::pi / 180.0;

// Whether every segment of `group` runs within kMaxContinuedTurnDeg of every other: the spread of
// their lines' turns from the first one's.
bool StraightWithinTurn(const PriorMap& map, const std::vector<int>& group) {
  const PriorSegment& first = map.segments[group.front()];
  double lo = 0.0, hi = 0.0;
  for (int s : group) {
    const double turn = LineTurn(first, map.segments[s]);
    lo = std::min(lo, turn);
    hi = std::max(hi, turn);
  }
  return hi - lo <= kMaxContinuedTurn;
}

struct UnionFind {
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  std::size_t Find(std::size_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  }
  void Join(std::size_t a, std::size_t b) {
    a = Find(a);
    b = Find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);  // the smallest index is the root
  }
  std::vector<std::size_t> parent;
};

// The buildings of `group`'s segments other than its first segment's, ascending, each once.
std::vector<int> SharedWith(const PriorMap& map, const std::vector<int>& group) {
  const int own = map.segments[group.front()].building;
  std::vector<int> others;
  for (int s : group) {
    const PriorSegment& segment = map.segments[s];
    if (segment.building >= 0) others.push_back(segment.building);
    others.insert(others.end(), segment.shared_with.begin(), segment.shared_with.end());
  }
  std::erase(others, own);
  std::sort(others.begin(), others.end());
  others.erase(std::unique(others.begin(), others.end()), others.end());
  return others;
}

// One wall for the segments `group` (ascending) of `map`: the header's fit.
PriorSegment MergedWall(const PriorMap& map, const std::vector<int>& group) {
  const PriorSegment& first = map.segments[group.front()];
  if (group.size() == 1) return first;
  Vec2 centroid = Vec2::Zero();
  double total = 0.0, largest_var = 0.0;
  for (int s : group) {
    const PriorSegment& segment = map.segments[s];
    const double w = 1.0 / (segment.std * segment.std);
    centroid += w * (segment.a + segment.b);
    total += 2.0 * w;
    largest_var = std::max(largest_var, segment.std * segment.std);
  }
  centroid /= total;
  Mat2 scatter = Mat2::Zero();
  for (int s : group) {
    const PriorSegment& segment = map.segments[s];
    const double w = 1.0 / (segment.std * segment.std);
    for (const Vec2& p : {segment.a, segment.b})
      scatter += w * (p - centroid) * (p - centroid).transpose();
  }
  Vec2 u = Eigen::SelfAdjointEigenSolver<Mat2>(scatter).eigenvectors().col(1);
  if (u.dot(first.b - first.a) < 0.0) u = -u;  // the first segment's direction
  const Vec2 normal(-u.y(), u.x());
  double lo = std::numeric_limits<double>::infinity(), hi = -lo, off = 0.0;
  for (int s : group) {
    for (const Vec2& p : {map.segments[s].a, map.segments[s].b}) {
      lo = std::min(lo, u.dot(p - centroid));
      hi = std::max(hi, u.dot(p - centroid));
      off = std::max(off, std::abs(normal.dot(p - centroid)));
    }
  }
  // The wall stays part of every building whose footprint holds it: a landmark on a shared wall
  // is evidence about each of them, whichever the map lists first.
  return {centroid + lo * u, centroid + hi * u, std::sqrt(largest_var + off * off), first.building,
          SharedWith(map, group)};
}

}  // namespace

bool ContinuesWall(const PriorSegment& a, const PriorSegment& b, double gate_chi2) {
  if (!((a.b - a.a).squaredNorm() > 0.0) || !((b.b - b.a).squaredNorm() > 0.0)) return false;
  if (a.building != b.building || a.shared_with != b.shared_with) return false;
  const bool vertex = a.b == b.a || a.a == b.b || a.a == b.a || a.b == b.b;
  return vertex && std::abs(LineTurn(a, b)) <= kMaxContinuedTurn &&
         EndpointsOffLine(a, b) <= gate_chi2 && EndpointsOffLine(b, a) <= gate_chi2;
}

bool IsSameWall(const PriorSegment& a, const PriorSegment& b, double gate_chi2) {
  if (!((a.b - a.a).squaredNorm() > 0.0) || !((b.b - b.a).squaredNorm() > 0.0)) return false;
  return OverlapFraction(a, b) >= 0.5 && EndpointsOffLine(a, b) <= gate_chi2 &&
         EndpointsOffLine(b, a) <= gate_chi2;
}

SameWalls MergeSameWalls(const PriorMap& map, double gate_chi2) {
  const std::size_t n = map.segments.size();
  // Candidates: segments whose boxes, grown by 3 std, meet; sweep along x.
  struct Box {
    double x0, x1, y0, y1;
    int segment;
  };
  std::vector<Box> boxes;
  boxes.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const PriorSegment& s = map.segments[i];
    const double pad = 3.0 * s.std;
    boxes.push_back({std::min(s.a.x(), s.b.x()) - pad, std::max(s.a.x(), s.b.x()) + pad,
                     std::min(s.a.y(), s.b.y()) - pad, std::max(s.a.y(), s.b.y()) + pad,
                     static_cast<int>(i)});
  }
  std::sort(boxes.begin(), boxes.end(), [](const Box& p, const Box& q) { return p.x0 < q.x0; });
  // Copies alone, and copies with the parts of split walls: a group that the parts joined is kept
  // only while it stays straight (ContinuesWall), else its segments are grouped as copies alone.
  UnionFind copies(n), with_parts(n);
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    for (std::size_t j = i + 1; j < boxes.size() && boxes[j].x0 <= boxes[i].x1; ++j) {
      if (boxes[j].y0 > boxes[i].y1 || boxes[i].y0 > boxes[j].y1) continue;
      const int a = boxes[i].segment, b = boxes[j].segment;
      const PriorSegment &sa = map.segments[a], &sb = map.segments[b];
      if (IsSameWall(sa, sb, gate_chi2)) {
        copies.Join(a, b);
        with_parts.Join(a, b);
      } else if (ContinuesWall(sa, sb, gate_chi2)) {
        with_parts.Join(a, b);
      }
    }
  }
  std::vector<std::vector<int>> joined(n);
  for (std::size_t i = 0; i < n; ++i) joined[with_parts.Find(i)].push_back(static_cast<int>(i));
  std::vector<char> keep_parts(n, 0);
  for (std::size_t root = 0; root < n; ++root) {
    const std::vector<int>& group = joined[root];
    const bool parts_joined = std::any_of(group.begin(), group.end(), [&](int s) {
      return copies.Find(static_cast<std::size_t>(s)) != copies.Find(root);
    });
    keep_parts[root] = !parts_joined || StraightWithinTurn(map, group);
  }
  // Roots of the two partitions apart: a copies' root is offset by n.
  const auto root_of = [&](std::size_t i) {
    const std::size_t root = with_parts.Find(i);
    return keep_parts[root] ? root : n + copies.Find(i);
  };
  SameWalls out;
  out.map.buildings = map.buildings;
  std::vector<int> wall_of_root(2 * n, -1);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t root = root_of(i);
    if (wall_of_root[root] < 0) {
      wall_of_root[root] = static_cast<int>(out.members.size());
      out.members.emplace_back();
    }
    out.members[wall_of_root[root]].push_back(static_cast<int>(i));
  }
  for (const std::vector<int>& group : out.members)
    out.map.segments.push_back(MergedWall(map, group));
  return out;
}

}  // namespace priormap::slam
