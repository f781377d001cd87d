#pragma once
/// The Gaussian joint state of EKF-SLAM with a prior map (Parsley & Julier, Sec. V-B): the vehicle
/// pose (x, y, theta), point landmarks (x, y) and the prior map's segments that relations have
/// touched (both endpoints, 4 numbers), with one full covariance. A prior segment is independent
/// of everything else until a relation couples it, so it enters the state only then; the joint
/// estimate is the same as if the whole prior map had been in the state from the start.
///
/// The covariance stays symmetric and positive semi-definite: updates subtract W W^T with
/// W = P H^T L^-T (S = L L^T), the Cholesky form of P - K S K^T used by Bailey & Nieto's
/// EKF-SLAM toolbox, which never forms the gain's product twice and only writes one triangle.

#include <optional>
#include <span>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <priormap/core/se2.hpp>

namespace priormap::slam {

using Mat4 = Eigen::Matrix4d;
using Vec4 = Eigen::Vector4d;

enum class BlockKind { kLandmark, kSegment };

/// A landmark's or segment's place in the state vector.
struct StateBlock {
  BlockKind kind = BlockKind::kLandmark;
  int id = -1;      ///< landmark id, or prior-map segment index
  int offset = -1;  ///< index of its first entry
  [[nodiscard]] int size() const { return kind == BlockKind::kLandmark ? 2 : 4; }
};

/// A measurement linearised at the current mean: z ~ h(x) + H (x - mean) + noise. `H` has the
/// state's full width; only the columns of the blocks involved are non-zero.
struct Linearization {
  Eigen::SparseMatrix<double, Eigen::RowMajor> H;
  Eigen::VectorXd innovation;  ///< z - h(mean), angles wrapped
  Eigen::MatrixXd R;           ///< measurement noise covariance
};

class JointState {
 public:
  static constexpr int kPoseSize = 3;

  JointState(const Se2& pose, const Mat3& pose_covariance);

  [[nodiscard]] int dim() const { return static_cast<int>(mean_.size()); }
  [[nodiscard]] const Eigen::VectorXd& mean() const { return mean_; }
  [[nodiscard]] const Eigen::MatrixXd& covariance() const { return covariance_; }
  [[nodiscard]] Se2 pose() const { return Se2::FromVector(mean_.head<3>()); }
  [[nodiscard]] Mat3 pose_covariance() const { return covariance_.topLeftCorner<3, 3>(); }

  [[nodiscard]] const std::vector<StateBlock>& blocks() const { return blocks_; }
  [[nodiscard]] std::optional<int> Offset(BlockKind kind, int id) const;
  [[nodiscard]] bool Contains(BlockKind kind, int id) const { return Offset(kind, id).has_value(); }
  [[nodiscard]] int NumLandmarks() const { return num_landmarks_; }
  [[nodiscard]] int NumSegments() const {
    return static_cast<int>(blocks_.size()) - num_landmarks_;
  }

  /// Prediction: the pose becomes `new_pose` = g(pose, u) with F = dg/dpose, and its covariance
  /// gains `Q` (= G_u Q_u G_u^T). Cross-covariances become F P_pose,map. O(dim).
  void PredictPose(const Se2& new_pose, const Mat3& F, const Mat3& Q);

  /// Appends landmark `id` at `position` = g(pose, z) with J_pose = dg/dpose, J_z = dg/dz and
  /// measurement noise R: covariance J_pose P_pose J_pose^T + J_z R J_z^T, cross-covariance
  /// J_pose P_pose,*. Precondition: the id is not in the state.
  void AddLandmark(int id, const Vec2& position, const Mat23& J_pose, const Mat2& J_z,
                   const Mat2& R);
  /// Appends prior segment `id` (endpoints a, b) with its own covariance, independent of the rest.
  void AddSegment(int id, const Vec2& a, const Vec2& b, const Mat4& covariance);
  /// Marginalises a block out. Precondition: it is in the state.
  void Remove(BlockKind kind, int id);

  /// H P H^T + R, the innovation covariance of a linearised measurement.
  [[nodiscard]] Eigen::MatrixXd InnovationCovariance(const Linearization& m) const;

  /// The Kalman update with a linearised measurement. Returns false, changing nothing, when the
  /// innovation covariance is not positive definite or the update would not be finite.
  bool Update(const Linearization& m);

  /// The update with a mixture likelihood sum_s w_s N(z_s; h_s(x), R_s), one linearised
  /// measurement per component: the posterior is the Gaussian sum of the components' Kalman
  /// updates, weighted by w_s N(nu_s; 0, S_s), collapsed to its mean and covariance (moment
  /// matching: sum_s a_s (P_s + (x_s - x)(x_s - x)^T), positive semi-definite by construction).
  /// Returns the components' posterior weights a_s; nullopt, changing nothing, when an innovation
  /// covariance is not positive definite, a component's update is not finite or no weight is
  /// positive.
  std::optional<std::vector<double>> UpdateMixture(std::span<const Linearization> components,
                                                   std::span<const double> weights);

 private:
  // H P H^T + R given P H^T, which the update needs too.
  [[nodiscard]] Eigen::MatrixXd InnovationCovariance(const Linearization& m,
                                                     const Eigen::MatrixXd& PHt) const;
  void Append(const StateBlock& block, const Eigen::VectorXd& mean,
              const Eigen::MatrixXd& cross_covariance, const Eigen::MatrixXd& covariance);
  void ReindexFrom(std::size_t first_block);
  static long Key(BlockKind kind, int id) {
    return 2L * id + (kind == BlockKind::kSegment ? 1 : 0);
  }

  Eigen::VectorXd mean_;
  Eigen::MatrixXd covariance_;
  std::vector<StateBlock> blocks_;
  std::unordered_map<long, std::size_t> index_;  ///< Key -> position in blocks_
  int num_landmarks_ = 0;
};

}  // namespace priormap::slam
