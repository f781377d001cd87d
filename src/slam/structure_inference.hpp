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

/// What the filter remembers about relations and segments.
struct RelationBook {
  struct SegmentStatus {
    bool known_real = false;   // has accepted relations: p(d_n = 1) = 1
    bool quarantined = false;  // an applied relation became implausible
    bool retired = false;      // left the state; never used again
  };
  std::vector<SegmentStatus> segments;       // per prior segment
  std::vector<std::pair<int, int>> applied;  // (state landmark id, segment), in order applied
  void Apply(int landmark, int segment);
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

  /// The (state landmark id, segment) relations to apply now.
  [[nodiscard]] std::vector<std::pair<int, int>> Infer(const JointState& state,
                                                       const RelationBook& book,
                                                       InferenceStats& stats) const;

 private:
  struct Pair {
    int landmark;  // state id
    int segment;
  };
  [[nodiscard]] std::vector<Pair> Gate(const JointState& state, const RelationBook& book) const;
  [[nodiscard]] HypothesisProblem Problem(const JointState& state, const std::vector<Pair>& pairs,
                                          const RelationBook& book) const;

  const PriorMap& map_;
  const SlamOptions& options_;
  SegmentGrid grid_;
};

}  // namespace priormap::slam::detail
