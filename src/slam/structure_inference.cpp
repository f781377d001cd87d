#include "structure_inference.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <numeric>
#include <tuple>
#include <unordered_map>

#include <priormap/core/segment.hpp>
#include <priormap/slam/structure_hierarchy.hpp>

namespace priormap::slam::detail {
namespace {

// Cells of the segment grid, and how far beyond its bounding box a segment is looked for: its
// endpoints may be several sigma off, and off-wall points lie a few metres out.
constexpr double kGridCell = 10.0;
constexpr double kGridPad = 8.0;

struct UnionFind {
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  std::size_t Find(std::size_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  }
  void Join(std::size_t a, std::size_t b) { parent[Find(a)] = Find(b); }
  std::vector<std::size_t> parent;
};

// theta and its 1x2 / 1x4 Jacobians by the point and by the segment's endpoints (a, b).
double Theta(const Vec2& p, const SegmentBelief& s, Row2* J_p, Eigen::RowVector4d* J_ab) {
  Row2 J_a, J_b;
  const double theta = SignedLineDistance(p, s.a, s.b, J_p, &J_a, &J_b);
  if (J_ab) *J_ab << J_a, J_b;
  return theta;
}

}  // namespace

void RelationBook::Apply(const Relation& relation) {
  applied.push_back(relation);
  for (int segment : relation.segments) applied_set_.emplace(relation.landmark, segment);
  // Which of a building's walls the point is on stays unknown, so none of them is known real.
  if (relation.building < 0) segments[relation.segments.front()].known_real = true;
}

SegmentBelief BeliefOf(const JointState& state, const PriorMap& map, int segment) {
  SegmentBelief belief;
  if (const auto offset = state.Offset(BlockKind::kSegment, segment)) {
    belief.offset = *offset;
    belief.a = state.mean().segment<2>(*offset);
    belief.b = state.mean().segment<2>(*offset + 2);
    belief.covariance = state.covariance().block<4, 4>(*offset, *offset);
  } else {
    const PriorSegment& s = map.segments[segment];
    belief.a = s.a;
    belief.b = s.b;
    belief.covariance = Mat4::Identity() * (s.std * s.std);
  }
  return belief;
}

StructureInference::StructureInference(const PriorMap& map, const SlamOptions& options)
    : map_(map), options_(options), grid_(map, kGridCell, kGridPad) {
  const PriorMapStructures structures = StructuresOf(map);
  for (std::size_t segment = 0; segment < map.segments.size(); ++segment) {
    buildings_of_segment_.push_back(structures.BuildingsOf(static_cast<int>(segment)));
  }
}

std::vector<StructureInference::Pair> StructureInference::Gate(const JointState& state,
                                                               const RelationBook& book) const {
  std::vector<Pair> pairs;
  const Eigen::MatrixXd& P = state.covariance();
  for (const StateBlock& block : state.blocks()) {
    if (block.kind != BlockKind::kLandmark) continue;
    const Vec2 p = state.mean().segment<2>(block.offset);
    const Mat2 Pp = P.block<2, 2>(block.offset, block.offset);
    for (int segment : grid_.Near(p)) {
      if (!book.Usable(segment) || book.IsApplied(block.id, segment)) continue;
      const SegmentBelief s = BeliefOf(state, map_, segment);
      const Vec2 d = s.b - s.a;
      const double length = d.norm();
      if (!(length > 0.0)) continue;
      // The point must project onto the segment, give or take its endpoints' uncertainty: the
      // infinite line would relate points on the neighbouring building of a straight street.
      const double end_sigma = std::sqrt(s.covariance.diagonal().maxCoeff());
      const double margin = options_.endpoint_margin_sigmas * end_sigma / length;
      const double t = (p - s.a).dot(d) / (length * length);
      if (t < -margin || t > 1.0 + margin) continue;
      Row2 J_p;
      Eigen::RowVector4d J_ab;
      const double theta = Theta(p, s, &J_p, &J_ab);
      double S = (J_p * Pp * J_p.transpose())(0, 0) +
                 (J_ab * s.covariance * J_ab.transpose())(0, 0) +
                 options_.wall_std * options_.wall_std;
      if (s.offset) {
        S += 2.0 * (J_p * P.block<2, 4>(block.offset, *s.offset) * J_ab.transpose())(0, 0);
      }
      if (theta * theta < options_.gate_chi2 * S) pairs.push_back({block.id, segment});
    }
  }
  return pairs;
}

HypothesisProblem StructureInference::Problem(const JointState& state,
                                              const std::vector<Pair>& pairs,
                                              const RelationBook& book) const {
  // The local variables: each landmark (2) and segment (4) of the cluster once.
  std::vector<std::pair<BlockKind, int>> variables;
  std::vector<int> local_offset;
  int dim = 0;
  auto local = [&](BlockKind kind, int id) {
    for (std::size_t i = 0; i < variables.size(); ++i) {
      if (variables[i] == std::make_pair(kind, id)) return local_offset[i];
    }
    variables.emplace_back(kind, id);
    local_offset.push_back(dim);
    dim += kind == BlockKind::kLandmark ? 2 : 4;
    return local_offset.back();
  };
  HypothesisProblem problem;
  const auto n = static_cast<Eigen::Index>(pairs.size());
  problem.theta.resize(n);
  std::vector<Eigen::RowVectorXd> rows;
  std::vector<std::pair<int, int>> row_offsets;  // (landmark local offset, segment local offset)
  for (const Pair& pair : pairs) {
    row_offsets.emplace_back(local(BlockKind::kLandmark, pair.landmark),
                             local(BlockKind::kSegment, pair.segment));
  }
  // Their joint covariance: from the state, and the prior for segments not in it (independent).
  std::vector<int> state_index;  // state index of each local entry, -1 for prior segments
  state_index.reserve(dim);
  for (const auto& [kind, id] : variables) {
    const auto offset = state.Offset(kind, id);
    const int size = kind == BlockKind::kLandmark ? 2 : 4;
    for (int k = 0; k < size; ++k) state_index.push_back(offset ? *offset + k : -1);
  }
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(dim, dim);
  for (int i = 0; i < dim; ++i) {
    for (int j = 0; j < dim; ++j) {
      if (state_index[i] >= 0 && state_index[j] >= 0) {
        C(i, j) = state.covariance()(state_index[i], state_index[j]);
      }
    }
  }
  for (std::size_t v = 0; v < variables.size(); ++v) {
    const auto& [kind, id] = variables[v];
    if (kind == BlockKind::kSegment && !state.Contains(kind, id)) {
      const double var = map_.segments[id].std * map_.segments[id].std;
      C.block<4, 4>(local_offset[v], local_offset[v]) = Mat4::Identity() * var;
    }
  }
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(n, dim);
  for (Eigen::Index j = 0; j < n; ++j) {
    const Pair& pair = pairs[j];
    const Vec2 p = state.mean().segment<2>(*state.Offset(BlockKind::kLandmark, pair.landmark));
    const SegmentBelief s = BeliefOf(state, map_, pair.segment);
    Row2 J_p;
    Eigen::RowVector4d J_ab;
    problem.theta[j] = Theta(p, s, &J_p, &J_ab);
    J.block<1, 2>(j, row_offsets[j].first) = J_p;
    J.block<1, 4>(j, row_offsets[j].second) = J_ab;
    problem.pairs.push_back(
        {pair.landmark, pair.segment,
         options_.building_relations ? buildings_of_segment_[pair.segment] : std::vector<int>{}});
    if (book.segments[pair.segment].known_real) problem.lines_known_real.push_back(pair.segment);
  }
  problem.S = J * C * J.transpose();
  problem.S.diagonal().array() += options_.wall_std * options_.wall_std;
  problem.S = 0.5 * (problem.S + problem.S.transpose()).eval();
  if (options_.null_density == NullDensity::kUniformOverGate) {
    for (Eigen::Index j = 0; j < n; ++j) {
      problem.null_density.push_back(0.5 / std::sqrt(options_.gate_chi2 * problem.S(j, j)));
    }
  }
  return problem;
}

void StructureInference::AcceptBuildingRelations(const std::vector<Pair>& members,
                                                 const HypothesisPosterior& posterior,
                                                 std::vector<Relation>& accepted) const {
  // Most probable first, so a point above p_accept for two buildings (p_accept < 0.5, or through
  // a wall they share) takes the likelier one.
  std::vector<const StructureMarginal*> candidates;
  for (const StructureMarginal& marginal : posterior.structure_marginals) {
    if (marginal.probability > options_.priors.p_accept) candidates.push_back(&marginal);
  }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const StructureMarginal* a, const StructureMarginal* b) {
                     return a->probability > b->probability;
                   });
  std::vector<int> decided;  // landmarks whose likeliest buildings have been looked at
  for (std::size_t k = 0; k < candidates.size(); ++k) {
    const StructureMarginal& best = *candidates[k];
    const int landmark = best.point;
    const auto is_landmark = [&](int other) { return other == landmark; };
    if (std::any_of(decided.begin(), decided.end(), is_landmark) ||
        std::any_of(accepted.begin(), accepted.end(),
                    [&](const Relation& r) { return r.landmark == landmark; })) {
      continue;
    }
    decided.push_back(landmark);
    // An exact tie is symmetric in the buildings, and so is its outcome. With the same candidate
    // walls (walls the tied buildings all share) the relation is one mixture, to all of them;
    // with different walls the data do not say which building, and the point waits.
    std::vector<int> tied{best.structure};
    bool same_walls = true;
    for (std::size_t m = k + 1; m < candidates.size(); ++m) {
      const StructureMarginal& other = *candidates[m];
      if (other.point != landmark || other.probability != best.probability) continue;
      tied.push_back(other.structure);
      same_walls = same_walls && other.pairs == best.pairs;
    }
    if (!same_walls) continue;
    std::sort(tied.begin(), tied.end());
    Relation relation{.landmark = landmark,
                      .segments = {},
                      .building = tied.front(),
                      .weights = best.weights,
                      .buildings = tied};
    for (int j : best.pairs) relation.segments.push_back(members[j].segment);
    accepted.push_back(std::move(relation));
  }
}

std::vector<Relation> StructureInference::Infer(const JointState& state, const RelationBook& book,
                                                InferenceStats& stats) const {
  std::vector<Pair> pairs = Gate(state, book);
  std::vector<Relation> accepted;
  if (pairs.empty()) return accepted;

  // Nodes: landmarks then segments, numbered locally; clusters are connected components.
  std::unordered_map<int, std::size_t> landmark_node, segment_node;
  for (const Pair& p : pairs) {
    landmark_node.try_emplace(p.landmark, landmark_node.size());
  }
  for (const Pair& p : pairs) {
    segment_node.try_emplace(p.segment, landmark_node.size() + segment_node.size());
  }
  std::vector<bool> dropped_landmark(landmark_node.size(), false);
  // Above kMaxEnumeratedPairs the enumeration refuses the cluster (2^pairs leaves).
  const auto cap =
      static_cast<std::size_t>(std::clamp(options_.max_cluster_pairs, 1, kMaxEnumeratedPairs));

  for (;;) {
    UnionFind uf(landmark_node.size() + segment_node.size());
    for (const Pair& p : pairs) {
      if (!dropped_landmark[landmark_node[p.landmark]]) {
        uf.Join(landmark_node[p.landmark], segment_node[p.segment]);
      }
    }
    std::unordered_map<std::size_t, std::vector<Pair>> clusters;
    for (const Pair& p : pairs) {
      if (!dropped_landmark[landmark_node[p.landmark]]) {
        clusters[uf.Find(landmark_node[p.landmark])].push_back(p);
      }
    }
    // A cluster above the cap drops its least certain landmark (largest position variance) and
    // the clustering is redone: those points are marginalised out this frame (the paper's
    // "removed from all D") and decided once their neighbours are.
    bool changed = false;
    for (auto& [root, members] : clusters) {
      stats.largest_cluster = std::max(stats.largest_cluster, members.size());
      if (members.size() <= cap) continue;
      int worst = -1;
      double worst_variance = -1.0;
      for (const Pair& p : members) {
        const int offset = *state.Offset(BlockKind::kLandmark, p.landmark);
        const double variance = state.covariance().block<2, 2>(offset, offset).trace();
        if (variance > worst_variance) {
          worst_variance = variance;
          worst = p.landmark;
        }
      }
      dropped_landmark[landmark_node[worst]] = true;
      ++stats.deferred_points;
      changed = true;
    }
    if (changed) continue;
    for (auto& [root, members] : clusters) {
      // Enumerate in a fixed order, so results do not depend on hash-map iteration.
      std::sort(members.begin(), members.end(), [](const Pair& x, const Pair& y) {
        return std::tie(x.landmark, x.segment) < std::tie(y.landmark, y.segment);
      });
      const HypothesisProblem problem = Problem(state, members, book);
      const HypothesisPosterior posterior = EnumerateHypotheses(problem, options_.priors);
      ++stats.clusters;
      stats.hypotheses += posterior.num_hypotheses;
      std::vector<Relation> cluster_accepted;
      for (std::size_t j = 0; j < members.size(); ++j) {
        const bool take =
            posterior.map_probability > options_.priors.p_accept
                ? static_cast<bool>(posterior.map[j])
                : options_.accept_marginals && posterior.marginals[j] > options_.priors.p_accept;
        if (take) cluster_accepted.push_back({members[j].landmark, {members[j].segment}, -1, {}});
      }
      AcceptBuildingRelations(members, posterior, cluster_accepted);
      accepted.insert(accepted.end(), std::make_move_iterator(cluster_accepted.begin()),
                      std::make_move_iterator(cluster_accepted.end()));
    }
    break;
  }
  // Single-segment relations first (one update), each kind in (landmark, segments) order: not
  // by building, whose index is the map's order, as the mixtures are applied one by one.
  std::sort(accepted.begin(), accepted.end(), [](const Relation& a, const Relation& b) {
    const bool a_up = a.building >= 0, b_up = b.building >= 0;
    return std::tie(a_up, a.landmark, a.segments) < std::tie(b_up, b.landmark, b.segments);
  });
  return accepted;
}

}  // namespace priormap::slam::detail
