#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <span>
#include <unordered_map>

#include <fmt/format.h>

#include <priormap/core/angles.hpp>
#include <priormap/core/check.hpp>
#include <priormap/core/segment.hpp>
#include <priormap/core/world_bounds.hpp>
#include <priormap/slam/prior_map_slam.hpp>
#include <priormap/slam/pseudo_observation.hpp>
#include <priormap/slam/range_bearing.hpp>
#include <priormap/slam/vehicle_model.hpp>

#include "structure_inference.hpp"

namespace priormap::slam {

bool RelationTruth::Correct(int landmark, int segment) const {
  if (landmark < 0 || segment < 0 || static_cast<std::size_t>(landmark) >= landmark_wall.size() ||
      static_cast<std::size_t>(segment) >= segment_wall.size()) {
    return false;
  }
  return landmark_on_wall[landmark] && segment_wall[segment] >= 0 &&
         segment_wall[segment] == landmark_wall[landmark];
}

bool RelationTruth::Spurious(int segment) const {
  return segment >= 0 && static_cast<std::size_t>(segment) < segment_wall.size() &&
         segment_wall[segment] < 0;
}

struct PriorMapSlam::Impl {
  Impl(const Se2& initial_pose, double start_time, const MotionNoise& motion_noise_,
       const SensorNoise& sensor_noise_, const PriorMap* prior_map_, SlamOptions options_,
       const RelationTruth* truth_)
      : state(initial_pose, Mat3::Zero()),
        time(start_time),
        motion_noise(motion_noise_),
        sensor_noise(sensor_noise_),
        prior_map(prior_map_ && options_.use_prior_map && !prior_map_->empty() ? prior_map_
                                                                               : nullptr),
        options(std::move(options_)),
        truth(truth_) {
    // Checked here, not at the first cluster: a run that never gates a pair would otherwise
    // accept them, and one that does would fail frames later.
    PRIORMAP_CHECK(ArePriorsValid(options.priors), "SlamOptions::priors out of range");
    if (prior_map) {
      for (const PriorSegment& s : prior_map->segments)
        PRIORMAP_CHECK(IsValidPriorStd(s.std), fmt::format("prior segment std {}", s.std));
      if (options.merge_same_walls) {
        // From here on a "segment" is a wall of the merged map; Record and Finish name it by
        // its first prior segment.
        walls = MergeSameWalls(*prior_map, options.same_wall_chi2);
        prior_map = &walls->map;
        for (const std::vector<int>& group : walls->members) {
          if (group.size() > 1) result.same_walls.push_back(group);
        }
      }
      inference.emplace(*prior_map, options);
      book.segments.resize(prior_map->segments.size());
    }
  }

  // A landmark of the state: its id there, its external id (the observations'), when last seen.
  struct Landmark {
    int external = -1;
    double last_seen = 0.0;
    Vec2 first_estimate = Vec2::Zero();  // its measurement Jacobians' linearisation point (FEJ)
  };

  JointState state;
  // FEJ: the pose the last prediction produced, before any update moved it.
  std::optional<Se2> predicted_pose;
  double time = 0.0;
  MotionNoise motion_noise;
  SensorNoise sensor_noise;
  const PriorMap* prior_map;       // the walls the filter uses: the merged map, with walls
  std::optional<SameWalls> walls;  // merge_same_walls: the walls and their prior segments
  SlamOptions options;
  const RelationTruth* truth;
  std::optional<detail::StructureInference> inference;
  detail::RelationBook book;
  std::vector<int> bad_frames;  // per book.applied: consecutive implausible re-checks

  std::unordered_map<int, Landmark> landmarks;  // by state id
  std::unordered_map<int, int> state_id_of;     // external id -> state id (in the state now)
  std::map<int, MappedLandmark> mapped;         // by external id: every landmark created
  int next_state_id = 0;
  int next_external_id = 0;  // nearest neighbour: ids given to new landmarks
  SlamResult result;

  [[nodiscard]] Mat2 MeasurementNoise() const {
    return Eigen::Vector2d(sensor_noise.range_std * sensor_noise.range_std,
                           sensor_noise.bearing_std * sensor_noise.bearing_std)
        .asDiagonal();
  }

  void Predict(const MotionStep& step) {
    Mat3 F;
    Mat3 Q;
    Se2 next;
    if (const auto* control = std::get_if<BicycleControl>(&step.motion)) {
      Mat32 G;
      next = BicycleMotion(state.pose(), *control, step.dt, motion_noise.wheelbase, &F, &G);
      const Eigen::Vector2d var(motion_noise.speed_std * motion_noise.speed_std,
                                motion_noise.steer_std * motion_noise.steer_std);
      Q = G * var.asDiagonal() * G.transpose();
    } else {
      const Se2& increment = std::get<Se2>(step.motion);
      Mat3 G;
      next = IncrementMotion(state.pose(), increment, &F, &G);
      Vec3 std = step.increment_std;
      for (int k = 0; k < 3; ++k) {
        if (!std::isfinite(std[k])) std[k] = motion_noise.increment_std[k];
      }
      Q = G * std.cwiseAbs2().asDiagonal() * G.transpose();
    }
    if (options.first_estimates_jacobians) {
      // dg/dtheta = J (next - pose) for both models; FEJ takes the pose before the update.
      const Vec2 from = predicted_pose ? predicted_pose->translation() : state.pose().translation();
      F(0, 2) = -(next.y() - from.y());
      F(1, 2) = next.x() - from.x();
      predicted_pose = next;
    }
    state.PredictPose(next, F, Q);
    time = step.time;
    RequireFinitePose("a", "motion step", step.line);
  }

  // A filter whose pose is no longer finite would write NaN maps and trajectories and still
  // report success: it stops here, saying when. So does one whose pose leaves the world that
  // every reader bounds (kMaxWorldCoordinate): its trajectory could not be read back as
  // positions. (`priormap slam run` refuses odometry that leaves it before filtering, at its row:
  // FirstPoseBeyondWorld; this catches the rest, e.g. a library caller's own input.)
  // `line`: where the step or frame was read (0: not from a file). The message is made only
  // when it is thrown: this runs after every step and frame.
  void RequireFinitePose(const char* article, const char* kind, int line) const {
    const auto after = [&] {
      return line > 0 ? fmt::format("the {} read at line {}", kind, line)
                      : fmt::format("{} {}", article, kind);
    };
    const Se2 pose = state.pose();
    if (!pose.vector().allFinite() || !state.pose_covariance().allFinite()) {
      throw SlamDiverged(fmt::format(
          "the filter diverged after {} at t = {} s: its pose or pose covariance is no longer "
          "finite (check the noise and vehicle settings)",
          after(), time));
    }
    if (!IsWithinWorld(pose.x()) || !IsWithinWorld(pose.y())) {
      throw SlamDiverged(fmt::format(
          "the filter's pose left the world after {} at t = {} s: ({}, {}) m, beyond {:.0e} m "
          "in x or y (the bound of world coordinates)",
          after(), time, pose.x(), pose.y(), kMaxWorldCoordinate));
    }
  }

  // Nearest neighbour by Mahalanobis distance among the landmarks in range; each landmark
  // takes at most one observation of a frame (the closest). Returns state ids, -1 for a new
  // landmark, -2 for an ambiguous observation (dropped).
  std::vector<int> AssociateNearest(const std::vector<RangeBearing>& observations) {
    struct Candidate {
      double d2;
      std::size_t obs;
      int landmark;
    };
    std::vector<Candidate> candidates;
    std::vector<double> best(observations.size(), std::numeric_limits<double>::infinity());
    const Se2 pose = state.pose();
    const Mat2 R = MeasurementNoise();
    for (const StateBlock& block : state.blocks()) {
      if (block.kind != BlockKind::kLandmark) continue;
      const Vec2 p = state.mean().segment<2>(block.offset);
      if ((p - pose.translation()).norm() > options.max_range + 5.0) continue;
      Mat23 Hp;
      Mat2 Hl;
      const Vec2 predicted = ObserveRangeBearing(pose, p, &Hp, &Hl);
      Eigen::Matrix<double, 2, 5> H;
      H << Hp, Hl;
      std::array<int, 5> idx{0, 1, 2, block.offset, block.offset + 1};
      Eigen::Matrix<double, 5, 5> C;
      for (int i = 0; i < 5; ++i) {
        for (int j = 0; j < 5; ++j) C(i, j) = state.covariance()(idx[i], idx[j]);
      }
      const Mat2 S = H * C * H.transpose() + R;
      const Eigen::LLT<Mat2> chol(S);
      for (std::size_t o = 0; o < observations.size(); ++o) {
        Vec2 nu(observations[o].range - predicted.x(),
                WrapAngle(observations[o].bearing - predicted.y()));
        const double d2 = chol.matrixL().solve(nu).squaredNorm();
        best[o] = std::min(best[o], d2);
        if (d2 < options.nn_gate_chi2) candidates.push_back({d2, o, block.id});
      }
    }
    std::sort(candidates.begin(), candidates.end(),
              [](const Candidate& a, const Candidate& b) { return a.d2 < b.d2; });
    std::vector<int> assigned(observations.size(), -3);
    std::vector<int> taken;
    for (const Candidate& c : candidates) {
      if (assigned[c.obs] != -3 || std::find(taken.begin(), taken.end(), c.landmark) != taken.end())
        continue;
      assigned[c.obs] = c.landmark;
      taken.push_back(c.landmark);
    }
    for (std::size_t o = 0; o < observations.size(); ++o) {
      if (assigned[o] == -3) assigned[o] = best[o] > options.nn_new_landmark_chi2 ? -1 : -2;
    }
    return assigned;
  }

  void UpdateLandmarks(const std::vector<std::pair<int, Vec2>>& updates) {
    if (updates.empty()) return;
    const Se2 pose = state.pose();
    Linearization m;
    m.H.resize(static_cast<Eigen::Index>(2 * updates.size()), state.dim());
    m.innovation.resize(m.H.rows());
    m.R = Eigen::MatrixXd::Zero(m.H.rows(), m.H.rows());
    std::vector<Eigen::Triplet<double>> triplets;
    triplets.reserve(10 * updates.size());
    const Mat2 R = MeasurementNoise();
    Eigen::Index r = 0;
    for (const auto& [id, z] : updates) {
      const int offset = *state.Offset(BlockKind::kLandmark, id);
      const Vec2 landmark = state.mean().segment<2>(offset);
      Mat23 Hp;
      Mat2 Hl;
      const Vec2 predicted = ObserveRangeBearing(pose, landmark, &Hp, &Hl);
      if (options.first_estimates_jacobians) {
        (void)ObserveRangeBearing(pose, landmarks.at(id).first_estimate, &Hp, &Hl);
      }
      // A landmark estimated at the sensor has no bearing and no Jacobian: its rows would make
      // the whole batch, every other landmark of the frame with it, non-finite and refused.
      if (!predicted.allFinite() || !Hp.allFinite() || !Hl.allFinite()) {
        ++result.rejected_updates;
        continue;
      }
      m.innovation[r] = z.x() - predicted.x();
      m.innovation[r + 1] = WrapAngle(z.y() - predicted.y());
      m.R.block<2, 2>(r, r) = R;
      if (options.second_order_range) {
        const Eigen::MatrixXd& P = state.covariance();
        const Mat2 relative_covariance = P.block<2, 2>(offset, offset) + P.topLeftCorner<2, 2>() -
                                         P.block<2, 2>(offset, 0) - P.block<2, 2>(0, offset);
        const RangeCurvature curvature =
            RangeSecondOrder(landmark - pose.translation(), relative_covariance);
        m.innovation[r] -= curvature.mean_offset;
        m.R(r, r) += curvature.variance;
      }
      for (int i = 0; i < 2; ++i) {
        for (int j = 0; j < 3; ++j) triplets.emplace_back(r + i, j, Hp(i, j));
        for (int j = 0; j < 2; ++j) triplets.emplace_back(r + i, offset + j, Hl(i, j));
      }
      r += 2;
    }
    if (r == 0) return;
    m.H.resize(r, state.dim());
    m.H.setFromTriplets(triplets.begin(), triplets.end());
    m.innovation.conservativeResize(r);
    m.R.conservativeResize(r, r);
    if (!state.Update(m)) ++result.rejected_updates;
  }

  void AddLandmark(int external, const Vec2& z) {
    Mat23 Jp;
    Mat2 Jz;
    const Vec2 position = RangeBearingToPoint(state.pose(), z, &Jp, &Jz);
    Mat2 R = MeasurementNoise();
    if (options.second_order_range) {
      // The measured range is the point's range; the Gaussian over the point (a line across the
      // line of sight) holds ranges longer by the curvature term, so its range spread gains it.
      const Mat2 C = Jp * state.pose_covariance() * Jp.transpose() + Jz * R * Jz.transpose();
      R(0, 0) += RangeSecondOrder(position - state.pose().translation(), C).variance;
    }
    const int id = next_state_id++;
    state.AddLandmark(id, position, Jp, Jz, R);
    landmarks[id] = {external, time, position};
    state_id_of[external] = id;
    ++result.landmarks_created;
  }

  void ApplyRelations(const std::vector<detail::Relation>& relations) {
    if (relations.empty()) return;
    const auto first_recorded = static_cast<std::ptrdiff_t>(book.applied.size());
    std::vector<int> added;
    for (const detail::Relation& relation : relations) {
      for (int segment : relation.segments) {
        if (state.Contains(BlockKind::kSegment, segment)) continue;
        const PriorSegment& s = prior_map->segments[segment];
        state.AddSegment(segment, s.a, s.b, Mat4::Identity() * (s.std * s.std));
        added.push_back(segment);
      }
    }
    PRIORMAP_DCHECK(std::is_partitioned(relations.begin(), relations.end(),
                                        [](const detail::Relation& r) { return r.building < 0; }),
                    "relations to single segments come first");
    // Relations to single segments: one update (they are sorted first).
    std::vector<std::pair<int, int>> single;
    for (const detail::Relation& relation : relations) {
      if (relation.building < 0) single.emplace_back(relation.landmark, relation.segments.front());
    }
    if (!single.empty()) {
      if (state.Update(PointOnSegmentObservation(state, single, options.wall_std))) {
        for (std::size_t k = 0; k < single.size(); ++k) Record(relations[k], single[k].second);
      } else {
        ++result.rejected_updates;
      }
    }
    // Relations to buildings: each a mixture over its walls, one after another.
    for (std::size_t k = single.size(); k < relations.size(); ++k) {
      const detail::Relation& relation = relations[k];
      const auto posterior =
          state.UpdateMixture(PointOnSomeSegmentObservation(state, relation.landmark,
                                                            relation.segments, options.wall_std),
                              relation.weights);
      if (!posterior) {
        ++result.rejected_updates;
        continue;
      }
      const auto most = std::max_element(posterior->begin(), posterior->end()) - posterior->begin();
      Record(relation, relation.segments[static_cast<std::size_t>(most)]);
      ++result.building_relations;
    }
    // A segment that entered the state for updates that were then rejected leaves it again,
    // untouched and still independent of everything, so it is not retired. (Only this call's
    // relations can use it: a segment outside the state has none applied.)
    for (int segment : added) {
      const bool used = std::any_of(book.applied.begin() + first_recorded, book.applied.end(),
                                    [&](const detail::Relation& r) {
                                      return std::find(r.segments.begin(), r.segments.end(),
                                                       segment) != r.segments.end();
                                    });
      if (!used) state.Remove(BlockKind::kSegment, segment);
    }
  }

  // The prior segments of wall `wall` (itself, unless walls were merged), and its name.
  [[nodiscard]] std::span<const int> SegmentsOf(const int& wall) const {
    return walls ? std::span<const int>(walls->members[static_cast<std::size_t>(wall)])
                 : std::span<const int>(&wall, 1);
  }
  [[nodiscard]] int PriorSegmentOf(int wall) const {
    return walls ? walls->members[static_cast<std::size_t>(wall)].front() : wall;
  }

  void Record(const detail::Relation& relation, int most_probable_segment) {
    book.Apply(relation);
    bad_frames.push_back(0);
    RelationRecord record;
    record.landmark = landmarks.at(relation.landmark).external;
    record.segment = PriorSegmentOf(most_probable_segment);
    record.time = time;
    if (relation.building >= 0) {
      record.building = relation.building;
      record.buildings = relation.buildings;
      for (int wall : relation.segments) record.walls.push_back(PriorSegmentOf(wall));
    }
    if (truth) {
      // A merged wall is the landmark's wall when one of its segments is, and spurious only when
      // all of them are.
      const auto correct = [&](int wall) {
        const std::span<const int> segments = SegmentsOf(wall);
        return std::any_of(segments.begin(), segments.end(),
                           [&](int s) { return truth->Correct(record.landmark, s); });
      };
      const auto spurious = [&](int wall) {
        const std::span<const int> segments = SegmentsOf(wall);
        return std::all_of(segments.begin(), segments.end(),
                           [&](int s) { return truth->Spurious(s); });
      };
      record.correct = std::any_of(relation.segments.begin(), relation.segments.end(), correct);
      record.spurious_segment =
          std::any_of(relation.segments.begin(), relation.segments.end(), spurious);
    }
    result.relations.push_back(record);
  }

  // The normalised innovation squared of an applied relation: for one to a building, that of
  // its most plausible wall.
  [[nodiscard]] double RelationNis(const detail::Relation& relation) const {
    double nis = std::numeric_limits<double>::infinity();
    for (int segment : relation.segments) {
      const std::pair<int, int> pair(relation.landmark, segment);
      const Linearization m =
          PointOnSegmentObservation(state, std::span(&pair, 1), options.wall_std);
      nis = std::min(nis, m.innovation[0] * m.innovation[0] / state.InnovationCovariance(m)(0, 0));
    }
    return nis;
  }

  // Applied relations whose landmark and segments are all still in the state, re-tested. The
  // relations of a segment are coupled through it, so one bad relation makes its neighbours look
  // bad too: per segment only the most implausible is flagged, and its segments quarantined.
  void RecheckRelations() {
    std::unordered_map<int, std::pair<std::size_t, double>> worst;  // segment -> (relation, nis)
    for (std::size_t k = 0; k < book.applied.size(); ++k) {
      const detail::Relation& relation = book.applied[k];
      const bool testable =
          state.Contains(BlockKind::kLandmark, relation.landmark) &&
          std::all_of(relation.segments.begin(), relation.segments.end(), [&](int segment) {
            return !book.segments[segment].quarantined &&
                   state.Contains(BlockKind::kSegment, segment);
          });
      if (!testable) continue;
      const double nis = RelationNis(relation);
      bad_frames[k] = nis > options.recheck_chi2 ? bad_frames[k] + 1 : 0;
      if (bad_frames[k] < options.recheck_frames) continue;
      for (int segment : relation.segments) {
        auto [it, inserted] = worst.try_emplace(segment, k, nis);
        if (!inserted && nis > it->second.second) it->second = {k, nis};
      }
    }
    for (const auto& [segment, flagged] : worst) {
      result.relations[flagged.first].flagged = true;
      result.relations[flagged.first].flagged_time = time;
      for (int s : book.applied[flagged.first].segments) book.segments[s].quarantined = true;
    }
  }

  void SlideWindow() {
    if (options.window_s <= 0.0) return;
    std::vector<int> expired;
    for (const auto& [id, landmark] : landmarks) {
      if (time - landmark.last_seen > options.window_s) expired.push_back(id);
    }
    std::sort(expired.begin(), expired.end());
    for (int id : expired) {
      state.Remove(BlockKind::kLandmark, id);
      const int external = landmarks.at(id).external;
      if (auto it = state_id_of.find(external); it != state_id_of.end() && it->second == id) {
        state_id_of.erase(it);
      }
      landmarks.erase(id);
    }
    if (expired.empty() || !prior_map) return;
    // Segments with no related landmark left are marginalised out and retired.
    std::vector<int> in_use;
    for (const detail::Relation& relation : book.applied) {
      if (state.Contains(BlockKind::kLandmark, relation.landmark)) {
        in_use.insert(in_use.end(), relation.segments.begin(), relation.segments.end());
      }
    }
    std::vector<int> retire;
    for (const StateBlock& block : state.blocks()) {
      if (block.kind == BlockKind::kSegment &&
          std::find(in_use.begin(), in_use.end(), block.id) == in_use.end()) {
        retire.push_back(block.id);
      }
    }
    for (int segment : retire) {
      state.Remove(BlockKind::kSegment, segment);
      book.segments[segment].retired = true;
    }
  }

  FrameRecord Observe(const ObservationFrame& frame) {
    time = std::max(time, frame.time);
    std::vector<std::pair<int, Vec2>> updates;
    std::vector<std::pair<int, Vec2>> fresh;  // (external id, z)
    if (options.association == AssociationMode::kKnownIds) {
      for (const RangeBearing& z : frame.observations) {
        PRIORMAP_CHECK(z.id >= 0, "known-id association needs ids on every observation");
        const auto it = state_id_of.find(z.id);
        if (it != state_id_of.end()) {
          updates.emplace_back(it->second, Vec2(z.range, z.bearing));
        } else {
          fresh.emplace_back(z.id, Vec2(z.range, z.bearing));
        }
      }
    } else {
      const std::vector<int> assigned = AssociateNearest(frame.observations);
      for (std::size_t o = 0; o < assigned.size(); ++o) {
        const Vec2 z(frame.observations[o].range, frame.observations[o].bearing);
        if (assigned[o] >= 0) {
          updates.emplace_back(assigned[o], z);
        } else if (assigned[o] == -1) {
          fresh.emplace_back(next_external_id++, z);
        }
      }
    }
    UpdateLandmarks(updates);
    for (const auto& [id, z] : updates) landmarks[id].last_seen = time;
    for (const auto& [external, z] : fresh) AddLandmark(external, z);

    FrameRecord record;
    if (prior_map) {
      RecheckRelations();
      const auto accepted = inference->Infer(state, book, result.inference);
      ApplyRelations(accepted);
      record.accepted = static_cast<int>(accepted.size());
    }
    SlideWindow();
    MapLandmarksInState();

    record.time = time;
    record.estimate = state.pose();
    record.covariance = state.pose_covariance();
    record.landmarks = state.NumLandmarks();
    record.segments = state.NumSegments();
    for (std::size_t k = 0; k < book.applied.size(); ++k) {
      if (!state.Contains(BlockKind::kLandmark, book.applied[k].landmark)) continue;
      ++record.relations_in_state;
      const RelationRecord& r = result.relations[k];
      if (r.correct) (*r.correct ? record.relations_correct : record.relations_incorrect)++;
      if (r.spurious_segment) ++record.relations_spurious;
    }
    RequireFinitePose("an", "observation frame", frame.line);
    result.frames.push_back(record);
    return record;
  }

  [[nodiscard]] LandmarkEstimate EstimateOf(const StateBlock& landmark) const {
    return {landmarks.at(landmark.id).external, state.mean().segment<2>(landmark.offset),
            state.covariance().block<2, 2>(landmark.offset, landmark.offset)};
  }

  // After each frame, so that a landmark the window drops keeps the estimate it had in the
  // last frame that ended with it in the state (the frame records count it there).
  void MapLandmarksInState() {
    for (const StateBlock& block : state.blocks()) {
      if (block.kind != BlockKind::kLandmark) continue;
      const LandmarkEstimate estimate = EstimateOf(block);
      mapped[estimate.id] = {.estimate = estimate, .last_time = time};
    }
  }

  SlamResult Finish() const {
    SlamResult out = result;
    for (auto [id, landmark] : mapped) {
      landmark.in_state = state_id_of.contains(id);
      out.all_landmarks.push_back(landmark);
    }
    for (const StateBlock& block : state.blocks()) {
      if (block.kind == BlockKind::kLandmark) {
        out.landmarks.push_back(EstimateOf(block));
      } else {
        out.segments.push_back({PriorSegmentOf(block.id), state.mean().segment<2>(block.offset),
                                state.mean().segment<2>(block.offset + 2),
                                state.covariance().block<4, 4>(block.offset, block.offset)});
      }
    }
    return out;
  }
};

PriorMapSlam::PriorMapSlam(const Se2& initial_pose, double start_time,
                           const MotionNoise& motion_noise, const SensorNoise& sensor_noise,
                           const PriorMap* prior_map, SlamOptions options,
                           const RelationTruth* truth)
    : impl_(std::make_unique<Impl>(initial_pose, start_time, motion_noise, sensor_noise, prior_map,
                                   std::move(options), truth)) {}
PriorMapSlam::~PriorMapSlam() = default;
PriorMapSlam::PriorMapSlam(PriorMapSlam&&) noexcept = default;
PriorMapSlam& PriorMapSlam::operator=(PriorMapSlam&&) noexcept = default;

void PriorMapSlam::Predict(const MotionStep& step) {
  impl_->Predict(step);
}
FrameRecord PriorMapSlam::Observe(const ObservationFrame& frame) {
  return impl_->Observe(frame);
}
const JointState& PriorMapSlam::state() const {
  return impl_->state;
}
SlamResult PriorMapSlam::Finish() const {
  return impl_->Finish();
}

SlamResult RunSlam(const SlamInput& input, const PriorMap* prior_map, const SlamOptions& options,
                   const RelationTruth* truth) {
  PriorMapSlam slam(input.initial_pose, input.start_time, input.motion_noise, input.sensor_noise,
                    prior_map, options, truth);
  constexpr double kTimeTolerance = 1e-9;
  std::size_t f = 0;
  for (const MotionStep& step : input.motion) {
    MotionStep rest = step;
    // Frames inside a bicycle step: split the step there (its controls are held over it).
    while (f < input.frames.size() && input.frames[f].time < rest.time - kTimeTolerance &&
           std::holds_alternative<BicycleControl>(rest.motion)) {
      const double begin = rest.time - rest.dt;
      const double part = input.frames[f].time - begin;
      if (part > kTimeTolerance) {
        MotionStep first = rest;
        first.time = input.frames[f].time;
        first.dt = part;
        slam.Predict(first);
        rest.dt -= part;
      }
      slam.Observe(input.frames[f++]);
    }
    // Frames at or before this step's start come before it; those inside an odometry
    // increment, which cannot be split, after it.
    while (f < input.frames.size() && input.frames[f].time <= rest.time - rest.dt + kTimeTolerance)
      slam.Observe(input.frames[f++]);
    slam.Predict(rest);
    while (f < input.frames.size() && input.frames[f].time <= rest.time + kTimeTolerance)
      slam.Observe(input.frames[f++]);
  }
  while (f < input.frames.size()) slam.Observe(input.frames[f++]);
  return slam.Finish();
}

}  // namespace priormap::slam
