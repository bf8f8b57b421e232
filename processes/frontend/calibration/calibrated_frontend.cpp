#include "calibrated_frontend.hpp"

namespace traverse::frontend {

CalibratedFrontend::CalibratedFrontend(std::unique_ptr<Frontend> inner,
                                       const FrontendConfig& config)
    : FrontendWrapper(std::move(inner)),
      T_initial_(config.initial_pose.pose()),
      yaw_(config.calibration) {}

bool CalibratedFrontend::add_odometry(const OdometrySample& odometry) {
  OdometrySample o = odometry;
  o.T_odom_base = odometry.T_odom_base * Pose2(0.0, 0.0, yaw_.yaw_rad().value_or(0.0));
  return inner_->add_odometry(o);
}

FrontendResult CalibratedFrontend::process(const Scan& scan) {
  return calibrated(inner_->process(scan));
}

std::optional<FrontendResult> CalibratedFrontend::finish() {
  auto result = inner_->finish();
  if (result) return calibrated(*result);
  return std::nullopt;
}

Pose2 CalibratedFrontend::to_base(const Pose2& T_map_bhat, double delta) const {
  return calibration::turned_about(T_map_bhat, T_initial_.translation(), delta);
}

FrontendResult CalibratedFrontend::calibrated(FrontendResult r) {
  if (r.status == ScanStatus::kMatched) yaw_.add_pose(r.T_map_base);
  const auto delta = yaw_.yaw_rad();
  if (!delta || !r.has_pose()) return r;
  r.T_map_base = to_base(r.T_map_base, *delta);
  r.covariance = rotate_covariance(r.covariance, Pose2(0.0, 0.0, *delta).rotation());
  if (r.diagnostics) {
    r.diagnostics->T_map_base_predicted = to_base(r.diagnostics->T_map_base_predicted, *delta);
  }
  return r;
}

void CalibratedFrontend::report(const CounterSink& sink) const {
  inner_->report(sink);
  sink("extrinsic_yaw_rad", yaw_.yaw_rad().value_or(0.0));
  sink("extrinsic_yaw_chords", static_cast<double>(yaw_.chords()));
  sink("extrinsic_yaw_travel_m", yaw_.travel_m());
}

}  // namespace traverse::frontend
