#pragma once
/// EKF-SLAM of point landmarks with a heterogeneous prior map (Parsley & Julier): a
/// full-covariance EKF over the vehicle pose and landmarks (steered bicycle or odometry
/// increments; range-bearing observations; association by known ids or by individually
/// compatible nearest neighbour; a sliding window that drops landmarks unseen for W seconds),
/// joined with the prior map's wall segments once relations couple them. Each frame it infers
/// which landmarks lie on which segments (association_hypotheses.hpp) and applies the accepted
/// relations 0 = theta(point, segment) as pseudo-observations of the joint state.
///
/// Beyond the paper: accepted relations are re-checked every frame. An EKF cannot take an update
/// back, so a relation whose innovation becomes implausible (normalised innovation squared above
/// `recheck_chi2` on `recheck_frames` consecutive frames) is reported (`RelationRecord::flagged`)
/// and its segment quarantined: no new relation is accepted to it.
///
/// A segment leaves the state when the window has dropped every landmark related to it, and is
/// retired: re-inserting it later with its prior (or its last marginal without the correlations
/// it had with the pose) would count its information twice, so it is not used again.

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <vector>

#include <priormap/slam/association_hypotheses.hpp>
#include <priormap/slam/joint_state.hpp>
#include <priormap/slam/prior_map.hpp>
#include <priormap/slam/same_walls.hpp>
#include <priormap/slam/slam_input.hpp>

namespace priormap::slam {

enum class AssociationMode {
  kKnownIds,         ///< observations carry landmark ids (the paper's simulation)
  kNearestNeighbour  ///< individual compatibility: nearest landmark by Mahalanobis distance
};

/// p(theta | d = 0), the likelihood of a pair that is not related.
enum class NullDensity {
  kConstant,        ///< StructurePriors::unrelated_density (the paper: 1 per metre)
  kUniformOverGate  ///< uniform over the gate, 1 / (2 sqrt(gate_chi2 S)): free of units
};

struct SlamOptions {
  bool use_prior_map = true;
  double window_s = 6.0;    ///< drop landmarks not seen for this long; <= 0 keeps them all
  double max_range = 30.0;  ///< only for nearest-neighbour candidates: landmarks this near

  /// Consistency of the EKF itself (docs/slam-prior-map.md, "A consistent filter first"):
  /// Jacobians at the first estimates (FEJ-EKF, Huang, Mourikis & Roumeliotis 2010): a landmark's
  /// measurement Jacobian at its initial position, the motion Jacobian's heading column from the
  /// pose predicted before the last update, so the filter gains no information about its global
  /// position and heading, which landmarks alone cannot observe.
  bool first_estimates_jacobians = true;
  /// The second-order terms of the range (RangeSecondOrder) in updates and initialisation.
  bool second_order_range = true;

  AssociationMode association = AssociationMode::kKnownIds;
  double nn_gate_chi2 = 9.21;          ///< accept an association below this (chi2, 2 dof, 99 %)
  double nn_new_landmark_chi2 = 18.4;  ///< a new landmark only above this from every landmark

  /// The paper's priors (0.89, 0.6). Acceptance and the null density are ours: the paper's
  /// p_accept = 0.7 is "optimistic ... because of the inconsistency of regular EKF-SLAM", and
  /// p(theta | d = 0) = 1 per metre is a unit-dependent choice; with a consistent filter, these
  /// make the study's relations both frequent and right (docs/slam-prior-map.md).
  StructurePriors priors{.p_line_real = 0.89,
                         .p_point_on_line = 0.6,
                         .p_accept = 0.99,
                         .unrelated_density = 0.05,
                         .one_line_per_point = true};
  NullDensity null_density = NullDensity::kConstant;
  double wall_std = 0.05;    ///< p(theta | d = 1) = N(0, wall_std^2): walls are not flat, m
  double gate_chi2 = 10.83;  ///< relation gate on theta^2 / S (chi2, 1 dof, 99.9 %)
  double endpoint_margin_sigmas = 3.0;  ///< the point's projection may pass an end by this
  /// Larger clusters drop their least certain points. Enumeration takes at most
  /// kMaxEnumeratedPairs pairs: a larger value acts as that one.
  int max_cluster_pairs = 8;
  bool accept_marginals = true;  ///< below p_accept for D_MAP, accept pairs with P(D_j) > p_accept
  /// One level up the hierarchy: a point gated with several walls of one building (at a corner),
  /// above p_accept for "some wall of this building" but for no single wall, is related to the
  /// building: the eq. (3) mixture over those walls, applied by moment matching
  /// (JointState::UpdateMixture). Off by default: in the study, collapsing the two-wall mixture
  /// to one Gaussian costs consistency (docs/slam-prior-map.md, "Relations to buildings").
  bool building_relations = false;
  double recheck_chi2 = 10.83;  ///< flag an applied relation above this ...
  int recheck_frames = 3;       ///< ... on this many consecutive frames
  /// Prior segments that are the same wall (collinear and overlapping within their std, as a wall
  /// two footprints share) are merged into one wall before filtering (same_walls.hpp). Without
  /// it, a point on such a wall splits its probability between the copies under
  /// `one_line_per_point` and is never related to the wall.
  bool merge_same_walls = true;
  double same_wall_chi2 = kSameWallChi2;  ///< the merge's gate (same_walls.hpp)
};

/// What the filter knows about the world's truth, to score relations (simulation only).
struct RelationTruth {
  std::vector<int> landmark_wall;      ///< per landmark id: the wall it is on or next to
  std::vector<bool> landmark_on_wall;  ///< per landmark id
  std::vector<int> segment_wall;       ///< per prior segment: its true wall, -1 if spurious

  [[nodiscard]] bool Correct(int landmark, int segment) const;
  [[nodiscard]] bool Spurious(int segment) const;
};

struct RelationRecord {
  int landmark = -1;
  /// The prior segment (building level: the wall with the largest posterior weight); a wall of
  /// several segments (SlamResult::same_walls) is named by its first.
  int segment = -1;
  double time = 0.0;     ///< when it was applied
  bool flagged = false;  ///< its innovation became implausible
  double flagged_time = 0.0;
  std::optional<bool> correct;    ///< with RelationTruth (building level: on one of `walls`)
  bool spurious_segment = false;  ///< with RelationTruth
  int building = -1;       ///< a relation to some wall of this building (eq. 3); -1: to `segment`
  std::vector<int> walls;  ///< building level: the candidate segments
  /// Building level: every building it relates the landmark to, ascending; `building` is the
  /// first. Several when buildings tie exactly with the same candidate walls (walls they share):
  /// the relation is to each, not to the one the map happens to list first.
  std::vector<int> buildings{};
};

struct FrameRecord {
  double time = 0.0;
  Se2 estimate;
  Mat3 covariance = Mat3::Zero();
  int landmarks = 0;  ///< in the state after the frame
  int segments = 0;
  // Relations applied to landmarks that are in the state after the frame (paper Fig. 5).
  int relations_in_state = 0;
  int relations_correct = 0;
  int relations_incorrect = 0;
  int relations_spurious = 0;
  int accepted = 0;  ///< relations accepted in this frame
};

struct InferenceStats {
  std::size_t clusters = 0;         ///< enumerated
  std::size_t deferred_points = 0;  ///< points left out of over-large clusters (decided later)
  std::size_t largest_cluster = 0;  ///< most gated pairs seen in one cluster (before capping)
  std::size_t hypotheses = 0;       ///< enumerated in all
};

struct LandmarkEstimate {
  int id = -1;
  Vec2 position = Vec2::Zero();
  Mat2 covariance = Mat2::Zero();
};

/// A landmark of the whole map the filter built: the sliding window drops landmarks from the
/// state, not from the map.
struct MappedLandmark {
  LandmarkEstimate estimate;  ///< after the last frame that ended with it in the state
  double last_time = 0.0;     ///< that frame's time, s
  bool in_state = false;      ///< still in the state at the end (`estimate` is in `landmarks`)
};

struct SegmentEstimate {
  int segment = -1;
  Vec2 a = Vec2::Zero(), b = Vec2::Zero();
  Mat4 covariance = Mat4::Zero();
};

/// Thrown by PriorMapSlam (and RunSlam) when the filter's pose stops being finite, or leaves the
/// world's bound (kMaxWorldCoordinate in x or y), saying after which step or frame.
class SlamDiverged : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct SlamResult {
  std::vector<FrameRecord> frames;
  std::vector<RelationRecord> relations;
  std::vector<LandmarkEstimate> landmarks;  ///< in the state at the end
  /// Every landmark id the filter created, ascending, at its last estimate: the map to score
  /// against the truth. With known ids, a landmark the window dropped and then saw again is
  /// created anew (see `landmarks_created`) but mapped once, at its latest estimate.
  std::vector<MappedLandmark> all_landmarks;
  std::vector<SegmentEstimate> segments;  ///< in the state at the end
  InferenceStats inference;
  /// Updates refused (innovation covariance not positive definite, or not finite), and single
  /// observations left out of their frame's update because their landmark's estimate lies at the
  /// sensor, where the range-bearing model has no Jacobian.
  std::size_t rejected_updates = 0;
  std::size_t building_relations = 0;  ///< of `relations`, those to some wall of a building
  std::size_t landmarks_created = 0;
  /// The groups of two or more prior segments filtered as one wall (SlamOptions::
  /// merge_same_walls), each ascending; relations and `segments` name such a wall by its first.
  std::vector<std::vector<int>> same_walls;
};

class PriorMapSlam {
 public:
  /// `prior_map` and `truth` (both optional) must outlive the filter.
  PriorMapSlam(const Se2& initial_pose, double start_time, const MotionNoise& motion_noise,
               const SensorNoise& sensor_noise, const PriorMap* prior_map, SlamOptions options,
               const RelationTruth* truth = nullptr);
  ~PriorMapSlam();
  PriorMapSlam(PriorMapSlam&&) noexcept;
  PriorMapSlam& operator=(PriorMapSlam&&) noexcept;

  void Predict(const MotionStep& step);
  /// Updates with a frame's observations, then (with a prior map) re-checks, infers and applies
  /// relations, then slides the window. Returns the frame's record.
  FrameRecord Observe(const ObservationFrame& frame);

  [[nodiscard]] const JointState& state() const;
  [[nodiscard]] SlamResult Finish() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The whole input: motion steps and frames merged by time (a frame is processed after every
/// step that ends no later than it; bicycle steps that straddle a frame are split there).
[[nodiscard]] SlamResult RunSlam(const SlamInput& input, const PriorMap* prior_map,
                                 const SlamOptions& options, const RelationTruth* truth = nullptr);

}  // namespace priormap::slam
