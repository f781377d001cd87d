#pragma once
// Sec. V-A per frame: gate (landmark, segment) pairs, group them into independent clusters, cap
// the clusters, enumerate each one's hypotheses and decide which relations to accept.

#include <set>
#include <utility>
#include <vector>

#include <priormap/slam/joint_state.hpp>
#include <priormap/slam/prior_map_slam.hpp>

#include "segment_grid.hpp"

namespace priormap::slam::detail {

/// A relation to apply or applied: landmark i lies on segment n (one segment), or on some segment
/// of a building (a relation known one level up the hierarchy: eq. 3, a mixture over the
/// building's candidate segments with weights p(d_s = 1 | d_S = 1)).
struct Relation {
  int landmark = -1;  // state id
  std::vector<int> segments;
  int building = -1;            // -1: a relation to segments[0] alone; else buildings.front()
  std::vector<double> weights;  // building level: the mixture's prior weights
  // Building level: every building it is a relation to, ascending. Several when buildings tie
  // with the same candidate walls (walls they all share): the mixture is then one and the same,
  // and naming the first alone would let the map's order of buildings decide.
  std::vector<int> buildings{};
};

/// What the filter remembers about relations and segments.
struct RelationBook {
  struct SegmentStatus {
    bool known_real = false;   // has accepted relations: p(d_n = 1) = 1
    bool quarantined = false;  // an applied relation became implausible
    bool retired = false;      // left the state; never used again
  };
  std::vector<SegmentStatus> segments;  // per prior segment
  std::vector<Relation> applied;        // in the order applied
  void Apply(const Relation& relation);
  // Whether the pair is part of an applied relation: a point related to some wall of a building
  // is not related to one of those walls again (the mixture already spent that information).
  // Asked for every gated pair of every frame: a set, not a scan of `applied`.
  [[nodiscard]] bool IsApplied(int landmark, int segment) const {
    return applied_set_.contains({landmark, segment});
  }
  [[nodiscard]] bool Usable(int segment) const {
    return !segments[segment].quarantined && !segments[segment].retired;
  }

 private:
  std::set<std::pair<int, int>> applied_set_;
};

/// A segment's current estimate: from the state when it is there, else from the prior map.
struct SegmentBelief {
  Vec2 a = Vec2::Zero(), b = Vec2::Zero();
  Mat4 covariance = Mat4::Zero();
  std::optional<int> offset;  // in the state
};
[[nodiscard]] SegmentBelief BeliefOf(const JointState& state, const PriorMap& map, int segment);

class StructureInference {
 public:
  StructureInference(const PriorMap& map, const SlamOptions& options);

  /// The relations to apply now: to single segments, then to buildings.
  [[nodiscard]] std::vector<Relation> Infer(const JointState& state, const RelationBook& book,
                                            InferenceStats& stats) const;

 private:
  struct Pair {
    int landmark;  // state id
    int segment;
  };
  // The building-level relations of a cluster: points not related to a single segment whose
  // probability of lying on some wall of one building exceeds p_accept. Decided the same
  // whatever the order of the buildings: exact ties are not broken by index.
  void AcceptBuildingRelations(const std::vector<Pair>& members,
                               const HypothesisPosterior& posterior,
                               std::vector<Relation>& accepted) const;
  [[nodiscard]] std::vector<Pair> Gate(const JointState& state, const RelationBook& book) const;
  [[nodiscard]] HypothesisProblem Problem(const JointState& state, const std::vector<Pair>& pairs,
                                          const RelationBook& book) const;

  const PriorMap& map_;
  const SlamOptions& options_;
  SegmentGrid grid_;
  // From the map's structure hierarchy: all of a shared wall's buildings, so that it counts for
  // each of them, not only for the one the map happens to list first.
  std::vector<std::vector<int>> buildings_of_segment_;
};

}  // namespace priormap::slam::detail
