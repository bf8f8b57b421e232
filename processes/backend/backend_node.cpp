#include "backend_node.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "config.hpp"
#include "scan_message.hpp"
#include "traverse/key_poses_t.hpp"
#include "traverse/pose_graph_edges_t.hpp"

namespace traverse::backend {
namespace {

void copy_matrix(const Eigen::Matrix3d& m, double out[9]) {
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) out[3 * r + c] = m(r, c);
  }
}

}  // namespace

std::optional<std::string> validate(const BackendNodeConfig& c) {
  ConfigCheck check;
  check.not_empty("scan_channel", c.scan_channel);
  check.not_empty("pose_channel", c.pose_channel);
  check.not_empty("key_poses_channel", c.key_poses_channel);
  check.not_empty("trajectory_channel", c.trajectory_channel);
  check.not_empty("edges_channel", c.edges_channel);
  check.nested("resend", validate(c.resend));
  check.in_range("max_poses_per_message", c.max_poses_per_message, 1, 580);
  check.not_negative("publish_move_m", c.publish_move_m);
  check.not_negative("publish_turn_rad", c.publish_turn_rad);
  check.not_negative("publish_covariance_change", c.publish_covariance_change);
  check.in_range("state_period_s", c.state_period_s, 0.0, 3600.0);
  check.nested("backend", validate(c.backend));
  return check.problem();
}

BackendNode::BackendNode(Bus& bus, const BackendNodeConfig& config, CounterSink counters,
                         const std::string& state_dir)
    : bus_(bus), config_(config), backend_(config.backend), counters_(std::move(counters)) {
  if (!state_dir.empty()) {
    state_.emplace(state_dir, std::llround(config_.state_period_s * 1e6), config_.state_durable);
    resumed_ = state_->resume(backend_);
  }
  bus_.subscribe<planar_scan_t>(config_.scan_channel,
                                [this](const planar_scan_t& m) { on_scan(m); });
  bus_.subscribe<pose2d_t>(config_.pose_channel, [this](const pose2d_t& m) { on_pose(m); });
  if (!config_.odometry_channel.empty()) {
    bus_.subscribe<odometry_t>(config_.odometry_channel,
                               [this](const odometry_t& m) { on_odometry(m); });
  }
  // The answer goes to every listener, and one that still lacks something asks again after the
  // next optimisation: one answer per channel per resend.pace_s serves all who asked.
  ResendPacing pacing{
      config_.resend.pace_us(),
      [this] {
        return published_.empty() ? int64_t{0} : backend_.key_poses()[published_.size() - 1].utime;
      },
      ResendPacing::Scope::kChannel};
  resend_ = std::make_unique<ResendAnswerer>(
      bus_, std::vector<std::string>{config_.edges_channel, config_.key_poses_channel},
      [this](const ResendRequest& r) { return answer_resend(r); }, std::move(pacing));
}

bool BackendNode::answer_resend(const ResendRequest& request) {
  // The graph as last published: key poses and edges added since wait for the next update.
  const std::size_t n_keys = published_.size();
  // An empty graph needs no answer: the listener gets all of it from the updates to come.
  if (n_keys == 0) return false;
  // Edges first, as with the updates: a listener that has them when the key poses come can
  // compute its local bounds at once.
  for (const std::string& channel : request.named) {
    if (channel == config_.edges_channel) {
      publish_edges(0, edges_published_, last_update_.optimisation,
                    channels::full_channel(channel));
    } else {
      std::vector<int> all(n_keys);
      std::iota(all.begin(), all.end(), 0);
      publish_key_poses(all, n_keys, last_update_, channels::full_channel(channel));
    }
  }
  return true;
}

void BackendNode::on_odometry(const odometry_t& msg) {
  if (!std::isfinite(msg.x) || !std::isfinite(msg.y) || !std::isfinite(msg.theta)) return;
  backend_.add_odometry(msg.utime, Pose2(msg.x, msg.y, msg.theta));
}

void BackendNode::on_scan(const planar_scan_t& msg) { backend_.add_scan(to_planar_scan(msg)); }

void BackendNode::on_pose(const pose2d_t& msg) {
  if (!std::isfinite(msg.x) || !std::isfinite(msg.y) || !std::isfinite(msg.theta)) return;
  // A scan stamped late: its pose is not the base's at its stamp, and the steps to it and from
  // it are no motion (the key poses follow the trajectory in time).
  if (msg.flags & pose2d_t::FLAG_LATE) {
    ++poses_late_;
    return;
  }
  Eigen::Matrix3d covariance;
  for (int i = 0; i < 9; ++i) covariance(i / 3, i % 3) = msg.covariance[i];
  if (auto update = backend_.add_pose(msg.utime, Pose2(msg.x, msg.y, msg.theta), covariance)) {
    publish(*update);
  }
}

void BackendNode::finish() {
  if (auto update = backend_.finish()) publish(*update);
  if (state_) state_->persist(backend_, true);
}

bool BackendNode::changed(int i) const {
  if (i >= static_cast<int>(published_.size())) return true;
  const Published& p = published_[i];
  const Pose2 T = backend_.published_pose(i);
  if ((T.translation() - p.T_world_base.translation()).norm() > config_.publish_move_m) return true;
  if (std::abs(wrap_angle(T.theta() - p.T_world_base.theta())) > config_.publish_turn_rad) {
    return true;
  }
  const Eigen::Vector3d v = backend_.published_covariance(i).diagonal();
  for (int k = 0; k < 3; ++k) {
    if (std::abs(v[k] - p.variances[k]) >
        config_.publish_covariance_change * std::abs(p.variances[k]))
      return true;
  }
  return false;
}

// The key-pose edges [first, last) (Backend::key_edges: the drift model's auxiliary vertices are
// not published).
void BackendNode::publish_edges(std::size_t first, std::size_t last, int32_t optimisation,
                                const std::string& channel) {
  const std::vector<KeyEdge>& edges = backend_.key_edges();
  const std::vector<KeyPose>& keys = backend_.key_poses();
  // 125 bytes per edge: at most 500 keep a part under 64 KB.
  const std::size_t per = static_cast<std::size_t>(std::min(config_.max_poses_per_message, 500));
  const int parts = static_cast<int>((last - first + per - 1) / per);
  for (int part = 0; part < parts; ++part) {
    pose_graph_edges_t msg{};
    msg.utime = keys.back().utime;
    msg.optimisation = optimisation;
    msg.part = part;
    msg.parts = parts;
    msg.total_edges = static_cast<int32_t>(last);
    msg.first_index = static_cast<int32_t>(first + part * per);
    for (std::size_t k = msg.first_index; k < std::min(last, first + (part + 1) * per); ++k) {
      const KeyEdge& e = edges[k];
      pose_graph_edge_t m{};
      m.utime = keys[e.to].utime;
      m.index = static_cast<int32_t>(k);
      m.from_id = e.from;
      m.to_id = e.to;
      m.kind = e.kind == EdgeKind::kClosure    ? pose_graph_edge_t::KIND_LOOP_CLOSURE
               : e.kind == EdgeKind::kFrontend ? pose_graph_edge_t::KIND_FRONTEND
                                               : pose_graph_edge_t::KIND_LINK;
      m.x = e.T_from_to.x();
      m.y = e.T_from_to.y();
      m.theta = e.T_from_to.theta();
      // The edges as the published marginals see them (BackendConfig::marginal_scale, and
      // marginal_frontend_scale on the frontend's).
      const BackendConfig& c = backend_.config();
      const double scale =
          c.marginal_scale * (frontend_chain(e.kind) ? c.marginal_frontend_scale : 1.0);
      copy_matrix(e.information / scale, m.information);
      msg.edges.push_back(m);
    }
    msg.n_edges = static_cast<int32_t>(msg.edges.size());
    bus_.publish(channel, msg);
  }
}

void BackendNode::publish(const BackendUpdate& update) {
  const std::vector<KeyPose>& keys = backend_.key_poses();
  if (keys.empty()) return;
  publish_edges(edges_published_, backend_.key_edges().size(), update.optimisation,
                config_.edges_channel);
  edges_published_ = backend_.key_edges().size();
  std::vector<int> changed_ids;
  for (int i = 0; i < static_cast<int>(keys.size()); ++i) {
    if (changed(i)) changed_ids.push_back(i);
  }
  published_.resize(keys.size());
  for (int i : changed_ids) {
    published_[i] = {backend_.published_pose(i), backend_.published_covariance(i).diagonal()};
  }
  publish_key_poses(changed_ids, keys.size(), update, config_.key_poses_channel);
  last_update_ = update;
  last_update_.new_key_poses.clear();
  last_update_.new_closures.clear();

  // The trajectory for evaluators: each new key pose once, at its estimate of this optimisation.
  for (int i : update.new_key_poses) {
    pose2d_t pose{};
    pose.utime = keys[i].utime;
    pose.parent_frame = "map";  // the frontend's frame, which the graph keeps
    pose.child_frame = "base";
    const Pose2 T = backend_.published_pose(i);
    pose.x = T.x();
    pose.y = T.y();
    pose.theta = T.theta();
    copy_matrix(backend_.published_covariance(i), pose.covariance);
    pose.flags = pose2d_t::FLAG_KEY_POSE;
    bus_.publish(config_.trajectory_channel, pose);
  }
  if (state_) state_->persist(backend_);
}

void BackendNode::publish_key_poses(const std::vector<int>& ids, std::size_t n_keys,
                                    const BackendUpdate& update, const std::string& channel) {
  const std::vector<KeyPose>& keys = backend_.key_poses();
  const int per = config_.max_poses_per_message;
  const int parts = std::max(1, static_cast<int>((ids.size() + per - 1) / per));
  const double chi2_now = chi2(backend_.graph());
  for (int part = 0; part < parts; ++part) {
    key_poses_t msg{};
    msg.utime = keys[n_keys - 1].utime;
    msg.optimisation = update.optimisation;
    msg.part = part;
    msg.parts = parts;
    msg.total_key_poses = static_cast<int32_t>(n_keys);
    msg.total_loop_closures = static_cast<int32_t>(backend_.closures().size());
    msg.optimisation_s = update.optimisation_s;
    msg.chi2 = chi2_now;
    const std::size_t lo = static_cast<std::size_t>(part) * per;
    const std::size_t hi = std::min(ids.size(), lo + per);
    for (std::size_t k = lo; k < hi; ++k) {
      const int i = ids[k];
      key_pose_t p{};
      p.utime = keys[i].utime;
      p.id = i;
      const Pose2 T = backend_.published_pose(i);
      p.x = T.x();
      p.y = T.y();
      p.theta = T.theta();
      copy_matrix(backend_.published_covariance(i), p.covariance);
      msg.poses.push_back(p);
    }
    msg.n_poses = static_cast<int32_t>(msg.poses.size());
    if (part == 0) {
      for (const LoopClosure& c : update.new_closures) {
        loop_closure_t l{};
        l.utime = keys[c.to].utime;
        l.from_utime = keys[c.from].utime;
        l.from_id = c.from;
        l.to_id = c.to;
        l.x = c.T_from_to.x();
        l.y = c.T_from_to.y();
        l.theta = c.T_from_to.theta();
        copy_matrix(c.covariance, l.covariance);
        l.response = c.response;
        l.candidates = c.candidates_tried;
        msg.closures.push_back(l);
      }
    }
    msg.n_closures = static_cast<int32_t>(msg.closures.size());
    max_message_bytes_ =
        std::max(max_message_bytes_, static_cast<std::size_t>(msg.getEncodedSize()));
    bus_.publish(channel, msg);
    ++messages_;
  }
}

void BackendNode::report_counters() {
  if (!counters_) return;
  const BackendCounters& c = backend_.counters();
  const LoopCloserCounters& l = backend_.loop_counters();
  counters_("poses_received", static_cast<double>(c.prep.poses));
  counters_("poses_out_of_order", static_cast<double>(c.prep.out_of_order));
  counters_("poses_late", static_cast<double>(poses_late_));
  counters_("poses_sparse", static_cast<double>(c.prep.sparse_poses));
  counters_("scans_received", static_cast<double>(c.scans));
  counters_("jumps_smoothed", static_cast<double>(c.prep.jumps_smoothed));
  counters_("outliers_replaced", static_cast<double>(c.prep.outliers_replaced));
  counters_("key_poses", static_cast<double>(backend_.key_poses().size()));
  counters_("key_poses_without_scan", static_cast<double>(c.key_poses_without_scan));
  counters_("links_matched", static_cast<double>(c.links_matched));
  counters_("links_fallback", static_cast<double>(c.links_fallback));
  counters_("links_opened", static_cast<double>(c.links_opened));
  counters_("links_held", static_cast<double>(c.links_held));
  counters_("links_refined", static_cast<double>(c.links_refined));
  const OdometryCounters& o = backend_.odometry_counters();
  counters_("odometry_readings", static_cast<double>(o.readings));
  counters_("odometry_out_of_order", static_cast<double>(o.readings_out_of_order));
  counters_("odometry_implausible", static_cast<double>(o.readings_implausible));
  counters_("odometry_steps_implausible", static_cast<double>(o.steps_implausible));
  counters_("odometry_steps_checked", static_cast<double>(o.steps_checked));
  counters_("odometry_steps_contradicted", static_cast<double>(o.steps_contradicted));
  counters_("frontend_steps_replaced_by_odometry", static_cast<double>(c.frontend_steps_replaced));
  counters_("frontend_spikes_netted", static_cast<double>(c.frontend_spikes_netted));
  counters_("loop_closures", static_cast<double>(backend_.closures().size()));
  counters_("loop_episodes", static_cast<double>(l.episodes));
  counters_("loop_candidates", static_cast<double>(l.candidates));
  counters_("loop_rejected_response", static_cast<double>(l.rejected_response));
  counters_("loop_rejected_ambiguous", static_cast<double>(l.rejected_ambiguous));
  counters_("loop_rejected_covariance", static_cast<double>(l.rejected_covariance));
  counters_("loop_opened", static_cast<double>(l.opened));
  counters_("loop_refined", static_cast<double>(l.refined));
  counters_("loop_refine_failed", static_cast<double>(l.refine_failed));
  counters_("loop_rejected_inconsistent", static_cast<double>(l.rejected_inconsistent));
  counters_("loop_rejected_graph", static_cast<double>(c.closures_rejected_inconsistent));
  counters_("optimisations", static_cast<double>(c.optimisations));
  counters_("optimisations_failed", static_cast<double>(c.optimisations_failed));
  counters_("optimisation_last_s", c.last_optimisation_s);
  counters_("optimisation_total_s", c.total_optimisation_s);
  counters_("symbolic_analyses", static_cast<double>(backend_.analyses()));
  counters_("orderings_reused", static_cast<double>(backend_.orderings_reused()));
  counters_("scan_store_bytes", static_cast<double>(backend_.scans().memory_bytes()));
  counters_("scan_bytes_per_key_pose", backend_.scans().bytes_per_key_pose());
  counters_("key_poses_messages", static_cast<double>(messages_));
  counters_("key_poses_message_max_bytes", static_cast<double>(max_message_bytes_));
  resend_->report(counters_);
  counters_("boresight_yaw_rad", backend_.boresight().yaw_rad().value_or(0.0));
  counters_("boresight_estimate_rad", backend_.boresight().estimate_rad());
  counters_("boresight_yaw_sigma_rad", backend_.boresight().yaw_sigma_rad());
  counters_("boresight_chords", static_cast<double>(backend_.boresight().chords()));
  counters_("start_frame_heading_rad", backend_.start_frame().heading_rad().value_or(0.0));
  counters_("start_frame_estimate_rad", backend_.start_frame().estimate_rad());
  counters_("start_frame_early_rad", backend_.start_frame().early_estimate_rad());
  counters_("start_frame_matches", static_cast<double>(backend_.start_frame().matches()));
  if (!state_) return;
  const BackendStateCounters& s = state_->counters();
  counters_("state_snapshots", static_cast<double>(s.snapshots));
  counters_("state_snapshot_failures", static_cast<double>(s.snapshot_failures));
  counters_("state_snapshot_last_s", s.last_snapshot_s);
  counters_("state_snapshot_total_s", s.total_snapshot_s);
  counters_("state_snapshot_bytes", s.last_snapshot_bytes);
  counters_("state_key_scans_appended", static_cast<double>(s.key_scans_appended));
}

}  // namespace traverse::backend
