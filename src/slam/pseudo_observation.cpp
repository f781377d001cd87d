#include <vector>

#include <priormap/core/check.hpp>
#include <priormap/core/segment.hpp>
#include <priormap/slam/pseudo_observation.hpp>

namespace priormap::slam {

Linearization PointOnSegmentObservation(const JointState& state,
                                        std::span<const std::pair<int, int>> relations,
                                        double wall_std) {
  Linearization m;
  const auto rows = static_cast<Eigen::Index>(relations.size());
  m.H.resize(rows, state.dim());
  m.innovation.resize(rows);
  m.R = Eigen::MatrixXd::Identity(rows, rows) * (wall_std * wall_std);
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(6 * relations.size());
  for (Eigen::Index r = 0; r < rows; ++r) {
    const auto [landmark, segment] = relations[r];
    const auto lo = state.Offset(BlockKind::kLandmark, landmark);
    const auto so = state.Offset(BlockKind::kSegment, segment);
    PRIORMAP_CHECK(lo && so, "a relation's landmark and segment must be in the state");
    Row2 J_p, J_a, J_b;
    const double theta =
        SignedLineDistance(state.mean().segment<2>(*lo), state.mean().segment<2>(*so),
                           state.mean().segment<2>(*so + 2), &J_p, &J_a, &J_b);
    m.innovation[r] = 0.0 - theta;
    for (int j = 0; j < 2; ++j) {
      triplets.emplace_back(r, *lo + j, J_p[j]);
      triplets.emplace_back(r, *so + j, J_a[j]);
      triplets.emplace_back(r, *so + 2 + j, J_b[j]);
    }
  }
  m.H.setFromTriplets(triplets.begin(), triplets.end());
  return m;
}

std::vector<Linearization> PointOnSomeSegmentObservation(const JointState& state, int landmark,
                                                         std::span<const int> segments,
                                                         double wall_std) {
  std::vector<Linearization> components;
  components.reserve(segments.size());
  for (int segment : segments) {
    const std::pair<int, int> relation(landmark, segment);
    components.push_back(PointOnSegmentObservation(state, std::span(&relation, 1), wall_std));
  }
  return components;
}

}  // namespace priormap::slam
