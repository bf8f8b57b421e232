#include "backend.hpp"

#include <Eigen/LU>
#include <chrono>
#include <cmath>
#include <cstdlib>

#include "config.hpp"

namespace traverse::backend {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

std::optional<std::string> validate(const BackendConfig& c) {
  ConfigCheck check;
  check.nested("T_base_laser", validate(c.T_base_laser));
  check.nested("smoothing", validate(c.smoothing));
  check.nested("key_poses", validate(c.key_poses));
  check.nested("scans", validate(c.scans));
  check.nested("link", validate(c.link));
  check.nested("link_refine", validate(c.link_refine));
  check.in_range("link_chain_length", c.link_chain_length, 1, 1000);
  check.in_range("min_link_response", c.min_link_response, 0.0, 1.0);
  check.positive("fallback_sigma_xy_m", c.fallback_sigma_xy_m);
  check.positive("fallback_sigma_theta_rad", c.fallback_sigma_theta_rad);
  check.not_negative("frontend_sigma_xy_m", c.frontend_sigma_xy_m);
  check.not_negative("frontend_sigma_theta_rad", c.frontend_sigma_theta_rad);
  check.nested("loop", validate(c.loop));
  check.nested("spa", validate(c.spa));
  check.positive("optimize_every", c.optimize_every);
  check.positive("max_pending_scans", c.max_pending_scans);
  return check.problem();
}

Backend::Backend(BackendConfig config)
    : config_(std::move(config)),
      T_base_laser_(config_.T_base_laser.pose()),
      link_matcher_(config_.link),
      link_refiner_(config_.link_refine),
      loop_(config_.loop),
      spa_(config_.spa) {}

void Backend::add_scan(PlanarScan scan) {
  ++counters_.scans;
  pending_scans_.push_back(std::move(scan));
  while (static_cast<int>(pending_scans_.size()) > config_.max_pending_scans) {
    pending_scans_.pop_front();
  }
}

Pose2 Backend::smooth(int64_t utime, const Pose2& T_map_base) {
  if (tail_.empty()) {
    last_raw_ = T_map_base;
    tail_.push_back({utime, T_map_base});
    return T_map_base;
  }
  // The smoothing compares the newest raw step with the preceding (already smoothed) steps.
  std::vector<StampedPose> window = tail_;
  window.push_back({utime, tail_.back().T_world_base * between(last_raw_, T_map_base)});
  const SmoothedTrajectory s = smooth_jumps(window, config_.smoothing);
  const int n = static_cast<int>(s.poses.size());
  if (!s.replaced_steps.empty() && s.replaced_steps.back() == n - 1) ++counters_.jumps_smoothed;
  const Pose2 smoothed =
      tail_.back().T_world_base * between(s.poses[n - 2].T_world_base, s.poses[n - 1].T_world_base);
  last_raw_ = T_map_base;
  tail_.push_back({utime, smoothed});
  if (static_cast<int>(tail_.size()) > config_.smoothing.window + 1) tail_.erase(tail_.begin());
  travel_m_ += (smoothed.translation() - tail_[tail_.size() - 2].T_world_base.translation()).norm();
  return smoothed;
}

bool Backend::is_outlier(const StampedPose& held, const StampedPose& next) const {
  if (tail_.empty()) return false;
  // The two raw steps appended to the smoothed tail, as smooth() would append them.
  std::vector<StampedPose> window = tail_;
  window.push_back({held.utime, tail_.back().T_world_base * between(last_raw_, held.T_world_base)});
  window.push_back({next.utime, tail_.back().T_world_base * between(last_raw_, next.T_world_base)});
  const SmoothedTrajectory s = smooth_jumps(std::move(window), config_.smoothing);
  return !s.outliers.empty() && s.outliers.back() == static_cast<int>(tail_.size());
}

std::optional<BackendUpdate> Backend::add_pose(int64_t utime, const Pose2& T_map_base) {
  ++counters_.poses;
  const StampedPose next{utime, T_map_base};
  if (!held_) {
    held_ = next;
    return std::nullopt;
  }
  StampedPose pose = *held_;
  held_ = next;
  if (is_outlier(pose, next)) {
    ++counters_.outliers_replaced;
    const double s = static_cast<double>(pose.utime - last_key_input_utime_) /
                     static_cast<double>(std::max<int64_t>(1, next.utime - last_key_input_utime_));
    pose.T_world_base = interpolate(last_raw_, next.T_world_base, s);
  }
  return take_pose(pose.utime, pose.T_world_base);
}

std::optional<BackendUpdate> Backend::take_pose(int64_t utime, const Pose2& T_map_base) {
  last_key_input_utime_ = utime;
  const Pose2 smoothed = smooth(utime, T_map_base);
  since_key_.push_back({utime, smoothed});
  const bool first = key_poses_.empty() && since_key_.size() == 1;
  const std::vector<int> keys = select_key_poses(since_key_, config_.key_poses);
  if (!first && keys.back() != static_cast<int>(since_key_.size()) - 1) return std::nullopt;

  // The scan this pose belongs to: the one ending at the pose's time (older ones are dropped).
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

void Backend::add_key_pose(const PlanarScan& scan) {
  const StampedPose& now = tail_.back();
  // Motion during the sweep, relative to the key pose: the last smoothed step, at constant
  // velocity (the frontend publishes one pose per sweep).
  Eigen::Vector3d rate = Eigen::Vector3d::Zero();  // tangent per microsecond
  if (tail_.size() >= 2) {
    const StampedPose& prev = tail_[tail_.size() - 2];
    const double dt = static_cast<double>(std::max<int64_t>(1, now.utime - prev.utime));
    rate = between(prev.T_world_base, now.T_world_base).log() / dt;
  }
  const auto T_ref_base = [&](int64_t t) {
    return Pose2::exp(rate * static_cast<double>(t - now.utime));
  };
  const int index = scans_.add(reduce_scan(scan, T_base_laser_, T_ref_base, config_.scans));

  KeyPose key;
  key.utime = now.utime;
  key.travel_m = travel_m_;
  if (index == 0) {
    graph_.add_vertex(index, now.T_world_base, true);
  } else {
    // Link to the previous key pose: match against the last few key scans around the frontend's
    // relative motion.
    const int prev = index - 1;
    const Pose2 T_world_guess = graph_.poses[prev] * between(last_key_smoothed_, now.T_world_base);
    std::vector<Eigen::Vector2d> reference;
    for (int j = std::max(0, index - config_.link_chain_length); j < index; ++j) {
      scans_.append_world(j, graph_.poses[j], reference);
    }
    const MatchResult m = link_matcher_.match(reference, scans_.points_d(index), T_world_guess);
    Pose2 T_world_key = T_world_guess;
    Eigen::Matrix3d covariance;
    if (m.valid && m.raw_response >= config_.min_link_response) {
      ++counters_.links_matched;
      T_world_key = m.T_world_query;
      if (config_.link_refine.enabled) {
        const RefineResult r = link_refiner_.refine(reference, scans_.points_d(index), T_world_key);
        if (r.valid) {
          ++counters_.links_refined;
          T_world_key = r.T_world_query;
        }
      }
      // The matcher's covariance is in the world frame; the edge error's in the key pose's.
      covariance = rotate_covariance(m.covariance, T_world_key.rotation().transpose());
    } else {
      ++counters_.links_fallback;
      const double sxy = config_.fallback_sigma_xy_m, sth = config_.fallback_sigma_theta_rad;
      covariance = Eigen::Vector3d(sxy * sxy, sxy * sxy, sth * sth).asDiagonal();
    }
    graph_.add_vertex(index, T_world_key);
    Edge edge;
    edge.from = prev;
    edge.to = index;
    edge.T_from_to = between(graph_.poses[prev], T_world_key);
    edge.information = covariance.inverse();
    graph_.edges.push_back(edge);
    if (config_.frontend_sigma_xy_m > 0.0 && config_.frontend_sigma_theta_rad > 0.0) {
      const double sxy = config_.frontend_sigma_xy_m, sth = config_.frontend_sigma_theta_rad;
      edge.T_from_to = between(last_key_smoothed_, now.T_world_base);
      edge.information =
          Eigen::Vector3d(1.0 / (sxy * sxy), 1.0 / (sxy * sxy), 1.0 / (sth * sth)).asDiagonal();
      graph_.edges.push_back(edge);
    }
    key.covariance = key_poses_.back().covariance;  // until the next optimisation
  }
  key_poses_.push_back(key);
  last_key_smoothed_ = now.T_world_base;
}

void Backend::add_closure(const LoopClosure& closure) {
  Edge edge;
  edge.from = closure.from;
  edge.to = closure.to;
  edge.T_from_to = closure.T_from_to;
  edge.information = closure.covariance.inverse();
  graph_.edges.push_back(edge);
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
  if (held_) {
    const StampedPose pose = *held_;
    held_.reset();
    last = take_pose(pose.utime, pose.T_world_base);
  }
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
