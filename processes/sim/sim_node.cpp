#include "sim_node.hpp"

#include <algorithm>
#include <cmath>

#include "channels.hpp"

namespace traverse::sim {

planar_scan_t to_message(const ScanData& scan) {
  planar_scan_t m{};
  m.utime = scan.utime_first;
  m.frame = scan.frame;
  m.utime_first = scan.utime_first;
  m.utime_last = scan.utime_last;
  m.angle_first = scan.angle_first;
  m.angle_step = scan.angle_step;
  m.range_min = scan.range_min;
  m.range_max = scan.range_max;
  m.n_ranges = static_cast<int32_t>(scan.ranges.size());
  m.ranges = scan.ranges;
  m.n_intensities8 = static_cast<int32_t>(scan.intensities.size());
  m.intensities8.assign(scan.intensities.begin(), scan.intensities.end());
  m.n_intensities16 = 0;
  return m;
}

imu_t to_message(const ImuData& imu) {
  imu_t m{};
  m.utime = imu.utime;
  m.frame = "imu";
  for (int i = 0; i < 3; ++i) {
    m.angular_velocity[i] = imu.angular_velocity[i];
    m.linear_acceleration[i] = imu.linear_acceleration[i];
  }
  return m;
}

pose2d_t to_message(const GroundTruth& gt) {
  pose2d_t m{};
  m.utime = gt.utime;
  m.parent_frame = "world";
  m.child_frame = "base";
  m.x = gt.T_world_base.x();
  m.y = gt.T_world_base.y();
  m.theta = gt.T_world_base.theta();
  for (double& c : m.covariance) c = 0.0;
  m.flags = 0;
  return m;
}

pose3d_t to_message_3d(const GroundTruth& gt) {
  pose3d_t m{};
  m.utime = gt.utime;
  m.parent_frame = "world";
  m.child_frame = "base";
  const Eigen::Isometry3d& T = gt.T_world_base_3d;
  for (int i = 0; i < 3; ++i) m.position[i] = T.translation()[i];
  const Eigen::Quaterniond q(T.linear());
  m.orientation[0] = q.w();
  m.orientation[1] = q.x();
  m.orientation[2] = q.y();
  m.orientation[3] = q.z();
  const Eigen::Matrix3d& R = T.linear();
  m.yaw = std::atan2(R(1, 0), R(0, 0));
  m.pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  m.roll = std::atan2(R(2, 1), R(2, 2));
  return m;
}

odometry_t to_message(const OdometryData& odom) {
  odometry_t m{};
  m.utime = odom.utime;
  m.parent_frame = "odom";
  m.child_frame = "base";
  m.x = odom.x;
  m.y = odom.y;
  m.theta = odom.theta;
  for (int i = 0; i < 9; ++i) {
    m.pose_covariance[i] = odom.pose_covariance[i];
    m.velocity_covariance[i] = odom.velocity_covariance[i];
  }
  m.velocity[0] = odom.forward;
  m.velocity[1] = 0.0;
  m.velocity[2] = odom.turn;
  return m;
}

void publish_event(Publisher& publisher, const SimEvent& ev, bool publish_3d) {
  switch (ev.kind) {
    case SimEvent::Kind::kGroundTruth: {
      auto m = to_message(ev.ground_truth);
      publisher.publish(channels::kPoseGroundTruth, m);
      if (publish_3d) {
        auto m3 = to_message_3d(ev.ground_truth);
        publisher.publish(channels::kPoseGroundTruth3d, m3);
      }
      break;
    }
    case SimEvent::Kind::kOdometry: {
      auto m = to_message(ev.odometry);
      publisher.publish(channels::kOdometry, m);
      break;
    }
    case SimEvent::Kind::kImu: {
      auto m = to_message(ev.imu);
      publisher.publish(channels::kImu, m);
      break;
    }
    case SimEvent::Kind::kScanHorizontal: {
      auto m = to_message(ev.scan);
      publisher.publish(channels::kScanHorizontal, m);
      break;
    }
    case SimEvent::Kind::kScanProfile: {
      auto m = to_message(ev.scan);
      publisher.publish(channels::kScanProfile, m);
      break;
    }
  }
}

}  // namespace traverse::sim
