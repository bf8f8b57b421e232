// Adapts LCM messages to the Mapper: tilted profiles (planar_scan_t on SCAN_PROFILE) and the
// corrected trajectory in, exports out. The trajectory comes either as whole segments from the
// densifier (dense_segments_t on DENSE_SEGMENTS, many segments per message; a moved segment
// arrives again with a higher revision, and only the newest revision of each segment is kept, so
// a revision that arrives late cannot undo a newer one) or, with `pose_channel` set, as a plain
// pose2d_t stream (e.g. POSE_GROUND_TRUTH) cut into segments of `poses_per_segment` poses that
// never move. The annotator's colours (annotations_t on ANNOTATIONS) are kept per key pose, newest
// first, and given to every point at export (cloud.ply's red, green, blue and level) and to every
// occupied voxel (map_colour.ot, a ColorOcTree: the worst level of its points, voxel_colours.hpp).
// Out, besides the exports: a decimated preview of every profile placed for the first time
// (cloud_preview_t on CLOUD_PREVIEW, preview.hpp) for the operator's viewer, published from the
// process's own thread (publish_preview()).
//
// Late listeners (common/resend.hpp): a viewer that starts after the mapper asks for the preview
// (resend_request_t naming CLOUD_PREVIEW) and gets it again on CLOUD_PREVIEW_FULL, paced by
// publish_preview() (640 KB/s) so as not to overflow the sockets of the viewer or of the other
// processes, which receive every multicast message. Requests are paced per requester like the
// densifier's (ResendPacing): at most one answer per resend.pace_s of profile time, a requester
// not answered yet at once (one that asks while an answer goes out joins it: the answer goes on
// to the newest profile, then round from the oldest to where it stood, never restarted), and a
// request from a requester whose answer is still going out (a whole store takes seconds) is
// dropped. What is kept for that is
// capped (preview.resend_max_bytes) and thinned to a coarser grid beyond the cap
// (preview_resend.hpp), so it follows the map, not the run; live, a thinning pass runs on a thread
// of its own, so this thread's message handling never waits for it. In turn the node asks the
// annotator for every annotation when it starts (ANNOTATIONS_FULL), so a mapper started after the
// annotator colours its points at once, not grey until the end of data.
//
// Live, the Mapper runs on a worker thread and the message handlers only queue what arrives:
// after a loop closure the mapper re-places thousands of profiles (several seconds of work on a
// whole route). The bus already queues what arrives meanwhile (bus.hpp), so nothing is lost
// either way; the worker keeps the process's own thread free for its status every second and
// for export requests, and applies the moves once per batch of everything queued, so a loop
// closure sent in several messages re-places a profile once per batch, not once per message.
// The queue keeps the order of arrival, so the result is the same as handling each message at
// once; offline (--replay) the node works inline instead, which keeps memory bounded. The status
// counters map_lag_s / map_lag_max_s say how long the map trails what has arrived [s]: the time
// from the arrival of the oldest item of a batch until the batch, moves included, is in the map.
//
// With a state directory every profile and segment taken is also appended to it as it comes
// (mapper_state.hpp), and a node made on a directory that holds some starts from them: the map of
// before, rebuilt, then what comes next.
#pragma once

#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <variant>
#include <vector>

#include "bus.hpp"
#include "mapper.hpp"
#include "mapper_state.hpp"
#include "preview_resend.hpp"
#include "resend.hpp"
#include "traverse/annotations_t.hpp"
#include "traverse/cloud_preview_t.hpp"
#include "traverse/dense_segments_t.hpp"
#include "traverse/planar_scan_t.hpp"
#include "traverse/pose2d_t.hpp"
#include "voxel_colours.hpp"

namespace traverse::mapper {

class MapperNode {
 public:
  using CounterSink = std::function<void(const std::string& name, double value)>;
  // `worker_thread`: run the Mapper on its own thread (live); false: inline in the handlers.
  // `state_dir`: keep the inputs there and start from those it holds; throws std::runtime_error
  // naming the file when they are damaged.
  MapperNode(Bus& bus, const MapperConfig& config, const Eigen::Isometry3d& T_base_laser,
             CounterSink counters = {}, bool worker_thread = true,
             const std::string& state_dir = "");
  ~MapperNode();
  MapperNode(const MapperNode&) = delete;
  MapperNode& operator=(const MapperNode&) = delete;

  // Waits until everything received so far is in the map (moves applied) and a thinning pass of
  // the preview kept for late viewers is done.
  void flush();
  // Writes cloud.ply, map.bt, map.ot and map_colour.ot into the output folder (after a flush);
  // false (and why) on failure.
  bool export_all(std::string* error);
  // At shutdown: closes the last segment of a pose2d_t stream, applies everything, stops the
  // worker.
  void finish();
  void report_counters();
  // Publishes the preview points placed since the last call (cloud_preview_t on preview.channel);
  // on the thread that handles messages.
  void publish_preview();
  // The map; read it only after flush() or finish() and before the next message is handled.
  const Mapper& mapper() const { return mapper_; }

  // What the node started from when its state directory held some.
  struct Resumed {
    std::size_t profiles = 0, segments = 0;
    double seconds = 0.0;  // [s] wall time to read and place them
  };
  const std::optional<Resumed>& resumed() const { return resumed_; }

 private:
  using Work = std::variant<Profile, TrajectorySegment>;
  // Counters the worker publishes for the main thread.
  struct Snapshot {
    double profiles = 0, pending = 0, rejected = 0, dropped = 0, replaced = 0, points = 0,
           filtered = 0, voxels = 0, profile_bytes = 0, segments_applied = 0, segments_rejected = 0;
  };

  void on_profile(const planar_scan_t& msg);
  void on_segments(const dense_segments_t& msg);
  void on_pose(const pose2d_t& msg);
  void on_annotations(const annotations_t& msg);
  void cut_segment();
  // Keeps revision as the segment's newest; false (nothing changed) when one as new is known.
  bool take_revision(int64_t key_id_first, int32_t revision);

  void resume(SavedInputs& saved);
  void submit(Work work);
  void message_done();     // after each message's submits
  void apply(Work& work);  // worker side
  void settle();           // worker side: applies moves, drops stale profiles, takes a snapshot
  void run_worker();
  void stop_worker();  // lets the worker finish what is queued, then joins it

  Bus& bus_;
  MapperConfig config_;
  Mapper mapper_;                          // touched only by the worker (or inline)
  std::unique_ptr<CloudPreview> preview_;  // filled by the worker, published by publish_preview
  double preview_messages_ = 0, preview_sent_bytes_ = 0;
  int64_t preview_utime_ = 0;  // [us] utime of CLOUD_PREVIEW: never goes backwards
  // What a late viewer is sent (this thread only), and how many bytes of the answer went out in
  // the current pacing window.
  std::unique_ptr<PreviewResend> resend_store_;
  std::unique_ptr<ResendAnswerer> resend_;
  // The requesters of the answer under way, with where it stood when each asked.
  std::map<std::string, PreviewResend::Mark> answering_;
  int64_t newest_profile_utime_ = 0;  // [us] the data time answers are paced by
  std::chrono::steady_clock::time_point resend_window_;
  std::size_t resend_window_bytes_ = 0;
  double resend_messages_ = 0, resend_requests_joined_ = 0;
  CounterSink counters_;
  // Handler side (LCM thread).
  std::map<int64_t, int32_t> revisions_;  // newest revision queued, by key_id_first
  double segments_stale_ = 0;
  TrajectorySegment open_;           // pose2d_t stream: poses since the last cut
  PointColours colours_;             // the annotations, by key pose (this thread only)
  VoxelColourCounts voxel_colours_;  // of the last export (this thread only)
  double level_changes_ = 0, resend_requests_sent_ = 0;
  double poses_late_ = 0;  // poses flagged FLAG_LATE on pose_channel, left out
  int64_t next_key_id_ = 0;
  std::unique_ptr<MapperStateStore> state_;  // written on this thread
  std::optional<Resumed> resumed_;
  // Worker side.
  int64_t latest_utime_ = 0;  // [us] newest profile time applied
  double rejected_ = 0, dropped_ = 0, segments_applied_ = 0, segments_rejected_ = 0;
  // Between both.
  std::mutex mutex_;
  std::condition_variable work_cv_, idle_cv_;
  std::deque<Work> queue_;
  std::chrono::steady_clock::time_point oldest_queued_at_;  // arrival of queue_'s first item
  double lag_s_ = 0.0, lag_max_s_ = 0.0;  // [s] arrival of a batch's oldest item to its settling
  int64_t submitted_ = 0, done_ = 0;
  std::size_t max_queued_ = 0;
  bool stop_ = false;
  Snapshot snapshot_;
  std::thread worker_;
};

}  // namespace traverse::mapper
