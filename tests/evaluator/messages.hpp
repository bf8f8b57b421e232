// Messages of the backend and densifier built from the synthetic circle, for the collector and
// program tests.
#pragma once

#include <cstdint>
#include <vector>

#include "synthetic.hpp"
#include "traverse/dense_segments_t.hpp"
#include "traverse/key_poses_t.hpp"
#include "traverse/pose2d_t.hpp"

namespace traverse::evaluator::test {

// A trajectory pose as a pose2d_t message (frames left empty).
inline pose2d_t pose_message(const StampedPose& p) {
  pose2d_t msg{};
  msg.utime = p.utime;
  msg.x = p.pose.x();
  msg.y = p.pose.y();
  msg.theta = p.pose.theta();
  return msg;
}

inline Pose2 circle_at(int64_t utime_us) {
  return circle_pose(1e-6 * static_cast<double>(utime_us));
}

// Key pose `id` at utime on the circle, `dx_m` off in x.
inline key_pose_t key_pose(int64_t id, int64_t utime_us, double dx_m = 0.0) {
  key_pose_t p{};
  const Pose2 T = circle_at(utime_us);
  p.utime = utime_us;
  p.id = id;
  p.x = T.x() + dx_m;
  p.y = T.y();
  p.theta = T.theta();
  return p;
}

inline key_poses_t key_poses(int32_t optimisation, const std::vector<key_pose_t>& poses,
                             const std::vector<loop_closure_t>& closures = {}) {
  key_poses_t m{};
  m.utime = poses.empty() ? 0 : poses.back().utime;
  m.optimisation = optimisation;
  m.parts = 1;
  m.poses = poses;
  m.n_poses = static_cast<int32_t>(poses.size());
  m.closures = closures;
  m.n_closures = static_cast<int32_t>(closures.size());
  return m;
}

// A closure from the true relative pose with error `error` (e = t2v(Z^-1 T_true) = error) and a
// diagonal covariance of standard deviations sigma_xy_m, sigma_xy_m, sigma_theta_rad.
inline loop_closure_t loop_closure(int64_t from_id, int64_t to_id, int64_t from_us, int64_t to_us,
                                   const Pose2& error, double sigma_xy_m = 0.01,
                                   double sigma_theta_rad = 0.005) {
  loop_closure_t l{};
  l.utime = to_us;
  l.from_utime = from_us;
  l.from_id = from_id;
  l.to_id = to_id;
  const Pose2 Z = between(circle_at(from_us), circle_at(to_us)) * error.inverse();
  l.x = Z.x();
  l.y = Z.y();
  l.theta = Z.theta();
  l.covariance[0] = l.covariance[4] = sigma_xy_m * sigma_xy_m;
  l.covariance[8] = sigma_theta_rad * sigma_theta_rad;
  l.response = 0.8;
  l.candidates = 1;
  return l;
}

// Segment from key pose `first` to first + 1: poses every 50 ms over [t0_us, t0_us + 1 s], both
// ends included, `dx_m` off in x.
inline dense_segment_t dense_segment(int64_t first, int32_t revision, int64_t t0_us, double dx_m) {
  dense_segment_t s{};
  s.key_id_first = first;
  s.key_id_last = first + 1;
  s.revision = revision;
  for (int64_t t = t0_us; t <= t0_us + 1'000'000; t += 50'000) {
    const Pose2 T = circle_at(t);
    s.pose_utime.push_back(t);
    s.x.push_back(T.x() + dx_m);
    s.y.push_back(T.y());
    s.theta.push_back(T.theta());
  }
  s.n_poses = static_cast<int32_t>(s.pose_utime.size());
  return s;
}

inline dense_segments_t dense_segments(const std::vector<dense_segment_t>& segments) {
  dense_segments_t m{};
  m.utime = 0;
  m.parent_frame = "world";
  m.child_frame = "base";
  m.parts = 1;
  m.segments = segments;
  m.n_segments = static_cast<int32_t>(segments.size());
  return m;
}

}  // namespace traverse::evaluator::test
