#include <Eigen/Cholesky>

#include <priormap/core/angles.hpp>
#include <priormap/core/check.hpp>
#include <priormap/slam/joint_state.hpp>

namespace priormap::slam {

JointState::JointState(const Se2& pose, const Mat3& pose_covariance)
    : mean_(pose.vector()), covariance_(pose_covariance) {}

std::optional<int> JointState::Offset(BlockKind kind, int id) const {
  const auto it = index_.find(Key(kind, id));
  if (it == index_.end()) return std::nullopt;
  return blocks_[it->second].offset;
}

void JointState::PredictPose(const Se2& new_pose, const Mat3& F, const Mat3& Q) {
  const int n = dim();
  mean_.head<3>() = new_pose.vector();
  // Only the pose rows and columns change: P_vv <- F P_vv F^T + Q, P_vm <- F P_vm.
  if (n > kPoseSize) {
    const Eigen::MatrixXd cross = F * covariance_.topRightCorner(3, n - 3);
    covariance_.topRightCorner(3, n - 3) = cross;
    covariance_.bottomLeftCorner(n - 3, 3) = cross.transpose();
  }
  const Mat3 pose_block = F * covariance_.topLeftCorner<3, 3>() * F.transpose() + Q;
  covariance_.topLeftCorner<3, 3>() = 0.5 * (pose_block + pose_block.transpose());
}

void JointState::Append(const StateBlock& block, const Eigen::VectorXd& mean,
                        const Eigen::MatrixXd& cross_covariance,
                        const Eigen::MatrixXd& covariance) {
  PRIORMAP_CHECK(!index_.contains(Key(block.kind, block.id)), "block already in the state");
  const int n = dim();
  const int s = block.size();
  mean_.conservativeResize(n + s);
  mean_.tail(s) = mean;
  Eigen::MatrixXd grown(n + s, n + s);
  grown.topLeftCorner(n, n) = covariance_;
  grown.bottomLeftCorner(s, n) = cross_covariance;
  grown.topRightCorner(n, s) = cross_covariance.transpose();
  grown.bottomRightCorner(s, s) = 0.5 * (covariance + covariance.transpose());
  covariance_ = std::move(grown);
  StateBlock placed = block;
  placed.offset = n;
  index_[Key(block.kind, block.id)] = blocks_.size();
  blocks_.push_back(placed);
  if (block.kind == BlockKind::kLandmark) ++num_landmarks_;
}

void JointState::AddLandmark(int id, const Vec2& position, const Mat23& J_pose, const Mat2& J_z,
                             const Mat2& R) {
  const Eigen::MatrixXd cross = J_pose * covariance_.topRows(3);
  const Mat2 cov =
      J_pose * covariance_.topLeftCorner<3, 3>() * J_pose.transpose() + J_z * R * J_z.transpose();
  Append({BlockKind::kLandmark, id, -1}, position, cross, cov);
}

void JointState::AddSegment(int id, const Vec2& a, const Vec2& b, const Mat4& covariance) {
  Vec4 endpoints;
  endpoints << a, b;
  Append({BlockKind::kSegment, id, -1}, endpoints, Eigen::MatrixXd::Zero(4, dim()), covariance);
}

void JointState::Remove(BlockKind kind, int id) {
  const auto it = index_.find(Key(kind, id));
  PRIORMAP_CHECK(it != index_.end(), "block not in the state");
  const std::size_t position = it->second;
  const StateBlock removed = blocks_[position];
  const int n = dim();
  const int s = removed.size();
  const int tail = n - removed.offset - s;
  // Marginalising a Gaussian drops its rows and columns; shift the later ones up and left.
  mean_.segment(removed.offset, tail) = mean_.tail(tail).eval();
  mean_.conservativeResize(n - s);
  covariance_.block(removed.offset, 0, tail, n) = covariance_.bottomRows(tail).eval();
  covariance_.block(0, removed.offset, n, tail) = covariance_.rightCols(tail).eval();
  covariance_.conservativeResize(n - s, n - s);
  index_.erase(it);
  blocks_.erase(blocks_.begin() + static_cast<std::ptrdiff_t>(position));
  if (kind == BlockKind::kLandmark) --num_landmarks_;
  ReindexFrom(position);
}

void JointState::ReindexFrom(std::size_t first_block) {
  int offset = first_block == 0 ? kPoseSize
                                : blocks_[first_block - 1].offset + blocks_[first_block - 1].size();
  for (std::size_t i = first_block; i < blocks_.size(); ++i) {
    blocks_[i].offset = offset;
    offset += blocks_[i].size();
    index_[Key(blocks_[i].kind, blocks_[i].id)] = i;
  }
}

Eigen::MatrixXd JointState::InnovationCovariance(const Linearization& m) const {
  return InnovationCovariance(m, covariance_ * m.H.transpose());
}

Eigen::MatrixXd JointState::InnovationCovariance(const Linearization& m,
                                                 const Eigen::MatrixXd& PHt) const {
  Eigen::MatrixXd S = m.H * PHt;
  S += m.R;
  return 0.5 * (S + S.transpose());
}

bool JointState::Update(const Linearization& m) {
  PRIORMAP_CHECK(m.H.cols() == dim() && m.H.rows() == m.innovation.size() &&
                     m.R.rows() == m.H.rows() && m.R.cols() == m.H.rows(),
                 "measurement dimensions do not match the state");
  if (m.H.rows() == 0) return true;
  const Eigen::MatrixXd PHt = covariance_ * m.H.transpose();
  const Eigen::LLT<Eigen::MatrixXd> chol(InnovationCovariance(m, PHt));
  if (chol.info() != Eigen::Success) return false;
  // W = P H^T L^-T; K = W L^-1; x += W (L^-1 nu); P -= W W^T.
  const Eigen::MatrixXd Wt = chol.matrixL().solve(PHt.transpose());
  const Eigen::VectorXd whitened = chol.matrixL().solve(m.innovation);
  mean_.noalias() += Wt.transpose() * whitened;
  mean_[2] = WrapAngle(mean_[2]);
  covariance_.selfadjointView<Eigen::Lower>().rankUpdate(Wt.transpose(), -1.0);
  covariance_.triangularView<Eigen::StrictlyUpper>() = covariance_.transpose();
  return true;
}

}  // namespace priormap::slam
