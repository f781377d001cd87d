#pragma once
/// A relation "landmark i lies on prior segment n" as a pseudo-observation of the joint state
/// (Parsley & Julier, Sec. V-B): 0 = theta(x_i, a_n, b_n) + w, theta the signed orthogonal
/// distance of the point from the segment's line (SignedLineDistance, the paper's determinant
/// formula up to sign) and w ~ N(0, wall_std^2), the prior p(theta | d = 1) of a wall that is not
/// perfectly flat.

#include <span>
#include <utility>
#include <vector>

#include <priormap/slam/joint_state.hpp>

namespace priormap::slam {

/// Rows for the (state landmark id, segment id) relations, linearised at the state's mean.
/// Precondition: every landmark and segment is in the state.
[[nodiscard]] Linearization PointOnSegmentObservation(
    const JointState& state, std::span<const std::pair<int, int>> relations, double wall_std);

/// A relation known one level up the hierarchy (eq. 3): "landmark i lies on some wall of this
/// building", the likelihood sum_s p(d_s = 1 | d_S = 1) N(theta_s; 0, wall_std^2) over the
/// building's candidate `segments`. One component per segment, for JointState::UpdateMixture.
[[nodiscard]] std::vector<Linearization> PointOnSomeSegmentObservation(
    const JointState& state, int landmark, std::span<const int> segments, double wall_std);

}  // namespace priormap::slam
