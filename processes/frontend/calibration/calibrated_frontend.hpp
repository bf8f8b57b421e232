// A frontend of any kind wrapped so that its poses come out in the frame of the base the rig
// file meant, with the scanner's yaw on the cart estimated while it runs
// (common/extrinsic_yaw.hpp).
//
// The inner frontend matches scans in the frame bhat the rig file's T_base_laser gives the scans
// (the true base turned by the scanner's yaw error delta, T_base_bhat = Rot(delta)); its map and
// poses are consistent in that frame. The true base relative to the first scan's is then
// T_base0_base = Rot(delta) T_bhat0_bhat Rot(-delta), and with the map frame placed at
// initial_pose (T_map_base0 = T0) each published pose is T0 Rot(delta) T0^-1 T_map_bhat
// Rot(-delta): its position turned by delta about the first pose's, its heading as matched, its
// covariance's x-y block turned alike. Wheel odometry measures the true base and goes in as
// bhat's: T_odom_bhat = T_odom_base Rot(delta). Before the estimate holds, delta is 0 (the rig
// file as written). Only matched poses feed the estimate.
#pragma once

#include <memory>
#include <optional>

#include "extrinsic_yaw.hpp"
#include "frontend.hpp"
#include "two_phase.hpp"

namespace traverse::frontend {

class CalibratedFrontend final : public FrontendWrapper<Frontend> {
 public:
  CalibratedFrontend(std::unique_ptr<Frontend> inner, const FrontendConfig& config);

  bool add_odometry(const OdometrySample& odometry) override;
  FrontendResult process(const Scan& scan) override;
  std::optional<FrontendResult> finish() override;
  void report(const CounterSink& sink) const override;

 private:
  // The inner frontend's result in the base's frame (see the header), fed to the estimate first.
  FrontendResult calibrated(FrontendResult result);
  Pose2 to_base(const Pose2& T_map_bhat, double delta) const;

  Pose2 T_initial_;
  calibration::ExtrinsicYawEstimator yaw_;
};

}  // namespace traverse::frontend
