#include "backend.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <chrono>
#include <cmath>
#include <cstdlib>

#include "config.hpp"
#include "frontend_chain.hpp"

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
  check.in_range("link_degeneracy_min_ratio", c.link_degeneracy_min_ratio, 0.0, 1.0);
  check.positive("link_open_sigma_m", c.link_open_sigma_m);
  check.positive("fallback_sigma_xy_m", c.fallback_sigma_xy_m);
  check.positive("fallback_sigma_theta_rad", c.fallback_sigma_theta_rad);
  check.not_negative("frontend_sigma_xy_m", c.frontend_sigma_xy_m);
  check.not_negative("frontend_sigma_theta_rad", c.frontend_sigma_theta_rad);
  check.positive("link_covariance_scale", c.link_covariance_scale);
  check.positive("frontend_covariance_scale", c.frontend_covariance_scale);
  check.not_negative("frontend_drift_length_m", c.frontend_drift_length_m);
  check.not_negative("frame_heading_sigma_rad", c.frame_heading_sigma_rad);
  check.not_negative("key_pose_sigma_xy_m", c.key_pose_sigma_xy_m);
  check.positive("marginal_scale", c.marginal_scale);
  check.positive("marginal_frontend_scale", c.marginal_frontend_scale);
  check.nested("boresight", validate(c.boresight));
  check.nested("start_frame", validate(c.start_frame));
  check.nested("odometry", validate(c.odometry));
  check.nested("loop", validate(c.loop));
  check.not_negative("closure_max_chi2_increase", c.closure_max_chi2_increase);
  check.nested("spa", validate(c.spa));
  check.positive("optimize_every", c.optimize_every);
  check.positive("max_pending_scans", c.max_pending_scans);
  return check.problem();
}

Backend::Backend(BackendConfig config)
    : config_(std::move(config)),
      drift_model_(config_.frontend_drift_length_m > 0.0 && frontend_edges()),
      T_base_laser_(config_.T_base_laser.pose()),
      link_matcher_(config_.link),
      link_refiner_(config_.link_refine),
      loop_(config_.loop),
      odometry_(config_.odometry),
      spa_(config_.spa),
      trial_spa_(config_.spa),
      boresight_(config_.boresight),
      start_frame_(config_.start_frame),
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
  std::vector<Pose2> poses(key_poses_.size());
  for (std::size_t i = 0; i < poses.size(); ++i) poses[i] = key_poses_[i].T_world_base;
  const std::optional<LoopClosure> closure = loop_.add(current, poses, travel, scans_, &marginals);
  if (closure) add_closure(*closure);
  if (closure || current % config_.optimize_every == 0) return optimise();
  return std::nullopt;
}

Pose2 Backend::published_pose(int i) const {
  const Pose2& first = key_poses_[0].T_world_base;
  const Pose2 T = i == 0 ? first : start_frame_.published(key_poses_[i].T_world_base, first);
  return boresight_.published(T, first);
}

Eigen::Matrix3d Backend::published_covariance(int i) const {
  if (i == 0) return Eigen::Matrix3d::Zero();
  // A turn of the frame by d rad about the first key pose moves key pose i by J d.
  const Eigen::Vector2d r = published_pose(i).translation() - published_pose(0).translation();
  const Eigen::Vector3d J(-r.y(), r.x(), 1.0);
  const double sf =
      boresight_.yaw_rad() ? boresight_.yaw_sigma_rad() : config_.frame_heading_sigma_rad;
  const double sp = config_.key_pose_sigma_xy_m;
  const Eigen::Matrix3d in_frame =
      rotate_covariance(key_poses_[i].calibrated_covariance,
                        Pose2(0.0, 0.0, -start_frame_.heading_rad().value_or(0.0)).rotation());
  return config_.marginal_scale * boresight_.published(in_frame) + sf * sf * J * J.transpose() +
         Eigen::Vector3d(sp * sp, sp * sp, 0.0).asDiagonal().toDenseMatrix();
}

std::pair<Eigen::Matrix3d, Eigen::Matrix3d> Backend::frontend_covariances() const {
  const double sxy = config_.frontend_sigma_xy_m, sth = config_.frontend_sigma_theta_rad;
  const Eigen::Matrix3d fixed = Eigen::Vector3d(sxy * sxy, sxy * sxy, sth * sth).asDiagonal();
  const double scale = config_.frontend_covariance ? config_.frontend_covariance_scale : 0.0;
  const auto covariance = [&](const PreparedPose& p) {
    return scale > 0.0 ? frontend_pose_covariance(p, scale, fixed) : fixed;
  };
  const PreparedPose& a = last_key_;
  const PreparedPose& b = since_key_.back();
  const Eigen::Matrix3d cb = covariance(b);
  // The frontend's first pose defines its map and carries no covariance: it takes its
  // neighbour's.
  if (scale > 0.0 && a.frontend.covariance.isZero()) return {cb, cb};
  return {covariance(a), cb};
}

void Backend::add_frontend_edges(int key, const std::optional<OdometryStep>& odometry) {
  const PreparedPose& a = last_key_;
  const PreparedPose& b = since_key_.back();
  const auto [ca, cb] = frontend_covariances();
  const int from = drift_model_ ? key_vertex(key - 1) + 1 : key_vertex(key - 1);
  const int to = drift_model_ ? key_vertex(key) + 1 : key_vertex(key);
  Edge step;       // between the key poses, as published
  if (odometry) {  // the odometry's step instead of the frontend's
    Edge edge;
    edge.from = from;
    edge.to = to;
    edge.T_from_to = odometry->motion;
    edge.information = odometry->covariance.inverse();
    graph_.edges.push_back(edge);
    edge_kinds_.push_back(drift_model_ ? EdgeKind::kFrontendDrift : EdgeKind::kFrontend);
    step = edge;
  } else if (!drift_model_) {
    graph_.edges.push_back(motion_edge(from, to, a, b, ca, cb));
    edge_kinds_.push_back(EdgeKind::kFrontend);
    step = graph_.edges.back();
  } else {
    graph_.edges.push_back(drift_edge(from, to, a, b, ca, cb, config_.frontend_drift_length_m));
    edge_kinds_.push_back(EdgeKind::kFrontendDrift);
    step = key_step_edge(from, to, a, b, ca, cb, config_.frontend_drift_length_m);
  }
  key_edges_.push_back({key - 1, key, EdgeKind::kFrontend, step.T_from_to, step.information});
  if (!drift_model_) return;
  const int m_b = to;
  Edge pose;
  pose.from = m_b;
  pose.to = key_vertex(key);
  pose.information = cb.inverse();
  graph_.edges.push_back(pose);
  edge_kinds_.push_back(EdgeKind::kFrontendPose);
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
  // The scan store and the graph are changed only at the end, together, so that they stay in
  // step even if anything before throws.
  std::vector<Eigen::Vector2f> points = reduce_scan(scan, T_base_laser_, T_ref_base, config_.scans);
  const int index = scans_.size();

  KeyPose key;
  key.utime = now.utime;
  key.travel_m = now.travel_m;
  const bool frontend = frontend_edges();
  if (index == 0) {
    key.T_world_base = now.T_world_base;
    graph_.add_vertex(key_vertex(0), now.T_world_base, true);
    // The drifting frontend starts where the key poses do: both are fixed there.
    if (drift_model_) graph_.add_vertex(key_vertex(0) + 1, now.T_world_base, true);
  } else {
    const int prev = index - 1;
    const KeyStep step = link_key(index, points, now);
    key.T_world_base =
        key_poses_[prev].T_world_base * (step.link ? step.link->T_from_to : step.motion);
    graph_.add_vertex(key_vertex(index), key.T_world_base);
    if (drift_model_) {
      graph_.add_vertex(key_vertex(index) + 1, graph_.poses[key_vertex(prev) + 1] * step.motion);
    }
    if (step.link) {
      graph_.edges.push_back(*step.link);
      edge_kinds_.push_back(EdgeKind::kLink);
      key_edges_.push_back(
          {prev, index, EdgeKind::kLink, step.link->T_from_to, step.link->information});
    }
    if (frontend) add_frontend_edges(index, step.odometry);
    key.covariance = key_poses_.back().covariance;  // until the next optimisation
    key.calibrated_covariance = key_poses_.back().calibrated_covariance;
    // A step netted over a spike is not the start of another.
    step_before_from_odometry_.reset();
    if (step.odometry && !step.netted) step_before_from_odometry_ = step.odometry->motion;
  }
  scans_.add(std::move(points));
  key_poses_.push_back(key);
  key_before_last_ = last_key_;
  last_key_ = now;
}

void Backend::add_closure(LoopClosure closure) {
  Edge edge;
  edge.from = key_vertex(closure.from);
  edge.to = key_vertex(closure.to);
  edge.T_from_to = closure.T_from_to;
  edge.information = closure.covariance.inverse();
  if (config_.closure_max_chi2_increase > 0.0) {
    // The graph at its optimum without the closure, and a copy with it: the growth of chi2 is
    // the closure's disagreement with everything else, weighed by both covariances.
    const SpaResult without = spa_.optimize(graph_);
    PoseGraph trial = graph_;
    trial.edges.push_back(edge);
    const SpaResult with = trial_spa_.optimize(trial);
    closure.chi2_increase = with.final_chi2 - without.final_chi2;
    if (!(closure.chi2_increase <= config_.closure_max_chi2_increase)) {
      ++counters_.closures_rejected_inconsistent;
      return;
    }
    graph_ = std::move(trial);
  } else {
    graph_.edges.push_back(edge);
  }
  edge_kinds_.push_back(EdgeKind::kClosure);
  key_edges_.push_back(
      {closure.from, closure.to, EdgeKind::kClosure, edge.T_from_to, edge.information});
  closures_.push_back(closure);
}

PoseGraph Backend::calibrated_graph() const {
  PoseGraph graph = graph_;
  for (std::size_t k = 0; k < graph.edges.size(); ++k) {
    if (frontend_chain(edge_kinds_[k])) {
      graph.edges[k].information /= config_.marginal_frontend_scale;
    }
  }
  return graph;
}

std::optional<BackendUpdate> Backend::optimise() {
  BackendUpdate update;
  const auto t0 = std::chrono::steady_clock::now();
  update.spa = spa_.optimize(graph_);
  update.optimisation_s = seconds_since(t0);
  const auto t1 = std::chrono::steady_clock::now();
  const auto marginals = spa_.marginals(graph_);
  std::optional<std::vector<Eigen::Matrix3d>> calibrated = marginals;
  if (config_.marginal_frontend_scale != 1.0) {
    PoseGraph graph = calibrated_graph();
    calibrated = spa_.marginals(graph);
  }
  update.marginals_s = seconds_since(t1);
  std::vector<Pose2> poses(key_poses_.size());
  for (int i = 0; i < static_cast<int>(key_poses_.size()); ++i) {
    key_poses_[i].T_world_base = poses[i] = graph_.poses[key_vertex(i)];
    if (marginals) key_poses_[i].covariance = (*marginals)[key_vertex(i)];
    if (calibrated) key_poses_[i].calibrated_covariance = (*calibrated)[key_vertex(i)];
  }
  boresight_.update(poses);
  std::vector<double> travel(key_poses_.size());
  for (std::size_t i = 0; i < travel.size(); ++i) travel[i] = key_poses_[i].travel_m;
  start_frame_.update(poses, travel, scans_, link_matcher_, link_refiner_);
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

std::string Backend::input_fault() const {
  const long poses = counters_.prep.poses, dropped = counters_.prep.out_of_order;
  if (poses < 2) return {};
  const std::size_t keys = key_poses_.size();
  if (keys >= 2 && 2 * dropped <= poses) return {};
  return std::to_string(dropped) + " of " + std::to_string(poses) +
         " frontend poses were not later than the pose before (stamps that carry no time?), " +
         std::to_string(keys) + " key pose" + (keys == 1 ? "" : "s") + ": no trajectory";
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
