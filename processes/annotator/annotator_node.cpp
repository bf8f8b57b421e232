#include "annotator_node.hpp"

#include <algorithm>
#include <chrono>

#include "config.hpp"

namespace traverse::annotator {
namespace {

Eigen::Matrix3d matrix(const double m[9]) {
  Eigen::Matrix3d out;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) out(r, c) = m[3 * r + c];
  }
  return out;
}

void set_rgb(const Rgb& rgb, uint8_t out[3]) { std::copy(rgb.begin(), rgb.end(), out); }

}  // namespace

std::optional<std::string> validate(const AnnotatorNodeConfig& c) {
  ConfigCheck check;
  check.not_empty("key_poses_channel", c.key_poses_channel);
  check.not_empty("edges_channel", c.edges_channel);
  check.not_empty("annotations_channel", c.annotations_channel);
  // 52 bytes per key pose: at most 1200 keep a part under 64 KB.
  check.in_range("max_keys_per_message", c.max_keys_per_message, 1, 1200);
  check.nested("resend", validate(c.resend));
  if (check.problem()) return check.problem();
  return validate(c.annotator);  // its keys sit at the top level of the file
}

std::vector<annotations_t> pack_annotations(const Annotator& annotator,
                                            const std::vector<Annotation>& annotations,
                                            int64_t utime, int32_t optimisation, int8_t reason,
                                            int32_t loop_closures, int32_t changed_level,
                                            int per_message) {
  const AnnotatorConfig& cfg = annotator.config();
  const Legend& legend = annotator.legend();
  annotations_t head{};
  head.utime = utime;
  head.optimisation = optimisation;
  head.reason = reason;
  head.loop_closures = loop_closures;
  head.changed_level = changed_level;
  head.standard = legend.standard();
  head.coloured_by = cfg.colour_by;
  head.bound_method = cfg.bound;
  head.confidence = kConfidence;
  head.covariance_scale = cfg.covariance_scale;
  head.local_radius_m = cfg.local_radius_m;
  head.best_level = static_cast<int8_t>(legend.best());
  head.worst_level = static_cast<int8_t>(legend.worst());
  for (const Level& l : legend.levels()) {
    accuracy_level_t m{};
    m.utime = utime;
    m.name = l.name;
    m.min_m = l.min_m;
    m.max_m = l.max_m;
    set_rgb(l.rgb, m.rgb);
    m.accepted = l.accepted;
    head.levels.push_back(m);
  }
  head.n_levels = static_cast<int32_t>(head.levels.size());
  const std::size_t per = static_cast<std::size_t>(per_message);
  const int parts = std::max<int>(1, static_cast<int>((annotations.size() + per - 1) / per));
  std::vector<annotations_t> out(parts, head);
  for (std::size_t k = 0; k < annotations.size(); ++k) {
    const Annotation& a = annotations[k];
    key_annotation_t m{};
    m.utime = a.utime;
    m.id = a.id;
    m.x = a.T_world_base.x();
    m.y = a.T_world_base.y();
    m.bound_m = a.bound_m;
    m.local_bound_m = a.local_bound_m;
    m.level = static_cast<int8_t>(a.level);
    set_rgb(a.rgb, m.rgb);
    out[k / per].keys.push_back(m);
  }
  for (int p = 0; p < parts; ++p) {
    out[p].part = p;
    out[p].parts = parts;
    out[p].n_keys = static_cast<int32_t>(out[p].keys.size());
  }
  return out;
}

AnnotatorNode::AnnotatorNode(Bus& bus, const AnnotatorNodeConfig& config, CounterSink counters)
    : bus_(bus), config_(config), annotator_(config.annotator), counters_(std::move(counters)) {
  // The parts of one optimisation share a utime.
  bus_.subscribe<pose_graph_edges_t>(
      config_.edges_channel, [this](const pose_graph_edges_t& m) { on_edges(m); }, true);
  bus_.subscribe<key_poses_t>(
      config_.key_poses_channel, [this](const key_poses_t& m) { on_key_poses(m); }, true);
  // A late listener's answer: every annotation, as at the end of data but not final.
  resend_ = std::make_unique<ResendAnswerer>(
      bus_, std::vector<std::string>{config_.annotations_channel},
      [this](const ResendRequest&) {
        const std::vector<Annotation> all = all_annotations();
        if (!all.empty()) {
          publish(all, annotations_t::REASON_NEW, 0,
                  channels::full_channel(config_.annotations_channel));
        }
        return true;
      },
      // Its listeners (the mapper, the viewer) ask once, at start: each requester is answered,
      // at most once per resend.pace_s of key pose time.
      ResendPacing{.min_us = config_.resend.pace_us(), .data_time = [this] { return utime_; }});
  if (!config_.ask_for_state) return;
  // The backend's answers: the whole graph, read like an update.
  bus_.subscribe<pose_graph_edges_t>(
      channels::full_channel(config_.edges_channel),
      [this](const pose_graph_edges_t& m) { on_edges(m); }, true);
  bus_.subscribe<key_poses_t>(
      channels::full_channel(config_.key_poses_channel),
      [this](const key_poses_t& m) { on_key_poses(m); }, true);
  ask_for_graph();  // a backend already running has a graph this node has not seen
}

void AnnotatorNode::ask_for_graph() {
  if (!config_.ask_for_state || requested_at_ == optimisation_) return;
  request_resend(bus_, "annotator", {config_.edges_channel, config_.key_poses_channel}, utime_);
  requested_at_ = optimisation_;
  ++resend_requests_sent_;
}

void AnnotatorNode::on_edges(const pose_graph_edges_t& msg) {
  graph_edges_ = std::max(graph_edges_, msg.total_edges);
  for (const pose_graph_edge_t& e : msg.edges) {
    annotator_.add_edge(e.index, e.from_id, e.to_id, Pose2(e.x, e.y, e.theta),
                        matrix(e.information));
  }
}

void AnnotatorNode::on_key_poses(const key_poses_t& msg) {
  for (const key_pose_t& k : msg.poses) {
    annotator_.set_key_pose(k.id, k.utime, Pose2(k.x, k.y, k.theta), matrix(k.covariance));
  }
  utime_ = std::max(utime_, msg.utime);
  optimisation_ = std::max(optimisation_, msg.optimisation);
  if (msg.n_closures > 0) closure_pending_ = true;
  loop_closures_ = std::max(loop_closures_, msg.total_loop_closures);
  graph_key_poses_ = std::max(graph_key_poses_, msg.total_key_poses);
  // All parts of the optimisation are in (a lost part only delays its key poses to the next one).
  if (msg.part + 1 < msg.parts) return;
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<Annotation> changed = annotator_.update();
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ++updates_;
  update_s_total_ += s;
  update_s_max_ = std::max(update_s_max_, s);
  const int8_t reason =
      closure_pending_ ? annotations_t::REASON_LOOP_CLOSURE : annotations_t::REASON_NEW;
  closure_pending_ = false;
  if (!changed.empty()) {
    publish(changed, reason, annotator_.last_level_changes(), config_.annotations_channel);
  }
  // Something was missed (started late, or a message lost): ask for the whole graph.
  if (annotator_.key_poses_held() < static_cast<std::size_t>(graph_key_poses_) ||
      annotator_.counters().edges < graph_edges_) {
    ask_for_graph();
  }
}

void AnnotatorNode::publish(const std::vector<Annotation>& annotations, int8_t reason,
                            int32_t changed_level, const std::string& channel) {
  for (annotations_t& m :
       pack_annotations(annotator_, annotations, utime_, optimisation_, reason, loop_closures_,
                        changed_level, config_.max_keys_per_message)) {
    bus_.publish(channel, m);
    ++messages_;
  }
}

std::vector<Annotation> AnnotatorNode::all_annotations() const {
  std::vector<Annotation> all;
  for (const auto& [id, a] : annotator_.annotations()) all.push_back(a);
  return all;
}

void AnnotatorNode::finish() {
  const std::vector<Annotation> all = all_annotations();
  if (!all.empty()) publish(all, annotations_t::REASON_FINAL, 0, config_.annotations_channel);
}

void AnnotatorNode::report_counters() {
  if (!counters_) return;
  const AnnotatorCounters& c = annotator_.counters();
  counters_("key_poses_received", static_cast<double>(c.key_poses));
  counters_("key_poses_annotated", static_cast<double>(annotator_.annotations().size()));
  counters_("edges", static_cast<double>(c.edges));
  counters_("edges_rejected", static_cast<double>(c.edges_rejected));
  counters_("edges_missed", static_cast<double>(c.edge_gaps));
  counters_("local_failed", static_cast<double>(c.local_failed));
  counters_("local_columns", static_cast<double>(c.local_columns));
  counters_("annotations_changed", static_cast<double>(c.annotations_changed));
  counters_("level_changes", static_cast<double>(c.level_changes));
  counters_("annotation_messages", messages_);
  counters_("updates", updates_);
  counters_("update_total_s", update_s_total_);
  counters_("update_max_s", update_s_max_);
  counters_("resend_requests_sent", resend_requests_sent_);
  resend_->report(counters_);
}

}  // namespace traverse::annotator
