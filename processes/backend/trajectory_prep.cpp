#include "trajectory_prep.hpp"

#include <algorithm>
#include <cmath>

#include "config.hpp"

namespace traverse::backend {
namespace {

constexpr std::size_t kRecentIntervals = 5;  // as the frontend's rule
// Paced as a scanner's stream at large (PreparedPose::paced): the mean of this many intervals
// within [min_stream_interval_us, kPacedMeanUs]. The mean over 51 intervals, from the least to
// the most: full-rate intel 0.15-0.25 s (bursts 1 ms apart after stalls of up to 2 s), aces
// 0.13-0.30 s, fr079 0.21-0.22 s; subsampled by travel, intel 2.1-3.8 s, aces 2.1-4.1 s.
constexpr std::size_t kPaceIntervals = 51;
constexpr int64_t kPacedMeanUs = 500000;
constexpr int64_t kMaxPaceIntervalUs = 1000000000000;

}  // namespace

TrajectoryPrep::TrajectoryPrep(JumpSmoothingConfig config)
    : config_(std::move(config)), smoother_(config_) {}

bool TrajectoryPrep::sparse() const {
  if (config_.input == "stream") return false;
  if (config_.input == "sparse") return true;
  if (intervals_us_.size() < kRecentIntervals) return false;
  const auto recent = intervals_us_.end() - static_cast<std::ptrdiff_t>(kRecentIntervals);
  // A scanner's stream: every recent interval within [min_stream_interval_us,
  // sparse_interval_us]. One longer (a log subsampled by travel) or shorter (stamps squeezed
  // together where a log's clock failed) says the times do not pace the motion.
  const auto [lo, hi] = std::minmax_element(recent, intervals_us_.end());
  return *hi > config_.sparse_interval_us || *lo < config_.min_stream_interval_us;
}

bool TrajectoryPrep::paced() const {
  if (config_.input == "stream") return true;
  if (config_.input == "sparse" || intervals_us_.size() < kRecentIntervals) return false;
  const auto n = static_cast<int64_t>(intervals_us_.size());
  return pace_sum_us_ >= config_.min_stream_interval_us * n && pace_sum_us_ <= kPacedMeanUs * n;
}

std::optional<PreparedPose> TrajectoryPrep::add(const FrontendPose& pose) {
  ++counters_.poses;
  const int64_t last_utime = held_ ? held_->utime : (last_ ? last_->utime : INT64_MIN);
  if (pose.utime <= last_utime) {
    ++counters_.out_of_order;
    return std::nullopt;
  }
  if (last_utime != INT64_MIN) {
    // Each held to 10^6 s in the sum: the sum of 51 stays far within int64 whatever the stamps.
    const auto held = [](int64_t us) { return std::min(us, kMaxPaceIntervalUs); };
    intervals_us_.push_back(pose.utime - last_utime);
    pace_sum_us_ += held(intervals_us_.back());
    if (intervals_us_.size() > kPaceIntervals) {
      pace_sum_us_ -= held(intervals_us_.front());
      intervals_us_.pop_front();
    }
  }
  if (!held_) {
    held_ = pose;
    return std::nullopt;
  }
  const FrontendPose held = *held_;
  held_ = pose;
  return prepare(held, pose);
}

void TrajectoryPrep::resume(const PreparedPose& last, const TrajectoryPrepCounters& counters) {
  counters_ = counters;
  held_.reset();
  intervals_us_.clear();
  pace_sum_us_ = 0;
  last_ = last;
  smoother_.restart({last.utime, last.frontend.T_map_base}, last.T_world_base);
}

std::optional<PreparedPose> TrajectoryPrep::finish() {
  if (!held_) return std::nullopt;
  const FrontendPose held = *held_;
  held_.reset();
  return prepare(held, std::nullopt);
}

PreparedPose TrajectoryPrep::prepare(FrontendPose pose, const std::optional<FrontendPose>& next) {
  PreparedPose out;
  out.utime = pose.utime;
  out.sparse = sparse();
  out.paced = paced();
  const StampedPose raw{pose.utime, pose.T_map_base};
  if (!last_) {
    out.T_world_base = pose.T_map_base;
    smoother_.restart(raw, out.T_world_base);
  } else if (out.sparse || !config_.enabled) {
    // Subsampled by travel, or no smoothing: the frontend's step as it is.
    if (out.sparse) ++counters_.sparse_poses;
    out.T_world_base = last_->T_world_base * between(last_->frontend.T_map_base, pose.T_map_base);
    smoother_.restart(raw, out.T_world_base);
  } else {
    if (next && smoother_.is_outlier(raw, {next->utime, next->T_map_base})) {
      ++counters_.outliers_replaced;
      pose.T_map_base = smoother_.replace_outlier(raw, {next->utime, next->T_map_base});
    }
    bool jump = false;
    out.T_world_base = smoother_.add({pose.utime, pose.T_map_base}, jump);
    if (jump) ++counters_.jumps_smoothed;
  }
  out.frontend = pose;
  out.travel_m =
      last_ ? last_->travel_m +
                  (out.T_world_base.translation() - last_->T_world_base.translation()).norm()
            : 0.0;
  last_ = out;
  return out;
}

std::optional<std::string> validate(const KeyPoseConfig& c) {
  ConfigCheck check;
  check.positive("interval_us", c.interval_us);
  check.not_negative("distance_m", c.distance_m);
  check.not_negative("angle_rad", c.angle_rad);
  return check.problem();
}

std::vector<int> select_key_poses(const std::vector<StampedPose>& poses,
                                  const KeyPoseConfig& config) {
  std::vector<int> keys;
  if (poses.empty()) return keys;
  keys.push_back(0);
  double distance = 0.0, angle = 0.0;
  for (std::size_t k = 1; k < poses.size(); ++k) {
    const Pose2 step = between(poses[k - 1].T_world_base, poses[k].T_world_base);
    distance += step.translation().norm();
    angle += std::abs(step.theta());
    const bool by_time =
        config.interval_us > 0 && poses[k].utime - poses[keys.back()].utime >= config.interval_us;
    const bool by_distance = config.distance_m > 0.0 && distance >= config.distance_m;
    const bool by_angle = config.angle_rad > 0.0 && angle >= config.angle_rad;
    if (by_time || by_distance || by_angle) {
      keys.push_back(static_cast<int>(k));
      distance = angle = 0.0;
    }
  }
  return keys;
}

}  // namespace traverse::backend
