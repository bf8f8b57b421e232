// The backend's state on disk, so that a backend killed mid-run and restarted by the launcher, or
// a mapping session stopped and started again later, carries on with the same graph instead of an
// empty one (docs/deployment.md, "Crash recovery and sessions").
//
// A state directory holds
//   - key_scans.rec: one record per key scan (its reduced points, base frame), appended as each
//     key pose is added: a key scan never changes once stored (state_file.hpp, RecordLog);
//   - graph.state: a snapshot, rewritten atomically: the pose graph (vertices, edges and their
//     kinds), the key poses with their marginal covariances, the loop closures, the last key
//     pose's prepared and frontend pose (where the trajectory goes on from), the counters, and the
//     number of key scans it covers.
// The snapshot is written after an optimisation when period_us of data time has passed since the
// last one, and at the end: a backend killed between two snapshots loses the key poses since the
// last one (at most period_us of data) and what came while it was down, and goes on from there.
// What is not kept, because it is rebuilt from the next messages: the frontend poses not yet key
// poses, scans waiting for their pose, odometry, an open loop-closure episode (its candidates are
// tried again as the platform passes) and the loop closer's counters.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "backend.hpp"
#include "state_file.hpp"

namespace traverse::backend {

struct BackendStateCounters {
  long snapshots = 0;                // snapshots written
  long snapshot_failures = 0;        // ... that could not be written (the previous one stands)
  double last_snapshot_s = 0.0;      // [s] wall time of the last snapshot (scans synced and graph)
  double total_snapshot_s = 0.0;     // [s]
  double last_snapshot_bytes = 0.0;  // [bytes] of graph.state
  long key_scans_appended = 0;
};

// What a resume found.
struct ResumedState {
  int key_poses = 0;
  int closures = 0;
  int64_t last_key_utime = 0;  // [us] where the trajectory goes on from
};

class BackendStateStore {
 public:
  // Keeps the state in `dir` (created if missing), a snapshot every period_us of data time;
  // `durable`: flushed to the disk before each snapshot takes effect (state_file.hpp).
  BackendStateStore(std::string dir, int64_t period_us, bool durable);

  // Loads the state of `dir` into `backend`, which must be new (nothing added yet). nullopt when
  // `dir` holds no state; throws std::runtime_error naming the file when the state there is
  // damaged (the backend must not go on as if it had none: that would fork the map).
  std::optional<ResumedState> resume(Backend& backend);
  // After the backend changed: appends the key scans not yet stored, and writes the snapshot if
  // period_us of data time passed since the last one, or if `now`.
  void persist(const Backend& backend, bool now = false);

  const BackendStateCounters& counters() const { return counters_; }
  const std::string& dir() const { return dir_; }

 private:
  std::string snapshot(const Backend& backend) const;

  std::string dir_;
  int64_t period_us_;
  bool durable_;
  RecordLog scans_;
  int scans_stored_ = 0;
  int64_t last_snapshot_utime_ = INT64_MIN;
  BackendStateCounters counters_;
};

}  // namespace traverse::backend
