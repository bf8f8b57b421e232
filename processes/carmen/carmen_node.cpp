#include "carmen_node.hpp"

#include <algorithm>
#include <iterator>
#include <limits>

#include "channels.hpp"
#include "se2.hpp"

namespace traverse::carmen {
namespace {

// [m] The published range_max sits this far below a no-return code: half the 1 mm resolution the
// code is found at, far above a float's resolution at 100 m.
constexpr double kBelowNoReturnM = 0.0005;

}  // namespace

planar_scan_t to_scan_message(const Scan& scan, const CarmenConfig& cfg) {
  planar_scan_t msg{};
  msg.utime = scan.utime;
  msg.frame = kLaserFrame;
  msg.utime_first = scan.utime;
  msg.utime_last = scan.utime;
  const std::size_t n = scan.ranges.size();
  const std::size_t max_beams = static_cast<std::size_t>(std::max(cfg.max_beams, 1));
  const std::size_t stride = n > max_beams ? (n + max_beams - 1) / max_beams : 1;
  msg.angle_first = static_cast<float>(scan.beams.angle_first);
  msg.angle_step = static_cast<float>(scan.beams.angle_step * static_cast<double>(stride));
  double range_max = std::min(cfg.range_max_m, scan.range_max_m.value_or(cfg.range_max_m));
  if (scan.no_return_code_m) {
    range_max = std::min(range_max, *scan.no_return_code_m - kBelowNoReturnM);
  }
  msg.range_min = static_cast<float>(cfg.range_min_m);
  msg.range_max = static_cast<float>(range_max);
  msg.ranges.reserve((n + stride - 1) / stride);
  for (std::size_t i = 0; i < n; i += stride) msg.ranges.push_back(scan.ranges[i]);
  msg.n_ranges = static_cast<int32_t>(msg.ranges.size());
  msg.n_intensities8 = 0;
  msg.n_intensities16 = 0;
  return msg;
}

pose2d_t to_reference_pose(const Scan& scan) {
  pose2d_t msg{};
  msg.utime = scan.utime;
  msg.parent_frame = "world";
  msg.child_frame = "base";
  msg.x = scan.x_m;
  msg.y = scan.y_m;
  msg.theta = wrap_angle(scan.theta_rad);
  std::fill(std::begin(msg.covariance), std::end(msg.covariance), 0.0);  // unknown
  msg.flags = 0;
  return msg;
}

odometry_t to_odometry_message(int64_t utime, const OdometryChain& chain,
                               const std::optional<Eigen::Vector3d>& velocity,
                               const OdometryNoise& noise) {
  odometry_t msg{};
  msg.utime = utime;
  msg.parent_frame = kOdometryFrame;
  msg.child_frame = "base";
  msg.x = chain.T_odom_base().x();
  msg.y = chain.T_odom_base().y();
  msg.theta = wrap_angle(chain.T_odom_base().theta());
  const Eigen::Matrix3d v_cov = velocity ? velocity_covariance(noise) : Eigen::Matrix3d::Zero();
  for (int i = 0; i < 9; ++i) {
    msg.pose_covariance[i] = chain.covariance()(i / 3, i % 3);  // row-major
    msg.velocity_covariance[i] = v_cov(i / 3, i % 3);
  }
  for (int i = 0; i < 3; ++i) msg.velocity[i] = velocity ? (*velocity)(i) : 0.0;
  return msg;
}

const char* odometry_source_name(OdometrySource source) {
  switch (source) {
    case OdometrySource::kOdom:
      return "odom";
    case OdometrySource::kLaser:
      return "laser";
    case OdometrySource::kNone:
      break;
  }
  return "none";
}

OdometrySource choose_odometry_source(const std::string& configured, const Summary& survey) {
  if (configured == "odom") return OdometrySource::kOdom;
  if (configured == "laser") return OdometrySource::kLaser;
  if (configured == "none") return OdometrySource::kNone;
  if (survey.odometry > survey.odometry_reanchors) return OdometrySource::kOdom;
  return survey.scans > 0 ? OdometrySource::kLaser : OdometrySource::kNone;
}

Driver::Driver(Publisher& out, const CarmenConfig& cfg, OdometrySource source,
               const Summary& survey, std::function<void(int64_t)> pace)
    : out_(out),
      cfg_(cfg),
      source_(source),
      timeless_(survey.time.clock == Clock::kNominal),
      velocity_in_log_(survey.odometry_velocity),
      pace_(std::move(pace)),
      chain_(cfg.odometry_noise) {}

void Driver::publish(const Record& record) {
  if (const Scan* scan = std::get_if<Scan>(&record)) {
    on_scan(*scan);
  } else {
    on_odometry(std::get<OdometryReading>(record));
  }
}

void Driver::finish() { flush_odometry(std::numeric_limits<int64_t>::max()); }

void Driver::on_scan(const Scan& scan) {
  if (source_ == OdometrySource::kLaser) {
    chain_.add(Pose2(scan.odom_x_m, scan.odom_y_m, scan.odom_theta_rad));
    std::optional<Eigen::Vector3d> velocity;
    if (scan.tv_mps && scan.rv_radps) velocity = Eigen::Vector3d(*scan.tv_mps, 0.0, *scan.rv_radps);
    queue_odometry(scan.utime, velocity);
  } else if (source_ == OdometrySource::kOdom && timeless_ && chain_.started()) {
    queue_odometry(scan.utime, std::nullopt);  // the odometry at the scan, by file order
  }
  flush_odometry(scan.utime);
  if (static_cast<int64_t>(scan.ranges.size()) > cfg_.max_beams) ++scans_thinned_;
  planar_scan_t scan_msg = to_scan_message(scan, cfg_);
  pose2d_t pose_msg = to_reference_pose(scan);
  if (pace_) pace_(scan.utime);
  out_.publish(channels::kScanHorizontal, scan_msg);
  out_.publish(channels::kPoseReference, pose_msg);
  last_scan_utime_ = scan.utime;
  ++scans_;
}

void Driver::on_odometry(const OdometryReading& reading) {
  if (source_ != OdometrySource::kOdom) return;
  const Odometry& o = reading.odom;
  const Pose2 T_log_base(o.x_m, o.y_m, o.theta_rad);
  if (reading.reanchor) {
    chain_.reanchor(T_log_base);
    return;
  }
  chain_.add(T_log_base);
  if (timeless_ || !reading.in_time_order) return;
  std::optional<Eigen::Vector3d> velocity;
  if (velocity_in_log_) velocity = Eigen::Vector3d(o.tv_mps, 0.0, o.rv_radps);
  queue_odometry(reading.utime, velocity);
}

void Driver::queue_odometry(int64_t utime, const std::optional<Eigen::Vector3d>& velocity) {
  const bool behind_scan = last_scan_utime_ && utime <= *last_scan_utime_;
  const bool behind_odometry = (!pending_.empty() && utime <= pending_.back().utime) ||
                               (last_odometry_utime_ && utime <= *last_odometry_utime_);
  if (behind_scan || behind_odometry) {
    ++odometry_behind_scans_;
    return;
  }
  pending_.push_back(to_odometry_message(utime, chain_, velocity, cfg_.odometry_noise));
}

void Driver::flush_odometry(int64_t up_to_utime) {
  while (!pending_.empty() && pending_.front().utime <= up_to_utime) {
    odometry_t& msg = pending_.front();
    if (pace_) pace_(msg.utime);
    out_.publish(channels::kOdometry, msg);
    last_odometry_utime_ = msg.utime;
    ++odometry_;
    pending_.pop_front();
  }
}

}  // namespace traverse::carmen
