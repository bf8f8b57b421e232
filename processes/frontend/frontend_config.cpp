#include "frontend_config.hpp"

#include <algorithm>
#include <cmath>

#include "config.hpp"

namespace traverse::frontend {
namespace {

// A correlative search over +-window_m in x and y on cells of cell_m is exhaustive over (2
// window_m / cell_m + 1)^2 translations per heading: more than this many cells either side take
// seconds per scan.
constexpr double kMaxSearchCells = 200.0;

}  // namespace

std::optional<std::string> validate(const MapConfig& c) {
  ConfigCheck check;
  check.in_range("resolution_m", c.resolution_m, 0.005, 1.0);
  check.in_range("levels", c.levels, 1, 8);
  check.require(c.p_occupied > 0.5 && c.p_occupied < 1.0, "p_occupied", "must be in (0.5, 1)");
  check.require(c.p_free > 0.0 && c.p_free < 0.5, "p_free", "must be in (0, 0.5)");
  check.not_negative("update_distance_m", c.update_distance_m);
  check.not_negative("update_angle_rad", c.update_angle_rad);
  check.positive("max_bytes", c.max_bytes);
  return check.problem();
}

std::optional<std::string> validate(const MatcherConfig& c) {
  ConfigCheck check;
  check.in_range("iterations_coarse", c.iterations_coarse, 1, 1000);
  check.in_range("iterations_fine", c.iterations_fine, 1, 1000);
  check.not_negative("min_point_spacing_m", c.min_point_spacing_m);
  check.positive("min_valid_points", c.min_valid_points);
  check.not_negative("min_range_m", c.min_range_m);
  check.require(c.max_range_m > c.min_range_m, "max_range_m", "must exceed min_range_m");
  check.positive("prior_sigma_xy_m", c.prior_sigma_xy_m);
  check.positive("prior_sigma_theta_rad", c.prior_sigma_theta_rad);
  check.positive("min_residual_sigma", c.min_residual_sigma);
  check.not_negative("coarse_check_m", c.coarse_check_m);
  check.in_range("coarse_check_gain", c.coarse_check_gain, 0.0, 1.0);
  check.not_negative("coarse_check_max_gap_us", c.coarse_check_max_gap_us);
  check.not_negative("degeneracy_hold_after_s", c.degeneracy_hold_after_s);
  check.not_negative("degeneracy_hold_max_s", c.degeneracy_hold_max_s);
  check.not_negative("search_trigger_residual", c.search_trigger_residual);
  check.positive("search_linear_window_m", c.search_linear_window_m);
  check.require(c.search_angular_window_rad > 0.0 && c.search_angular_window_rad <= M_PI,
                "search_angular_window_rad", "must be in (0, pi]");
  check.not_negative("search_max_unverified_m", c.search_max_unverified_m);
  check.not_negative("search_max_unverified_rad", c.search_max_unverified_rad);
  check.positive("wide_search_gap_us", c.wide_search_gap_us);
  check.positive("wide_search_linear_window_m", c.wide_search_linear_window_m);
  check.require(
      c.wide_search_angular_window_rad > 0.0 && c.wide_search_angular_window_rad <= 3.1416,
      "wide_search_angular_window_rad", "must be in (0, pi]");
  check.in_range("wide_search_temperature", c.wide_search_temperature, 0.0, 100.0);
  check.in_range("sparse_ensemble_members", c.sparse_ensemble_members, 1, 16);
  check.positive("sparse_step_min_travel_m", c.sparse_step_min_travel_m);
  check.positive("sparse_step_min_turn_rad", c.sparse_step_min_turn_rad);
  check.not_negative("sparse_step_short_weight", c.sparse_step_short_weight);
  check.not_negative("sparse_step_off_arc_free_m", c.sparse_step_off_arc_free_m);
  check.not_negative("sparse_step_off_arc_weight", c.sparse_step_off_arc_weight);
  check.positive("sparse_lag_window_m", c.sparse_lag_window_m);
  check.require(c.sparse_lag_window_rad > 0.0 && c.sparse_lag_window_rad <= M_PI,
                "sparse_lag_window_rad", "must be in (0, pi]");
  check.not_negative("sparse_lag_long_weight", c.sparse_lag_long_weight);
  check.not_negative("sparse_lag_margin", c.sparse_lag_margin);
  check.in_range("sparse_widen_evidence_ratio", c.sparse_widen_evidence_ratio, 0.0, 1.0);
  check.require(c.sparse_widen_factor > 1.0, "sparse_widen_factor", "must be above 1");
  check.positive("sparse_widen_max_window_m", c.sparse_widen_max_window_m);
  check.in_range("degeneracy_min_ratio", c.degeneracy_min_ratio, 0.0, 1.0);
  check.in_range("moved_max_probability", c.moved_max_probability, 0.0, 0.5);
  return check.problem();
}

std::optional<std::string> validate(const DeskewConfig& c) {
  ConfigCheck check;
  check.in_range("imu_roll_rad", c.imu_roll_rad, -2.0 * M_PI, 2.0 * M_PI);
  check.in_range("imu_pitch_rad", c.imu_pitch_rad, -2.0 * M_PI, 2.0 * M_PI);
  check.in_range("imu_yaw_rad", c.imu_yaw_rad, -2.0 * M_PI, 2.0 * M_PI);
  check.in_range<int64_t>("imu_wait_us", c.imu_wait_us, 0, 10'000'000);
  return check.problem();
}

std::optional<std::string> validate(const MotionPriorConfig& c) {
  ConfigCheck check;
  check.require(
      c.source == "imu" || c.source == "odometry" || c.source == "both" || c.source == "none",
      "source", "must be one of imu, odometry, both, none, got '" + c.source + "'");
  check.in_range<int64_t>("odometry_max_gap_us", c.odometry_max_gap_us, 1, 60'000'000);
  check.in_range<int64_t>("odometry_max_extrapolation_us", c.odometry_max_extrapolation_us, 0,
                          10'000'000);
  check.in_range("odometry_sigma_xy_m", c.odometry_sigma_xy_m, 0.0, 10.0);
  check.in_range("odometry_sigma_xy_per_m", c.odometry_sigma_xy_per_m, 0.0, 10.0);
  check.in_range("odometry_sigma_theta_rad", c.odometry_sigma_theta_rad, 0.0, M_PI);
  check.in_range("odometry_sigma_theta_per_m", c.odometry_sigma_theta_per_m, 0.0, 10.0);
  check.in_range("odometry_sigma_theta_per_rad", c.odometry_sigma_theta_per_rad, 0.0, 10.0);
  check.in_range("search_sigmas", c.search_sigmas, 0.5, 100.0);
  check.in_range("odometry_check_margin", c.odometry_check_margin, 0.0, 2.0);
  check.in_range("odometry_check_sigmas", c.odometry_check_sigmas, 0.0, 100.0);
  check.in_range("search_min_linear_m", c.search_min_linear_m, 0.0, 100.0);
  check.in_range("search_min_angular_rad", c.search_min_angular_rad, 0.0, M_PI);
  check.in_range("prediction_sigma_mps", c.prediction_sigma_mps, 0.0, 100.0);
  check.in_range("prediction_sigma_radps", c.prediction_sigma_radps, 0.0, 100.0);
  check.in_range("max_acceleration_mps2", c.max_acceleration_mps2, 0.0, 1000.0);
  return check.problem();
}

std::optional<std::string> validate(const FrontendConfig& c) {
  ConfigCheck check;
  check.require(c.kind == "hector" || c.kind == "icp", "kind",
                "must be hector or icp, got '" + c.kind + "'");
  check.not_empty("scan_channel", c.scan_channel);
  check.not_empty("imu_channel", c.imu_channel);
  check.not_empty("odometry_channel", c.odometry_channel);
  check.not_empty("pose_channel", c.pose_channel);
  check.nested("T_base_laser", validate(c.T_base_laser));
  check.nested("initial_pose", validate(c.initial_pose));
  check.nested("map", validate(c.map));
  check.nested("matcher", validate(c.matcher));
  check.nested("deskew", validate(c.deskew));
  check.nested("motion_prior", validate(c.motion_prior));
  check.nested("icp", validate(c.icp));
  check.nested("handover", validate(c.handover));
  check.nested("calibration",
               validate(static_cast<const calibration::ExtrinsicYawConfig&>(c.calibration)));
  if (check.problem()) return check.problem();
  // The searches' windows in cells of the level each runs on: the recovery search on the
  // coarsest, the wide search on level 1 (or 0 with one level).
  const double coarsest_m = c.map.resolution_m * std::ldexp(1.0, c.map.levels - 1);
  const double wide_m = c.map.resolution_m * std::ldexp(1.0, std::min(1, c.map.levels - 1));
  check.require(c.matcher.search_linear_window_m / coarsest_m <= kMaxSearchCells,
                "matcher.search_linear_window_m",
                "must be at most 200 cells of the coarsest map level");
  check.require(c.matcher.wide_search_linear_window_m / wide_m <= kMaxSearchCells,
                "matcher.wide_search_linear_window_m", "must be at most 200 cells of map level 1");
  check.require(c.matcher.sparse_lag_window_m <= c.matcher.wide_search_linear_window_m,
                "matcher.sparse_lag_window_m", "must be at most wide_search_linear_window_m");
  check.require(
      !c.matcher.degeneracy_hold_without_odometry || c.motion_prior.max_acceleration_mps2 > 0.0,
      "matcher.degeneracy_hold_without_odometry",
      "needs motion_prior.max_acceleration_mps2 > 0 (an unbounded velocity is no "
      "prediction to hold)");
  return check.problem();
}

}  // namespace traverse::frontend
