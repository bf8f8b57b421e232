// A dense_segment_t (the densifier's corrected trajectory piece) as the mapper's
// TrajectorySegment: what the mapper and the viewer both place points with. The revision stays
// with the caller, which judges it against what it already holds.
#pragma once

#include "trajectory_store.hpp"
#include "traverse/dense_segment_t.hpp"

namespace traverse::mapper {

inline TrajectorySegment segment_of(const dense_segment_t& msg) {
  TrajectorySegment s;
  s.key_id_first = msg.key_id_first;
  s.utimes = msg.pose_utime;
  for (int i = 0; i < msg.n_poses; ++i)
    s.T_world_base.emplace_back(msg.x[i], msg.y[i], msg.theta[i]);
  return s;
}

}  // namespace traverse::mapper
