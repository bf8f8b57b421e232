#include "handover.hpp"

#include <map>

#include "config.hpp"
#include "hector/scan_points.hpp"
#include "state_file.hpp"

namespace traverse::frontend {
namespace {

// Samples up to this long after a scan's last point are given before it is re-tracked, as the
// node waits for samples that cover a scan.
constexpr int64_t kSampleLeadUs = 50'000;
constexpr uint64_t kMaxItems = 10'000'000;

}  // namespace

std::optional<std::string> validate(const HandoverConfig& c) {
  ConfigCheck check;
  check.not_empty("control_channel", c.control_channel);
  check.in_range("window_s", c.window_s, 0.1, 600.0);
  check.in_range("max_scans", c.max_scans, 2, 100'000);
  check.in_range("check_scans", c.check_scans, 0, 1000);
  check.positive("fit_distance_m", c.fit_distance_m);
  check.require(c.fit_distance_m <= 0.3, "fit_distance_m", "must be at most 0.3");
  check.in_range("min_fit", c.min_fit, 0.0, 1.0);
  check.in_range("save_period_s", c.save_period_s, 0.0, 3600.0);
  return check.problem();
}

void Handover::add_imu(int64_t utime, const Eigen::Vector3d& angular_velocity_imu) {
  Sample s;
  s.utime = utime;
  s.imu = true;
  s.angular_velocity = angular_velocity_imu;
  samples_.push_back(s);
}

void Handover::add_odometry(const OdometrySample& odometry) {
  Sample s;
  s.utime = odometry.utime;
  s.odometry = odometry;
  samples_.push_back(s);
}

void Handover::add_scan(const Scan& scan) {
  scans_.push_back({scan, std::nullopt});
  trim();
}

void Handover::add_published(int64_t utime, const Pose2& T_map_base) {
  for (auto it = scans_.rbegin(); it != scans_.rend(); ++it) {
    if (it->scan.utime_last == utime) {
      it->T_published = T_map_base;
      return;
    }
  }
}

void Handover::trim() {
  const int64_t newest = scans_.back().scan.utime_last;
  const auto window_us = static_cast<int64_t>(config_.window_s * 1e6);
  while (scans_.size() > static_cast<std::size_t>(config_.max_scans) ||
         (scans_.size() > 1 && newest - scans_.front().scan.utime_last > window_us)) {
    scans_.pop_front();
  }
  // Samples from before the oldest scan's first point are of no use to a re-track.
  const int64_t oldest = scans_.front().scan.utime_first - kSampleLeadUs;
  while (!samples_.empty() && samples_.front().utime < oldest) samples_.pop_front();
}

std::optional<std::pair<int64_t, Pose2>> Handover::last_published() const {
  for (auto it = scans_.rbegin(); it != scans_.rend(); ++it) {
    if (it->T_published) return std::make_pair(it->scan.utime_last, *it->T_published);
  }
  return std::nullopt;
}

std::optional<Handover::Started> Handover::start(const FrontendConfig& config) const {
  std::size_t first = 0;
  while (first < scans_.size() && !scans_[first].T_published) ++first;
  if (first == scans_.size()) return std::nullopt;
  FrontendConfig c = config;
  const Pose2& T0 = *scans_[first].T_published;
  c.initial_pose = {.x_m = T0.x(), .y_m = T0.y(), .theta_rad = T0.theta()};
  Started started;
  started.frontend = make_frontend(c);
  Frontend& f = *started.frontend;
  std::size_t s = 0;
  const auto feed_until = [&](int64_t utime) {
    for (; s < samples_.size() && samples_[s].utime <= utime; ++s) {
      if (samples_[s].imu) {
        f.add_imu(samples_[s].utime, samples_[s].angular_velocity);
      } else {
        f.add_odometry(samples_[s].odometry);
      }
    }
  };
  std::map<int64_t, Pose2> own;
  const auto take = [&](const FrontendResult& r) {
    if (r.has_pose()) own[r.utime] = r.T_map_base;
  };
  for (std::size_t k = first; k < scans_.size(); ++k) {
    feed_until(scans_[k].scan.utime_last + kSampleLeadUs);
    take(f.process(scans_[k].scan));
    ++started.scans;
    started.last_utime = scans_[k].scan.utime_last;
  }
  feed_until(INT64_MAX);
  // Aligned at the newest scan that has both poses.
  for (auto it = scans_.rbegin(); it != scans_.rend(); ++it) {
    const auto o = own.find(it->scan.utime_last);
    if (!it->T_published || o == own.end()) continue;
    started.C = *it->T_published * o->second.inverse();
    const Pose2 d = between(*it->T_published, o->second);
    started.misfit_m = d.translation().norm();
    started.misfit_rad = std::abs(d.theta());
    break;
  }
  return started;
}

double Handover::fit(const Scan& scan, const Pose2& T_map_base,
                     const FrontendConfig& config) const {
  ScanPointMaker make(config.T_base_laser.pose(), config.matcher.min_range_m,
                      config.matcher.max_range_m);
  if (!fit_map_) {
    fit_map_.emplace(0.3, 0.02);
    for (const Held& h : scans_) {
      if (!h.T_published) continue;
      std::vector<MapPoint> points;
      for (const Eigen::Vector2d& p : subsample(make(h.scan).points_base, 0.02)) {
        points.push_back({*h.T_published * p, Eigen::Vector2d::UnitX()});
      }
      fit_map_->add(points);
    }
  }
  const PointMap& map = *fit_map_;
  const std::vector<Eigen::Vector2d> query = subsample(make(scan).points_base, 0.05);
  if (map.empty() || query.empty()) return 0.0;
  int near = 0;
  for (const Eigen::Vector2d& p : query) {
    if (map.nearest(T_map_base * p, config_.fit_distance_m)) ++near;
  }
  return static_cast<double>(near) / static_cast<double>(query.size());
}

std::string Handover::serialise() const {
  StateWriter w;
  w.put<uint64_t>(scans_.size());
  for (const Held& h : scans_) {
    const Scan& s = h.scan;
    w.put(s.utime_first);
    w.put(s.utime_last);
    w.put(s.angle_first);
    w.put(s.angle_step);
    w.put(s.range_min);
    w.put(s.range_max);
    w.put_vector(s.ranges);
    w.put<uint8_t>(h.T_published ? 1 : 0);
    w.put(h.T_published.value_or(Pose2()));
  }
  w.put<uint64_t>(samples_.size());
  for (const Sample& s : samples_) {
    w.put(s.utime);
    w.put<uint8_t>(s.imu ? 1 : 0);
    for (int i = 0; i < 3; ++i) w.put(s.angular_velocity[i]);
    w.put(s.odometry.T_odom_base);
    for (int i = 0; i < 9; ++i) w.put(s.odometry.pose_covariance(i / 3, i % 3));
  }
  return w.bytes();
}

bool Handover::restore(const std::string& bytes) {
  StateReader r(bytes);
  std::deque<Held> scans;
  std::deque<Sample> samples;
  uint64_t n = 0;
  if (!r.get(n) || n > kMaxItems) return false;
  for (uint64_t k = 0; k < n; ++k) {
    Held h;
    Scan& s = h.scan;
    uint8_t has = 0;
    Pose2 T;
    if (!r.get(s.utime_first) || !r.get(s.utime_last) || !r.get(s.angle_first) ||
        !r.get(s.angle_step) || !r.get(s.range_min) || !r.get(s.range_max) ||
        !r.get_vector(s.ranges, kMaxItems) || !r.get(has) || !r.get(T))
      return false;
    if (has) h.T_published = T;
    scans.push_back(std::move(h));
  }
  if (!r.get(n) || n > kMaxItems) return false;
  for (uint64_t k = 0; k < n; ++k) {
    Sample s;
    uint8_t imu = 0;
    bool ok = r.get(s.utime) && r.get(imu);
    for (int i = 0; i < 3; ++i) ok = ok && r.get(s.angular_velocity[i]);
    ok = ok && r.get(s.odometry.T_odom_base);
    for (int i = 0; i < 9; ++i) ok = ok && r.get(s.odometry.pose_covariance(i / 3, i % 3));
    if (!ok) return false;
    s.imu = imu != 0;
    s.odometry.utime = s.utime;
    samples.push_back(s);
  }
  if (!r.at_end()) return false;
  scans_ = std::move(scans);
  samples_ = std::move(samples);
  return true;
}

}  // namespace traverse::frontend
