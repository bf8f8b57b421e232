// Adapts pose2d_t messages to the evaluator: collects the estimate and reference channels from a
// live bus or from an LCM log read event by event.
#pragma once

#include <cstddef>
#include <string>

#include "bus.hpp"
#include "trajectory.hpp"
#include "traverse/pose2d_t.hpp"

namespace traverse::evaluator {

class PoseCollector {
 public:
  PoseCollector(std::string estimate_channel, std::string reference_channel);

  // Live: every pose on the two channels (one subscription when they are the same channel).
  void subscribe(Bus& bus);

  struct LogSummary {
    std::size_t events = 0;           // events read
    std::size_t decode_failures = 0;  // events on our channels that are not pose2d_t
    std::size_t damaged_records = 0;  // damaged places the reader skipped
  };
  // Offline: every pose on the two channels of an LCM log. Throws std::runtime_error if the file
  // cannot be opened.
  LogSummary read_log(const std::string& path);

  const Trajectory& estimate() const { return estimate_; }
  const Trajectory& reference() const { return reference_; }
  // Poses with a NaN or infinite coordinate: dropped, they would poison every figure.
  std::size_t non_finite_poses() const { return non_finite_poses_; }

 private:
  void add(const std::string& channel, const pose2d_t& msg);

  std::string estimate_channel_;
  std::string reference_channel_;
  Trajectory estimate_;
  Trajectory reference_;
  std::size_t non_finite_poses_ = 0;
};

}  // namespace traverse::evaluator
