// A second kind of frontend: point-to-line ICP against a map of key scans' points (icp_matcher.hpp,
// point_map.hpp), for the same messages as the Hector frontend and interchangeable with it at run
// time (frontend_node.hpp, handover.hpp). Per scan:
//   1. keep the valid readings (too few: the pose is predicted, flagged);
//   2. predict the pose at the scan's last point with the Hector core's motion model (IMU,
//      odometry as the motion prior combines them, the velocity of the last poses);
//   3. undo the motion during the sweep as the Hector core does (hector/deskew.hpp);
//   4. match the points against the map from the prediction (point-to-line ICP, a weak prior
//      towards the prediction);
//   5. a match that pairs fewer than min_inlier_fraction of the points is not trusted: the pose is
//      the prediction, flagged, and the scan stays out of the map;
//   6. the pose goes into the motion model, and the scan with its normals into the map when the
//      pose moved key_distance_m or turned key_angle_rad since the last one.
// The first scan is placed at initial_pose. It has no wide search: it is meant for a scanner's
// stream (tens of scans a second), not for logs subsampled by travel, where the Hector frontend's
// sparse path (sparse/) is the one to use.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>

#include "frontend.hpp"
#include "hector/motion_model.hpp"
#include "hector/scan_points.hpp"
#include "point_map.hpp"

namespace traverse::frontend {

class IcpFrontend final : public Frontend {
 public:
  // The config must pass validate(); the trajectory starts at config.initial_pose.
  explicit IcpFrontend(const FrontendConfig& config);

  bool add_imu(int64_t utime, const Eigen::Vector3d& angular_velocity_imu) override;
  bool add_odometry(const OdometrySample& odometry) override;
  FrontendResult process(const Scan& scan) override;
  std::optional<FrontendResult> finish() override { return std::nullopt; }
  std::size_t map_bytes() const override { return map_.memory_bytes(); }
  void report(const CounterSink& sink) const override;

  const PointMap& map() const { return map_; }

 private:
  struct Counters {
    int64_t scans_received = 0;
    int64_t scans_matched = 0;
    int64_t scans_predicted = 0;   // too few valid points
    int64_t scans_unverified = 0;  // too few points paired: predicted
    int64_t scans_dropped_time = 0;
    int64_t readings_invalid = 0;
    int64_t map_updates = 0;
    int64_t map_cells_dropped = 0;
    int64_t icp_iterations = 0;
    int64_t imu_samples = 0;
    int64_t imu_dropped = 0;
    int64_t odometry_samples = 0;
    int64_t odometry_dropped = 0;
  };
  // The scan's points (base frame, de-skewed) into the map at T_map_base.
  void add_to_map(const std::vector<Eigen::Vector2d>& points_base, const Pose2& T_map_base);
  void predicted(FrontendResult& r, const Pose2& T_predicted);

  FrontendConfig config_;
  Pose2 T_initial_;
  ScanPointMaker scan_points_;
  MotionModel motion_;
  PointMap map_;
  std::optional<Pose2> T_map_base_last_key_;
  Counters counters_;
};

}  // namespace traverse::frontend
