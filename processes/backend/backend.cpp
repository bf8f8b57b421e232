#include "backend.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <chrono>
#include <cmath>
#include <cstdlib>

namespace traverse::backend {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// The matcher's world-frame covariance of a pose, expressed in that pose's own frame (the frame of
// the pose graph's edge error).
// The rotation of (x, y) by theta, the heading left alone.
Eigen::Matrix3d rotation3(double theta) {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  R.topLeftCorner<2, 2>() = Pose2(0.0, 0.0, theta).rotation();
  return R;
}

Eigen::Matrix3d to_pose_frame(const Eigen::Matrix3d& covariance_world, const Pose2& T_world_pose) {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  R.topLeftCorner<2, 2>() = T_world_pose.rotation().transpose();
  return R * covariance_world * R.transpose();
}

}  // namespace

std::string validate(const BackendConfig& c) {
  if (auto e = validate(c.link); !e.empty()) return "link." + e;
  if (auto e = validate(c.link_refine); !e.empty()) return "link_refine." + e;
  if (auto e = validate(c.loop); !e.empty()) return "loop." + e;
  if (auto e = validate(c.spa); !e.empty()) return "spa." + e;
  if (c.link_chain_length < 1) return "link_chain_length must be >= 1";
  if (!(c.link_covariance_scale > 0.0) || c.link_max_mahalanobis < 0.0) {
    return "link_covariance_scale must be > 0, link_max_mahalanobis >= 0";
  }
  if (!(c.fallback_sigma_xy_m > 0.0) || !(c.fallback_sigma_theta_rad > 0.0)) {
    return "fallback sigmas must be > 0";
  }
  if (c.frontend_sigma_xy_m < 0.0 || c.frontend_sigma_theta_rad < 0.0) {
    return "frontend sigmas must be >= 0 (0: no frontend edge)";
  }
  if (c.optimize_every < 1) return "optimize_every must be >= 1";
  if (c.max_pending_scans < 1) return "max_pending_scans must be >= 1";
  if (auto e = validate(c.smoothing); !e.empty()) return "smoothing." + e;
  if (!(c.frontend_covariance_scale > 0.0) || c.frontend_drift_xy_m < 0.0 ||
      c.frontend_drift_theta_rad < 0.0) {
    return "frontend_covariance_scale must be > 0, frontend_drift_* >= 0";
  }
  return {};
}

Backend::Backend(BackendConfig config)
    : config_(std::move(config)),
      T_base_laser_(config_.T_base_laser.x_m, config_.T_base_laser.y_m,
                    config_.T_base_laser.theta_rad),
      link_matcher_(config_.link),
      link_refiner_(config_.link_refine),
      loop_(config_.loop),
      spa_(config_.spa),
      prep_(config_.smoothing) {}

void Backend::add_scan(PlanarScan scan) {
  ++counters_.scans;
  pending_scans_.push_back(std::move(scan));
  while (static_cast<int>(pending_scans_.size()) > config_.max_pending_scans) {
    pending_scans_.pop_front();
  }
}

std::optional<BackendUpdate> Backend::add_pose(int64_t utime, const Pose2& T_map_base,
                                               const Eigen::Matrix3d& covariance) {
  const std::optional<PreparedPose> pose = prep_.add({utime, T_map_base, covariance});
  counters_.prep = prep_.counters();
  if (!pose) return std::nullopt;
  return take_pose(*pose);
}

std::optional<BackendUpdate> Backend::take_pose(const PreparedPose& pose) {
  if (!since_key_.empty()) previous_ = since_key_.back();
  since_key_.push_back(pose);
  const bool first = key_poses_.empty() && since_key_.size() == 1;
  std::vector<StampedPose> since;
  for (const PreparedPose& p : since_key_) since.push_back({p.utime, p.T_world_base});
  const std::vector<int> keys = select_key_poses(since, config_.key_poses);
  if (!first && keys.back() != static_cast<int>(since_key_.size()) - 1) return std::nullopt;

  // The scan this pose belongs to: the one ending at the pose's time (older ones are dropped).
  const int64_t utime = pose.utime;
  while (!pending_scans_.empty() && pending_scans_.front().utime_last < utime) {
    pending_scans_.pop_front();
  }
  if (pending_scans_.empty() || pending_scans_.front().utime_last != utime) {
    ++counters_.key_poses_without_scan;  // try again with the next pose
    return std::nullopt;
  }
  add_key_pose(pending_scans_.front());
  pending_scans_.pop_front();
  since_key_.assign(1, since_key_.back());

  const int current = static_cast<int>(key_poses_.size()) - 1;
  std::vector<double> travel(key_poses_.size());
  for (std::size_t i = 0; i < travel.size(); ++i) travel[i] = key_poses_[i].travel_m;
  std::vector<Eigen::Matrix3d> marginals(key_poses_.size());
  for (std::size_t i = 0; i < marginals.size(); ++i) marginals[i] = key_poses_[i].covariance;
  const std::optional<LoopClosure> closure =
      loop_.add(current, graph_.poses, travel, scans_, &marginals);
  if (closure) add_closure(*closure);
  if (closure || current % config_.optimize_every == 0) return optimise();
  return std::nullopt;
}

Edge Backend::frontend_edge(int from, int to) const {
  const PreparedPose& a = last_key_;
  const PreparedPose& b = since_key_.back();
  Edge edge;
  edge.from = from;
  edge.to = to;
  edge.T_from_to = between(a.T_world_base, b.T_world_base);
  const double sxy = config_.frontend_sigma_xy_m, sth = config_.frontend_sigma_theta_rad;
  Eigen::Matrix3d covariance = Eigen::Vector3d(sxy * sxy, sxy * sxy, sth * sth).asDiagonal();
  // A pose without a covariance (the frontend's first, which defines its map) takes the other's.
  const auto usable = [](const Eigen::Matrix3d& C) { return !C.isZero() && C.allFinite(); };
  const Eigen::Matrix3d& Ca =
      usable(a.frontend.covariance) ? a.frontend.covariance : b.frontend.covariance;
  const Eigen::Matrix3d& Cb = usable(b.frontend.covariance) ? b.frontend.covariance : Ca;
  if (config_.frontend_covariance && usable(Ca) && usable(Cb)) {
    // Each pose's error in the frontend's map frame, turned into the prepared frame (they differ
    // by the jumps smoothed away), carried through the relative pose: J_a C_a J_a^T + J_b C_b
    // J_b^T with the edge error's Jacobians (pose_graph.hpp).
    const auto in_world = [](const PreparedPose& p, const Eigen::Matrix3d& C) {
      const Eigen::Matrix3d R = rotation3(p.T_world_base.theta() - p.frontend.T_map_base.theta());
      return Eigen::Matrix3d(R * C * R.transpose());
    };
    Eigen::Matrix3d J_a, J_b;
    edge_jacobians(a.T_world_base, b.T_world_base, edge.T_from_to, J_a, J_b);
    covariance = config_.frontend_covariance_scale * (J_a * in_world(a, Ca) * J_a.transpose() +
                                                      J_b * in_world(b, Cb) * J_b.transpose());
    const double travel = std::max(0.0, b.travel_m - a.travel_m);
    covariance += travel * Eigen::Vector3d(std::pow(config_.frontend_drift_xy_m, 2),
                                           std::pow(config_.frontend_drift_xy_m, 2),
                                           std::pow(config_.frontend_drift_theta_rad, 2))
                               .asDiagonal();
  }
  edge.information = covariance.inverse();
  return edge;
}

void Backend::add_key_pose(const PlanarScan& scan) {
  const PreparedPose& now = since_key_.back();
  // Motion during the sweep, relative to the key pose: the last prepared step, at constant
  // velocity (the frontend publishes one pose per sweep), unless the poses come seconds apart
  // (a log subsampled by travel: the step says nothing about the motion during one sweep).
  Eigen::Vector3d rate = Eigen::Vector3d::Zero();  // tangent per microsecond
  if (previous_ && !now.sparse) {
    const double dt = static_cast<double>(std::max<int64_t>(1, now.utime - previous_->utime));
    rate = between(previous_->T_world_base, now.T_world_base).log() / dt;
  }
  const auto T_ref_base = [&](int64_t t) {
    return Pose2::exp(rate * static_cast<double>(t - now.utime));
  };
  const int index = scans_.add(reduce_scan(scan, T_base_laser_, T_ref_base, config_.scans));

  KeyPose key;
  key.utime = now.utime;
  key.travel_m = now.travel_m;
  if (index == 0) {
    graph_.add_vertex(index, now.T_world_base, true);
  } else {
    // Link to the previous key pose: match against the last few key scans around the frontend's
    // relative motion.
    const int prev = index - 1;
    const Pose2 T_world_guess =
        graph_.poses[prev] * between(last_key_.T_world_base, now.T_world_base);
    std::vector<Eigen::Vector2d> reference;
    for (int j = std::max(0, index - config_.link_chain_length); j < index; ++j) {
      scans_.append_world(j, graph_.poses[j], reference);
    }
    const MatchResult m = link_matcher_.match(reference, scans_.points_d(index), T_world_guess);
    const bool frontend =
        config_.frontend_sigma_xy_m > 0.0 && config_.frontend_sigma_theta_rad > 0.0;
    const Edge motion = frontend_edge(prev, index);
    Edge link;
    link.from = prev;
    link.to = index;
    bool linked = false;
    if (m.valid && m.raw_response >= config_.min_link_response) {
      Pose2 T_world_key = m.T_world_query;
      if (config_.link_refine.enabled) {
        const RefineResult r = link_refiner_.refine(reference, scans_.points_d(index), T_world_key);
        if (r.valid) {
          ++counters_.links_refined;
          T_world_key = r.T_world_query;
        }
      }
      link.T_from_to = between(graph_.poses[prev], T_world_key);
      const Eigen::Matrix3d covariance =
          config_.link_covariance_scale * to_pose_frame(m.covariance, T_world_key);
      link.information = covariance.inverse();
      // The match must agree with the frontend's motion within their covariances: a scan that
      // fits the last few elsewhere (a corridor, a turn the chain has not seen) is left out.
      linked = true;
      if (frontend && config_.link_max_mahalanobis > 0.0) {
        const Eigen::Vector3d d = edge_error(Pose2(), link.T_from_to, motion.T_from_to);
        const Eigen::Matrix3d S = covariance + motion.information.inverse();
        if (std::sqrt(d.dot(S.ldlt().solve(d))) > config_.link_max_mahalanobis) {
          ++counters_.links_rejected_inconsistent;
          linked = false;
        }
      }
      if (linked) ++counters_.links_matched;
    }
    if (!linked && !frontend) {
      ++counters_.links_fallback;
      const double sxy = config_.fallback_sigma_xy_m, sth = config_.fallback_sigma_theta_rad;
      link.T_from_to = between(graph_.poses[prev], T_world_guess);
      link.information =
          Eigen::Vector3d(1.0 / (sxy * sxy), 1.0 / (sxy * sxy), 1.0 / (sth * sth)).asDiagonal();
      linked = true;
    }
    graph_.add_vertex(index, graph_.poses[prev] * (linked ? link.T_from_to : motion.T_from_to));
    if (linked) {
      graph_.edges.push_back(link);
      edge_kinds_.push_back(EdgeKind::kLink);
    }
    if (frontend) {
      graph_.edges.push_back(motion);
      edge_kinds_.push_back(EdgeKind::kFrontend);
    }
    key.covariance = key_poses_.back().covariance;  // until the next optimisation
  }
  key_poses_.push_back(key);
  last_key_ = now;
}

void Backend::add_closure(const LoopClosure& closure) {
  Edge edge;
  edge.from = closure.from;
  edge.to = closure.to;
  edge.T_from_to = closure.T_from_to;
  edge.information = closure.covariance.inverse();
  graph_.edges.push_back(edge);
  edge_kinds_.push_back(EdgeKind::kClosure);
  closures_.push_back(closure);
}

std::optional<BackendUpdate> Backend::optimise() {
  BackendUpdate update;
  const auto t0 = std::chrono::steady_clock::now();
  update.spa = spa_.optimize(graph_);
  update.optimisation_s = seconds_since(t0);
  const auto t1 = std::chrono::steady_clock::now();
  const auto marginals = spa_.marginals(graph_);
  update.marginals_s = seconds_since(t1);
  if (marginals) {
    for (std::size_t i = 0; i < key_poses_.size(); ++i) key_poses_[i].covariance = (*marginals)[i];
  }
  ++counters_.optimisations;
  // A graph of the fixed first key pose alone has nothing to optimise.
  if (key_poses_.size() > 1 && (!update.spa.converged || !marginals)) {
    ++counters_.optimisations_failed;
  }
  counters_.last_optimisation_s = update.optimisation_s;
  counters_.total_optimisation_s += update.optimisation_s;
  update.optimisation = ++optimisations_;
  for (int i = first_unreported_key_; i < static_cast<int>(key_poses_.size()); ++i) {
    update.new_key_poses.push_back(i);
  }
  first_unreported_key_ = static_cast<int>(key_poses_.size());
  update.new_closures.assign(closures_.begin() + static_cast<long>(first_unreported_closure_),
                             closures_.end());
  first_unreported_closure_ = closures_.size();
  return update;
}

std::optional<BackendUpdate> Backend::finish() {
  std::optional<BackendUpdate> last;
  if (const std::optional<PreparedPose> pose = prep_.finish()) last = take_pose(*pose);
  const std::optional<LoopClosure> closure = loop_.finish();
  if (closure) add_closure(*closure);
  if (key_poses_.empty()) return std::nullopt;
  if (closure || first_unreported_key_ < static_cast<int>(key_poses_.size())) {
    std::optional<BackendUpdate> update = optimise();
    if (last && update) {  // one update reports both
      update->new_key_poses.insert(update->new_key_poses.begin(), last->new_key_poses.begin(),
                                   last->new_key_poses.end());
      update->new_closures.insert(update->new_closures.begin(), last->new_closures.begin(),
                                  last->new_closures.end());
    }
    return update;
  }
  return last;
}

}  // namespace traverse::backend
