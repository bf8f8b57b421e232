#include "sim_node.hpp"

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

void publish_event(Publisher& publisher, const SimEvent& ev) {
  switch (ev.kind) {
    case SimEvent::Kind::kGroundTruth: {
      auto m = to_message(ev.ground_truth);
      publisher.publish(channels::kPoseGroundTruth, m);
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
