// Adapts LCM messages to the frontend (frontend.hpp, made by make_frontend()): planar_scan_t,
// imu_t and odometry_t in, pose2d_t out (parent "map", child "base", one per scan, FLAG_PREDICTED
// when the frontend says kPredicted), the frontend's counters into the process status. A scan waits
// until IMU samples cover its last point (or until a scan imu_wait_us later has arrived, or for
// good when no IMU publishes), because a log player delivers a sweep at its first point's time,
// before the IMU samples taken during the sweep; likewise for odometry, once any has come (its
// messages may trail the scan). A frontend may give a pose a scan late (on a log subsampled by
// travel: MatcherConfig:: sparse_lag), the last one at shutdown (flush(true)).
//
// Handover (handover.hpp): a frontend_control_t on handover.control_channel naming another kind
// replaces the running frontend between two scans by one of that kind, started from the recent
// scans and aligned with the last published pose; the status says which kind runs
// (frontend_kind_icp), how many swaps were made and the last request carried out
// (frontend_request_id), which is what the sender waits for. With a state directory the recent
// window is saved (every handover.save_period_s of data and at the end) and a node started on it
// again resumes from it: a mapping session continued later, or a frontend restarted after a crash.
// Its first scans are checked against the saved ones (resume_failure() says why not).
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <future>
#include <memory>
#include <optional>
#include <string>

#include "bus.hpp"
#include "frontend.hpp"
#include "handover.hpp"
#include "traverse/frontend_control_t.hpp"
#include "traverse/imu_t.hpp"
#include "traverse/odometry_t.hpp"
#include "traverse/planar_scan_t.hpp"

namespace traverse::frontend {

class FrontendNode {
 public:
  using CounterSink = std::function<void(const std::string& name, double value)>;
  // With `state_dir`: resumes from the state saved there, if any (throws std::runtime_error when
  // that state is damaged), and saves its own there.
  FrontendNode(Bus& bus, const FrontendConfig& config, CounterSink counters = {},
               const std::string& state_dir = "");
  ~FrontendNode();  // waits for a save being written

  // Processes every scan that is ready; all waiting scans, and the one the lag holds, if `all`
  // (at shutdown).
  void flush(bool all = false);
  // Copies the frontend's counters to the sink (status counters of the process).
  void report_counters();
  // Writes the recent window to the state directory (if any) and waits for it; `durable`:
  // flushed to the disk before it takes effect (the end of a session; the periodic saves for a
  // crash need not be, since a killed process loses nothing the kernel already holds).
  void save_state(bool durable = true);
  const Frontend& frontend() const { return *frontend_; }
  const std::string& kind() const { return kind_; }
  // Resumed from a saved state: scans re-tracked; the first scans' check failed: why (the node
  // then publishes nothing more).
  std::optional<int> resumed_scans() const { return resumed_scans_; }
  const std::string& resume_failure() const { return resume_failure_; }

 private:
  void save_in_background();
  void on_scan(const planar_scan_t& msg);
  void on_imu(const imu_t& msg);
  void on_odometry(const odometry_t& msg);
  void on_control(const frontend_control_t& msg);
  void publish(const FrontendResult& result);
  // Replaces the frontend by one of `kind` started from the recent window.
  void hand_over(const std::string& kind);
  // The resumed session's check of a scan's published pose against the saved scans.
  bool check_resumed(const Scan& scan, const Pose2& T_map_base);

  Bus& bus_;
  FrontendConfig config_;
  std::string kind_;
  std::unique_ptr<Frontend> frontend_;
  CounterSink counters_;
  std::deque<Scan> pending_;
  std::optional<int64_t> last_imu_utime_;       // [us] of the newest IMU sample the frontend took
  std::optional<int64_t> last_odometry_utime_;  // [us] of the newest odometry sample it took
  Handover handover_;
  Pose2 C_;  // published pose = C_ * the frontend's own (identity until a handover)
  int64_t last_request_id_ = 0;
  int64_t swaps_ = 0, control_rejected_ = 0;
  double last_misfit_m_ = 0.0, last_misfit_rad_ = 0.0;
  std::string state_dir_;
  int64_t last_saved_utime_ = INT64_MIN;
  // The periodic saves: the window is serialised on this thread, written on another (a 16 MB
  // write held the scans up by 0.1 to 0.2 s); one at a time, a save due while the last one is
  // still being written is skipped.
  std::future<bool> writing_;
  long saves_ = 0, saves_skipped_ = 0;
  double save_total_s_ = 0.0, save_max_s_ = 0.0;  // [s] wall time this thread spent on them
  double state_bytes_ = 0.0;                      // [bytes] of the last save
  std::optional<int> resumed_scans_;
  std::optional<Handover> saved_;  // the saved window, while the first scans are checked
  int checks_left_ = 0;
  double worst_fit_ = 1.0;
  std::string resume_failure_;
};

}  // namespace traverse::frontend
