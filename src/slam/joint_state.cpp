#include <cmath>
#include <limits>

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
  // LLT reports success on a matrix holding NaN: such an update is refused like any other
  // that cannot be made, rather than written into the state.
  if (!Wt.allFinite() || !whitened.allFinite()) return false;
  mean_.noalias() += Wt.transpose() * whitened;
  mean_[2] = WrapAngle(mean_[2]);
  covariance_.selfadjointView<Eigen::Lower>().rankUpdate(Wt.transpose(), -1.0);
  covariance_.triangularView<Eigen::StrictlyUpper>() = covariance_.transpose();
  return true;
}

std::optional<std::vector<double>> JointState::UpdateMixture(
    std::span<const Linearization> components, std::span<const double> weights) {
  PRIORMAP_CHECK(!components.empty() && components.size() == weights.size(),
                 "a mixture update needs one weight per component");
  constexpr double kLog2Pi = 1.8378770664093454836;
  struct Component {
    Eigen::MatrixXd Wt;    // L^-1 H P: the update subtracts Wt^T Wt
    Eigen::VectorXd step;  // K nu
    double log_weight;
  };
  std::vector<Component> parts;
  parts.reserve(components.size());
  double best = -std::numeric_limits<double>::infinity();
  for (std::size_t s = 0; s < components.size(); ++s) {
    const Linearization& m = components[s];
    PRIORMAP_CHECK(m.H.cols() == dim() && m.H.rows() == m.innovation.size() &&
                       m.R.rows() == m.H.rows() && m.R.cols() == m.H.rows(),
                   "measurement dimensions do not match the state");
    const Eigen::MatrixXd PHt = covariance_ * m.H.transpose();
    const Eigen::LLT<Eigen::MatrixXd> chol(InnovationCovariance(m, PHt));
    if (chol.info() != Eigen::Success) return std::nullopt;
    Component c;
    c.Wt = chol.matrixL().solve(PHt.transpose());
    const Eigen::VectorXd whitened = chol.matrixL().solve(m.innovation);
    c.step = c.Wt.transpose() * whitened;
    if (!c.Wt.allFinite() || !c.step.allFinite()) return std::nullopt;  // as Update
    const double log_det = 2.0 * chol.matrixLLT().diagonal().array().log().sum();
    c.log_weight =
        weights[s] > 0.0
            ? std::log(weights[s]) - 0.5 * (whitened.squaredNorm() + log_det + m.H.rows() * kLog2Pi)
            : -std::numeric_limits<double>::infinity();
    best = std::max(best, c.log_weight);
    parts.push_back(std::move(c));
  }
  if (!std::isfinite(best)) return std::nullopt;
  std::vector<double> posterior;
  double total = 0.0;
  for (const Component& c : parts) total += posterior.emplace_back(std::exp(c.log_weight - best));
  Eigen::VectorXd step = Eigen::VectorXd::Zero(dim());
  for (std::size_t s = 0; s < parts.size(); ++s) {
    posterior[s] /= total;
    step += posterior[s] * parts[s].step;
  }
  // P - sum_s a_s K_s S_s K_s^T + sum_s a_s (step_s - step)(step_s - step)^T, lower triangle.
  auto lower = covariance_.selfadjointView<Eigen::Lower>();
  for (std::size_t s = 0; s < parts.size(); ++s) {
    if (posterior[s] == 0.0) continue;
    lower.rankUpdate(parts[s].Wt.transpose(), -posterior[s]);
    lower.rankUpdate(parts[s].step - step, posterior[s]);
  }
  covariance_.triangularView<Eigen::StrictlyUpper>() = covariance_.transpose();
  mean_ += step;
  mean_[2] = WrapAngle(mean_[2]);
  return posterior;
}

}  // namespace priormap::slam
