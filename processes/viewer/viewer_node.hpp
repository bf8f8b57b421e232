// Adapts LCM messages to the viewer's Scene and StatusBoard and hands what changed to the
// WebServer: the mapper's preview points (cloud_preview_t on CLOUD_PREVIEW), the corrected
// trajectory (dense_segments_t on DENSE_SEGMENTS), the annotator's colours and legend
// (annotations_t on ANNOTATIONS), the newest pose (pose2d_t on POSE_FRONTEND) and every process's
// status (process_status_t on STATUS_*). Handlers only update the scene; update() (every
// update_period_s, from the process loop) encodes the changes for the browsers, and only when a
// browser is connected: with none, the viewer does no more than keep its scene.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "bus.hpp"
#include "scene.hpp"
#include "status_board.hpp"
#include "traverse/annotations_t.hpp"
#include "traverse/cloud_preview_t.hpp"
#include "traverse/dense_segments_t.hpp"
#include "traverse/pose2d_t.hpp"
#include "viewer_config.hpp"
#include "web_server.hpp"

namespace traverse::viewer {

class ViewerNode {
 public:
  using CounterSink = std::function<void(const std::string& name, double value)>;
  // The config must pass validate(); `server` may be null (no browsers: tests of the scene).
  ViewerNode(Bus& bus, const ViewerConfig& config, WebServer* server, CounterSink counters = {});
  ~ViewerNode();
  ViewerNode(const ViewerNode&) = delete;
  ViewerNode& operator=(const ViewerNode&) = delete;

  // Sends browsers what changed, at most every update_period_s; `now_utime` [us] wall clock.
  void update(int64_t now_utime);
  void report_counters();
  const Scene& scene() const { return scene_; }
  const StatusBoard& board() const { return board_; }

 private:
  void on_preview(const cloud_preview_t& msg);
  void on_segments(const dense_segments_t& msg);
  void on_annotations(const annotations_t& msg);
  void on_pose(const pose2d_t& msg);
  void on_status(const std::string& channel, const uint8_t* data, int size);

  Bus& bus_;
  ViewerConfig config_;
  WebServer* server_;
  CounterSink counters_;
  Scene scene_;
  StatusBoard board_;
  Bus::Handle status_subscription_ = nullptr;
  int64_t last_update_utime_ = 0;
  bool status_changed_ = false;
  std::string last_guidance_;  // the guidance frame sent last
  double statuses_ = 0, statuses_rejected_ = 0, statuses_stale_ = 0, updates_sent_ = 0,
         update_s_max_ = 0, resend_requests_sent_ = 0;
};

}  // namespace traverse::viewer
