// The final trajectory of a stage whose estimates are revised after every optimisation: the
// backend's key poses (each message holds the key poses that appeared or moved) and the
// densifier's segments (each message holds segments that are new or that an optimisation moved).
// Only the newest version of each piece counts; the estimate is all pieces at their newest.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>

#include "trajectory.hpp"

namespace traverse::evaluator {

// Key poses by id: a later update of an id replaces the earlier one (messages are applied in the
// order they were received, which is the backend's publishing order).
class KeyPoseTrajectory {
 public:
  void update(int64_t id, const StampedPose& pose);
  // Every id at its newest pose, in time order; non-finite poses are left out.
  Trajectory trajectory() const;
  std::size_t size() const { return by_id_.size(); }
  std::size_t replaced() const { return replaced_; }  // updates that moved an existing id

 private:
  std::map<int64_t, StampedPose> by_id_;
  std::size_t replaced_ = 0;
};

struct DenseSegment {
  int64_t key_id_first = 0;  // backend id of the key pose that starts the segment
  int64_t key_id_last = 0;   // backend id of the key pose that ends it
  int32_t revision = 0;      // 0 when first sent, +1 each time an optimisation moved it
  Trajectory poses;          // both end poses included, increasing time
};

// Segments by key_id_first: a higher revision replaces a lower one; an equal revision received
// later replaces the earlier one (a resend); a lower revision received late is ignored.
class DenseTrajectory {
 public:
  // True when the segment was kept.
  bool update(DenseSegment segment);
  // The union of the newest segments in key-id order. Neighbouring segments share their end pose
  // (same time): it is kept once, from the earlier segment. Non-finite poses are left out.
  Trajectory trajectory() const;
  std::size_t size() const { return by_first_.size(); }
  std::size_t stale() const { return stale_; }  // updates ignored for a lower revision

 private:
  std::map<int64_t, DenseSegment> by_first_;
  std::size_t stale_ = 0;
};

}  // namespace traverse::evaluator
