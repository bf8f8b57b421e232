#include "densifier.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "config.hpp"

namespace traverse::densifier {

std::optional<std::string> validate(const DensifierConfig& c) {
  ConfigCheck check;
  check.require(parse_mode(c.mode).has_value(), "mode",
                "must be paper or rigid, not '" + c.mode + "'");
  check.not_negative("turn_lever_m", c.turn_lever_m);
  check.not_negative("republish_threshold_m", c.republish_threshold_m);
  check.not_negative("republish_threshold_rad", c.republish_threshold_rad);
  check.not_empty("parent_frame", c.parent_frame);
  check.not_empty("key_pose_channel", c.key_pose_channel);
  // Below a few kilobytes a message holds only a handful of segments and bursts grow long again;
  // above 64 KB it no longer fits one UDP datagram.
  check.in_range("max_message_bytes", c.max_message_bytes, 4096, 65000);
  check.not_negative("spike_threshold_m", c.spike_threshold_m);
  check.not_negative("spike_max_span_us", c.spike_max_span_us);
  check.not_negative("spike_min_interval_us", c.spike_min_interval_us);
  check.not_negative("spike_interval_tolerance", c.spike_interval_tolerance);
  check.nested("resend", validate(c.resend));
  return check.problem();
}

std::optional<Mode> parse_mode(const std::string& name) {
  if (name == "paper") return Mode::kPaper;
  if (name == "rigid") return Mode::kRigid;
  return std::nullopt;
}

namespace {

// The pose at `utime` on the geodesic from lo to hi (lo.utime < hi.utime).
Pose2 interpolate_between(const StampedPose& lo, const StampedPose& hi, int64_t utime) {
  const double s = static_cast<double>(utime - lo.utime) / static_cast<double>(hi.utime - lo.utime);
  return interpolate(lo.T_world_base, hi.T_world_base, s);
}

}  // namespace

std::optional<Pose2> interpolate_at(const std::vector<StampedPose>& poses, int64_t utime) {
  if (poses.empty() || utime < poses.front().utime || utime > poses.back().utime) {
    return std::nullopt;
  }
  auto hi = std::lower_bound(poses.begin(), poses.end(), utime,
                             [](const StampedPose& p, int64_t t) { return p.utime < t; });
  if (hi->utime == utime) return hi->T_world_base;
  return interpolate_between(*(hi - 1), *hi, utime);
}

namespace {

// Heading correction at fraction s of the segment, interpolated between the two ends' corrections.
double heading_correction(const Pose2& D_a, const Pose2& D_b, const Pose2& K_a, const Pose2& K_b,
                          double s) {
  const double da = wrap_angle(K_a.theta() - D_a.theta());
  const double db = da + wrap_angle((K_b.theta() - D_b.theta()) - da);
  return da + s * (db - da);
}

// Seed 000: similarity transform of the positions, interpolated heading corrections (by time).
std::vector<StampedPose> correct_paper(const std::vector<StampedPose>& dense, const Pose2& K_a,
                                       const Pose2& K_b) {
  const Pose2& D_a = dense.front().T_world_base;
  const Pose2& D_b = dense.back().T_world_base;
  const Eigen::Vector2d d = D_b.translation() - D_a.translation();
  const Eigen::Vector2d e = K_b.translation() - K_a.translation();
  double scale = 1.0, rot = 0.0;
  if (d.norm() > 1e-12 && e.norm() > 1e-12) {
    scale = e.norm() / d.norm();
    rot = std::atan2(e.y(), e.x()) - std::atan2(d.y(), d.x());
  }
  const Eigen::Matrix2d R = Eigen::Rotation2Dd(rot).toRotationMatrix();
  const double t_span = static_cast<double>(dense.back().utime - dense.front().utime);
  std::vector<StampedPose> out;
  out.reserve(dense.size());
  for (const StampedPose& p : dense) {
    const double s = t_span > 0 ? static_cast<double>(p.utime - dense.front().utime) / t_span : 0.0;
    const Eigen::Vector2d q =
        K_a.translation() + scale * R * (p.T_world_base.translation() - D_a.translation());
    const double theta = p.T_world_base.theta() + heading_correction(D_a, D_b, K_a, K_b, s);
    out.push_back({p.utime, Pose2(q.x(), q.y(), wrap_angle(theta))});
  }
  // The end poses are the key poses themselves (the similarity meets them up to rounding).
  out.front().T_world_base = K_a;
  out.back().T_world_base = K_b;
  return out;
}

// Interpolated rigid correction, weighted by travel (distance + lever x turned angle), or by time
// when the platform did not move.
std::vector<StampedPose> correct_rigid(const std::vector<StampedPose>& dense, const Pose2& K_a,
                                       const Pose2& K_b, double turn_lever_m) {
  const Pose2 C_a = K_a * dense.front().T_world_base.inverse();
  const Pose2 C_b = K_b * dense.back().T_world_base.inverse();
  std::vector<double> travel(dense.size(), 0.0);
  for (std::size_t i = 1; i < dense.size(); ++i) {
    const Pose2& p = dense[i - 1].T_world_base;
    const Pose2& q = dense[i].T_world_base;
    travel[i] = travel[i - 1] + (q.translation() - p.translation()).norm() +
                turn_lever_m * std::abs(wrap_angle(q.theta() - p.theta()));
  }
  const double total = travel.back();
  const double t_span = static_cast<double>(dense.back().utime - dense.front().utime);
  // Below a micrometre of travel the fraction is noise: spread by time instead.
  const bool by_time = total < 1e-6;
  std::vector<StampedPose> out;
  out.reserve(dense.size());
  for (std::size_t i = 0; i < dense.size(); ++i) {
    double s = 0.0;
    if (by_time) {
      if (t_span > 0) s = static_cast<double>(dense[i].utime - dense.front().utime) / t_span;
    } else {
      s = travel[i] / total;
    }
    out.push_back({dense[i].utime, interpolate(C_a, C_b, s) * dense[i].T_world_base});
  }
  out.front().T_world_base = K_a;
  out.back().T_world_base = K_b;
  return out;
}

}  // namespace

std::vector<StampedPose> correct_segment(const std::vector<StampedPose>& dense, const Pose2& K_a,
                                         const Pose2& K_b, Mode mode, double turn_lever_m) {
  if (dense.size() < 2) return {};
  return mode == Mode::kPaper ? correct_paper(dense, K_a, K_b)
                              : correct_rigid(dense, K_a, K_b, turn_lever_m);
}

Densifier::Densifier(const DensifierConfig& config) : config_(config) {
  auto mode = parse_mode(config.mode);
  if (!mode)
    throw std::invalid_argument("densifier mode must be paper or rigid, not " + config.mode);
  mode_ = *mode;
}

bool Densifier::add_dense(int64_t utime, const Pose2& T_world_base, std::vector<Segment>* closed) {
  if (!dense_.empty() && utime <= dense_.back().utime) return false;
  const int64_t previous = dense_.empty() ? utime - 1 : dense_.back().utime;
  dense_.push_back({utime, T_world_base});
  std::vector<Segment> out;
  replace_spike(out);
  // Key poses the dense data has just reached become placed; their segments can close.
  const auto end = keys_.upper_bound(utime);
  for (auto it = keys_.upper_bound(previous); it != end; ++it) {
    if (it->second.placed) continue;
    it->second.placed = true;
    if (it != keys_.begin()) refresh_segment(std::prev(it), out);
    refresh_segment(it, out);
  }
  if (closed) closed->insert(closed->end(), out.begin(), out.end());
  return true;
}

bool Densifier::steady(int64_t in_us, int64_t out_us) const {
  constexpr std::size_t kPeriods = 20;
  const std::size_t n = dense_.size();
  std::vector<int64_t> intervals;
  for (std::size_t i = n - 1; i > 0 && intervals.size() < kPeriods; --i) {
    intervals.push_back(dense_[i].utime - dense_[i - 1].utime);
  }
  const auto mid = intervals.begin() + static_cast<std::ptrdiff_t>(intervals.size() / 2);
  std::nth_element(intervals.begin(), mid, intervals.end());
  const double period = static_cast<double>(*mid);
  const double tolerance = config_.spike_interval_tolerance * period;
  return std::abs(static_cast<double>(in_us) - period) <= tolerance &&
         std::abs(static_cast<double>(out_us) - period) <= tolerance;
}

void Densifier::replace_spike(std::vector<Segment>& out) {
  const std::size_t n = dense_.size();
  if (config_.spike_threshold_m <= 0.0 || n < 3) return;
  const StampedPose& a = dense_[n - 3];
  const StampedPose& b = dense_[n - 1];
  StampedPose& p = dense_[n - 2];
  if (b.utime - a.utime > config_.spike_max_span_us) return;
  const int64_t in = p.utime - a.utime, out_us = b.utime - p.utime;
  if (std::min(in, out_us) < config_.spike_min_interval_us) return;
  const Pose2 q = interpolate_between(a, b, p.utime);
  const double off = (p.T_world_base.translation() - q.translation()).norm();
  // Turns count as travel, as the bending counts them (turn_lever_m): a turn moves the base's
  // origin when the platform does not turn about it, so the path between two neighbours that
  // turn is no straight line, and a pose turned off their interpolation may lie off it by the
  // lever times that angle. A wrong match that slides along what the scan cannot fix (a corridor)
  // keeps the heading the walls give it: off in position alone.
  const auto lever = [&](const Pose2& u, const Pose2& v) {
    return config_.turn_lever_m * std::abs(wrap_angle(v.theta() - u.theta()));
  };
  const double travel = (b.T_world_base.translation() - a.T_world_base.translation()).norm() +
                        lever(a.T_world_base, b.T_world_base);
  if (off <= config_.spike_threshold_m || off <= travel || off <= lever(q, p.T_world_base)) return;
  // A scanner's stream comes at a steady rate; uneven intervals are a log's restamped times.
  // Checked last: it looks at the last 20 intervals, and few poses get this far.
  if (!steady(in, out_us)) return;
  p.T_world_base = q;
  ++spikes_replaced_;
  // The segment over the pose, and the one before when a key pose sits exactly on it.
  const auto after = keys_.upper_bound(p.utime);
  if (after == keys_.begin()) return;
  const auto at = std::prev(after);
  refresh_segment(at, out);
  if (at->first == p.utime && at != keys_.begin()) refresh_segment(std::prev(at), out);
}

std::vector<Segment> Densifier::update_key_poses(const std::vector<KeyPose>& keys) {
  std::vector<int64_t> touched;
  for (const KeyPose& k : keys) {
    KeyState& s = keys_[k.utime];
    s.key = k;
    s.placed = !dense_.empty() && k.utime >= dense_.front().utime && k.utime <= dense_.back().utime;
    touched.push_back(k.utime);
  }
  // Every segment that starts or ends at a touched key, each once, in time order.
  std::vector<int64_t> starts;
  for (int64_t t : touched) {
    auto it = keys_.find(t);
    starts.push_back(t);
    if (it != keys_.begin()) starts.push_back(std::prev(it)->first);
  }
  std::sort(starts.begin(), starts.end());
  starts.erase(std::unique(starts.begin(), starts.end()), starts.end());
  std::vector<Segment> out;
  for (int64_t t : starts) refresh_segment(keys_.find(t), out);
  return out;
}

std::vector<StampedPose> Densifier::dense_between(int64_t t0, int64_t t1) const {
  std::vector<StampedPose> out;
  auto a = interpolate_at(dense_, t0);
  auto b = interpolate_at(dense_, t1);
  if (!a || !b) return out;
  out.push_back({t0, *a});
  auto it = std::upper_bound(dense_.begin(), dense_.end(), t0,
                             [](int64_t t, const StampedPose& p) { return t < p.utime; });
  for (; it != dense_.end() && it->utime < t1; ++it) out.push_back(*it);
  out.push_back({t1, *b});
  return out;
}

std::vector<Segment> Densifier::settle() {
  std::vector<Segment> out;
  for (auto it = keys_.begin(); it != keys_.end(); ++it) refresh_segment(it, out, true);
  return out;
}

std::vector<Segment> Densifier::sent_segments() const {
  std::vector<Segment> out;
  for (const auto& [utime, seg] : segments_) {
    if (seg.revision < 0) continue;
    out.push_back(
        {keys_.at(utime).key.id, keys_.at(seg.utime_last).key.id, seg.revision, seg.poses});
  }
  return out;
}

void Densifier::refresh_segment(std::map<int64_t, KeyState>::iterator it, std::vector<Segment>& out,
                                bool exact) {
  if (it == keys_.end()) return;
  auto next = std::next(it);
  if (next == keys_.end() || !it->second.placed || !next->second.placed) return;
  const std::vector<StampedPose> dense = dense_between(it->first, next->first);
  if (dense.size() < 2) return;
  std::vector<StampedPose> poses =
      correct_segment(dense, it->second.key.T_world_base, next->second.key.T_world_base, mode_,
                      config_.turn_lever_m);
  SegmentState& seg = segments_[it->first];
  bool changed =
      seg.revision < 0 || seg.utime_last != next->first || seg.poses.size() != poses.size();
  for (std::size_t i = 0; !changed && i < poses.size(); ++i) {
    const Pose2& p = poses[i].T_world_base;
    const Pose2& q = seg.poses[i].T_world_base;
    const double dm = (p.translation() - q.translation()).norm();
    const double dr = std::abs(wrap_angle(p.theta() - q.theta()));
    changed = exact ? (dm > 0.0 || dr > 0.0)
                    : (dm > config_.republish_threshold_m || dr > config_.republish_threshold_rad);
  }
  if (!changed) return;
  if (seg.revision >= 0) ++segments_moved_;
  ++seg.revision;
  seg.utime_last = next->first;
  seg.poses = std::move(poses);
  out.push_back({it->second.key.id, next->second.key.id, seg.revision, seg.poses});
}

Pose2 Densifier::correction(const KeyState& k) const {
  return k.key.T_world_base * interpolate_at(dense_, k.key.utime)->inverse();
}

std::optional<Pose2> Densifier::pose_at(int64_t utime) const {
  auto raw = interpolate_at(dense_, utime);
  if (!raw) return std::nullopt;
  auto seg = segments_.upper_bound(utime);
  if (seg != segments_.begin()) {
    --seg;
    if (utime <= seg->second.utime_last) return interpolate_at(seg->second.poses, utime);
  }
  // Outside every closed segment: the correction of the nearest placed key pose, applied rigidly.
  const KeyState* nearest = nullptr;
  int64_t best = 0;
  for (const auto& [t, k] : keys_) {
    if (!k.placed) continue;
    const int64_t d = std::abs(t - utime);
    if (!nearest || d < best) nearest = &k, best = d;
  }
  if (!nearest) return raw;
  return correction(*nearest) * *raw;
}

std::vector<StampedPose> Densifier::corrected_trajectory() const {
  std::vector<StampedPose> out;
  out.reserve(dense_.size());
  for (const StampedPose& p : dense_) out.push_back({p.utime, *pose_at(p.utime)});
  return out;
}

}  // namespace traverse::densifier
