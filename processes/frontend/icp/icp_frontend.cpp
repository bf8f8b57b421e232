#include "icp_frontend.hpp"

#include <cmath>

#include "config.hpp"
#include "hector/deskew.hpp"
#include "icp_matcher.hpp"
#include "sweep_input.hpp"

namespace traverse::frontend {
std::optional<std::string> validate(const IcpConfig& c) {
  ConfigCheck check;
  check.in_range("cell_m", c.cell_m, 0.05, 5.0);
  check.in_range("point_spacing_m", c.point_spacing_m, 0.001, 1.0);
  check.not_negative("key_distance_m", c.key_distance_m);
  check.not_negative("key_angle_rad", c.key_angle_rad);
  check.positive("map_radius_m", c.map_radius_m);
  check.positive("normal_radius_m", c.normal_radius_m);
  check.in_range("max_line_spread", c.max_line_spread, 0.0, 1.0);
  check.not_negative("query_spacing_m", c.query_spacing_m);
  check.require(c.max_correspondence_m > 0.0 && c.max_correspondence_m <= c.cell_m,
                "max_correspondence_m", "must be in (0, cell_m]");
  check.require(
      c.final_correspondence_m > 0.0 && c.final_correspondence_m <= c.max_correspondence_m,
      "final_correspondence_m", "must be in (0, max_correspondence_m]");
  check.positive("kernel_m", c.kernel_m);
  check.in_range("max_iterations", c.max_iterations, 1, 1000);
  check.positive("convergence_m", c.convergence_m);
  check.positive("convergence_rad", c.convergence_rad);
  check.positive("prior_sigma_xy_m", c.prior_sigma_xy_m);
  check.positive("prior_sigma_theta_rad", c.prior_sigma_theta_rad);
  check.positive("min_residual_sigma_m", c.min_residual_sigma_m);
  check.in_range("min_inlier_fraction", c.min_inlier_fraction, 0.0, 1.0);
  check.positive("min_valid_points", c.min_valid_points);
  return check.problem();
}

IcpFrontend::IcpFrontend(const FrontendConfig& config)
    : config_(config),
      T_initial_(config.initial_pose.pose()),
      scan_points_(config.T_base_laser.pose(), config.matcher.min_range_m,
                   config.matcher.max_range_m),
      motion_(T_initial_, R_base_imu(config.deskew), config.motion_prior),
      map_(config.icp.cell_m, config.icp.point_spacing_m) {}

bool IcpFrontend::add_imu(int64_t utime, const Eigen::Vector3d& angular_velocity_imu) {
  return counted(motion_.add_imu(utime, angular_velocity_imu), counters_.imu_samples,
                 counters_.imu_dropped);
}

bool IcpFrontend::add_odometry(const OdometrySample& odometry) {
  return counted(motion_.add_odometry(odometry), counters_.odometry_samples,
                 counters_.odometry_dropped);
}

FrontendResult IcpFrontend::process(const Scan& scan) {
  ++counters_.scans_received;
  FrontendResult r;
  r.utime = scan.utime_last;
  FrontendDiagnostics& d = r.diagnostics.emplace();
  const bool initialised = motion_.initialised();
  const int64_t last_utime = motion_.last_utime();
  if (sweep_times_wrong(scan, initialised ? &last_utime : nullptr)) {
    ++counters_.scans_dropped_time;
    return r;
  }
  ScanPoints points = scan_points_(scan);
  counters_.readings_invalid += points.invalid;
  d.valid_points = static_cast<int>(points.points_base.size());
  const bool use_imu =
      motion_.imu_covers(initialised ? motion_.last_utime() : scan.utime_first, scan.utime_last);
  d.imu_used = use_imu;
  r.sparse =
      initialised && scan.utime_last - motion_.last_utime() > config_.matcher.wide_search_gap_us;
  const Pose2 T_predicted =
      initialised ? motion_.predict(scan.utime_last, use_imu, r.sparse).T_map_base : T_initial_;
  d.T_map_base_predicted = T_predicted;
  if (d.valid_points < config_.icp.min_valid_points) {
    ++counters_.scans_predicted;
    predicted(r, T_predicted);
    return r;
  }
  if (config_.deskew.enabled) {
    deskew_sweep(points.points_base, points.utimes, scan.utime_last, motion_, use_imu,
                 config_.deskew.translation);
  }
  if (!initialised) {  // the first scan's pose is given: exact by definition
    r.status = ScanStatus::kMatched;
    r.T_map_base = T_initial_;
    r.covariance = Eigen::Matrix3d::Identity() * 1e-12;
  } else {
    const IcpConfig& c = config_.icp;
    const Eigen::Matrix3d prior =
        Eigen::Vector3d(std::pow(c.prior_sigma_xy_m, -2), std::pow(c.prior_sigma_xy_m, -2),
                        std::pow(c.prior_sigma_theta_rad, -2))
            .asDiagonal();
    const IcpResult m = match_point_to_line(map_, subsample(points.points_base, c.query_spacing_m),
                                            T_predicted, T_predicted, prior, c);
    counters_.icp_iterations += m.iterations;
    d.iterations = m.iterations;
    d.matched_points = m.correspondences;
    if (m.inlier_fraction < c.min_inlier_fraction) {
      ++counters_.scans_unverified;
      predicted(r, T_predicted);
      return r;
    }
    r.status = ScanStatus::kMatched;
    r.T_map_base = m.T_map_base;
    r.covariance = m.covariance;
  }
  ++counters_.scans_matched;
  motion_.add_pose(r.utime, r.T_map_base, r.covariance, r.sparse);
  const bool key = !T_map_base_last_key_ || [&] {
    const Pose2 step = between(*T_map_base_last_key_, r.T_map_base);
    return step.translation().norm() >= config_.icp.key_distance_m ||
           std::abs(step.theta()) >= config_.icp.key_angle_rad;
  }();
  if (key) {
    add_to_map(points.points_base, r.T_map_base);
    d.map_updated = true;
  }
  return r;
}

void IcpFrontend::predicted(FrontendResult& r, const Pose2& T_predicted) {
  r.status = ScanStatus::kPredicted;
  r.T_map_base = T_predicted;
  const double sxy = config_.icp.prior_sigma_xy_m, sth = config_.icp.prior_sigma_theta_rad;
  r.covariance = motion_.last_covariance() +
                 Eigen::Matrix3d(Eigen::Vector3d(sxy * sxy, sxy * sxy, sth * sth).asDiagonal());
  // A blind first scan leaves the motion model where the trajectory starts.
  if (motion_.initialised()) {
    motion_.add_prediction(r.utime, r.T_map_base, r.covariance, r.sparse);
  }
}

void IcpFrontend::add_to_map(const std::vector<Eigen::Vector2d>& points_base,
                             const Pose2& T_map_base) {
  const IcpConfig& c = config_.icp;
  const std::vector<Eigen::Vector2d> kept = subsample(points_base, c.point_spacing_m);
  const auto normals = scan_normals(kept, c.normal_radius_m, c.max_line_spread);
  const Eigen::Matrix2d R = T_map_base.rotation();
  std::vector<MapPoint> points;
  for (std::size_t i = 0; i < kept.size(); ++i) {
    if (normals[i]) points.push_back({T_map_base * kept[i], R * *normals[i]});
  }
  map_.add(points);
  T_map_base_last_key_ = T_map_base;
  ++counters_.map_updates;
  counters_.map_cells_dropped += map_.drop_beyond(T_map_base.translation(), c.map_radius_m);
}

void IcpFrontend::report(const CounterSink& sink) const {
  const Counters& c = counters_;
  sink("scans_received", static_cast<double>(c.scans_received));
  sink("scans_matched", static_cast<double>(c.scans_matched));
  sink("scans_predicted", static_cast<double>(c.scans_predicted));
  sink("scans_unverified", static_cast<double>(c.scans_unverified));
  sink("scans_dropped_time", static_cast<double>(c.scans_dropped_time));
  sink("readings_invalid", static_cast<double>(c.readings_invalid));
  sink("map_updates", static_cast<double>(c.map_updates));
  sink("map_points", static_cast<double>(map_.points()));
  sink("map_cells_dropped", static_cast<double>(c.map_cells_dropped));
  sink("icp_iterations", static_cast<double>(c.icp_iterations));
  sink("imu_samples", static_cast<double>(c.imu_samples));
  sink("imu_dropped", static_cast<double>(c.imu_dropped));
  sink("odometry_samples", static_cast<double>(c.odometry_samples));
  sink("odometry_dropped", static_cast<double>(c.odometry_dropped));
}

}  // namespace traverse::frontend
