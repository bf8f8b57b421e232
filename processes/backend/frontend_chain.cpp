#include "frontend_chain.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

namespace traverse::backend {
namespace {

// Below this travel a step still drifts as much as this [m]: a standstill keeps a finite
// information.
constexpr double kMinDriftTravelM = 0.01;
// In a scanner's stream one pose's covariance enters the drift at most this many times its
// neighbour's (by their position variances) [unitless].
constexpr double kMaxDriftRatio = 10.0;

}  // namespace

Eigen::Matrix3d frontend_pose_covariance(const PreparedPose& pose, double scale,
                                         const Eigen::Matrix3d& fallback) {
  const Eigen::Matrix3d& C = pose.frontend.covariance;
  if (C.isZero() || !C.allFinite() || !(C.diagonal().array() > 0.0).all()) return fallback;
  // Map frame -> world (prepared) frame -> the pose's own frame.
  return scale *
         rotate_covariance(C, Pose2(0.0, 0.0, -pose.frontend.T_map_base.theta()).rotation());
}

Edge drift_edge(int from, int to, const PreparedPose& a, const PreparedPose& b,
                const Eigen::Matrix3d& ca, const Eigen::Matrix3d& cb, double drift_length_m) {
  Edge edge;
  edge.from = from;
  edge.to = to;
  edge.T_from_to = between(a.T_world_base, b.T_world_base);
  const double travel = std::max(
      kMinDriftTravelM, b.travel_m - a.travel_m + kTurnLeverM * std::abs(edge.T_from_to.theta()));
  Eigen::Matrix3d la = ca, lb = cb;
  if (a.paced && b.paced) {
    const double pa = ca(0, 0) + ca(1, 1), pb = cb(0, 0) + cb(1, 1);
    if (pa > kMaxDriftRatio * pb) la *= kMaxDriftRatio * pb / pa;
    if (pb > kMaxDriftRatio * pa) lb *= kMaxDriftRatio * pa / pb;
  }
  const Eigen::Matrix3d typical = 0.5 * (la + lb);
  edge.information = (travel / drift_length_m * typical).inverse();
  return edge;
}

Edge motion_edge(int from, int to, const PreparedPose& a, const PreparedPose& b,
                 const Eigen::Matrix3d& ca, const Eigen::Matrix3d& cb) {
  Edge edge;
  edge.from = from;
  edge.to = to;
  edge.T_from_to = between(a.T_world_base, b.T_world_base);
  // Each pose's error carried through the relative pose: J_a C_a J_a^T + J_b C_b J_b^T with the
  // edge error's Jacobians (pose_graph.hpp), the covariances turned back into the world frame.
  Eigen::Matrix3d J_a, J_b;
  edge_jacobians(a.T_world_base, b.T_world_base, edge.T_from_to, J_a, J_b);
  const Eigen::Matrix3d Ca = rotate_covariance(ca, a.T_world_base.rotation());
  const Eigen::Matrix3d Cb = rotate_covariance(cb, b.T_world_base.rotation());
  edge.information = (J_a * Ca * J_a.transpose() + J_b * Cb * J_b.transpose()).inverse();
  return edge;
}

Edge key_step_edge(int from, int to, const PreparedPose& a, const PreparedPose& b,
                   const Eigen::Matrix3d& ca, const Eigen::Matrix3d& cb, double drift_length_m) {
  Edge edge = motion_edge(from, to, a, b, ca, cb);
  if (drift_length_m > 0.0) {
    const Edge drift = drift_edge(from, to, a, b, ca, cb, drift_length_m);
    edge.information = (edge.information.inverse() + drift.information.inverse()).inverse();
  }
  return edge;
}

}  // namespace traverse::backend
