// What traverse-viewer is told: where it serves the page, what it listens to, how it decimates and
// paces what it sends, and how big a slow browser's backlog may grow. One struct with the defaults
// in it; validate() checks every value in one place.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "channels.hpp"

namespace traverse::viewer {

struct ViewerConfig {
  // HTTP and WebSocket. 127.0.0.1: this machine only; 0.0.0.0 opens the page to the network (a
  // tablet on the cart's Wi-Fi). Port 0 takes any free port (said in the log and the status).
  std::string address = "127.0.0.1";
  int port = 8765;
  std::string web_root;  // the page and three.js; "": the build's web folder

  std::string preview_channel = channels::kCloudPreview;     // cloud_preview_t from the mapper
  std::string segments_channel = channels::kDenseSegments;   // dense_segments_t, corrected
  std::string annotations_channel = channels::kAnnotations;  // annotations_t, the colours
  std::string pose_channel = channels::kPoseFrontend;        // pose2d_t, the newest pose
  std::string status_prefix = "STATUS_";                     // process_status_t of every process
  // At start, ask the mapper, densifier and annotator for what they published before (answered on
  // <channel>_FULL): a viewer started late shows the whole run. false: only what comes from now.
  bool ask_for_state = true;
  // [m] edge of the voxels the page draws (its "voxels" toggle): the OctoMap's nodes eight leaves
  // (of the mapper's 2 cm) wide, each in the colour of the worst level among its points.
  double voxel_m = 0.16;

  double update_period_s = 0.2;     // [s] how often changes go to the browsers
  // [s] the page draws what the feed changed at most this often (what the operator does to the
  // view is drawn at once; 0: every update). Without a graphics processor a browser draws in
  // software, about 0.1 s of CPU a drawing on this 2-core machine: headless chromium on the same
  // machine as the graph took 28.6 s of CPU a minute with 0, 14.5-15.1 s with 0.5
  // (scripts/viewer-cost.sh --runs browser, office-s2, first 60 s, two runs each).
  double redraw_period_s = 0.5;
  double trajectory_step_m = 0.05;  // [m] drawn trajectory: poses at least this far apart
  double pose_history_s = 120.0;    // [s] frontend poses kept to tie the newest to the trajectory
  double loop_min_age_s = 30.0;     // [s] a loop-closure target is at least this much older
  int64_t client_queue_bytes = 16 << 20;  // [bytes] per browser; beyond it: dropped, resent whole
  int max_points = 4'000'000;             // preview points kept; more are dropped and counted

  template <class V>
  void visit(V& v) {
    v("address", address);
    v("port", port);
    v("web_root", web_root);
    v("preview_channel", preview_channel);
    v("segments_channel", segments_channel);
    v("annotations_channel", annotations_channel);
    v("pose_channel", pose_channel);
    v("status_prefix", status_prefix);
    v("ask_for_state", ask_for_state);
    v("voxel_m", voxel_m);
    v("update_period_s", update_period_s);
    v("redraw_period_s", redraw_period_s);
    v("trajectory_step_m", trajectory_step_m);
    v("pose_history_s", pose_history_s);
    v("loop_min_age_s", loop_min_age_s);
    v("client_queue_bytes", client_queue_bytes);
    v("max_points", max_points);
  }
};

// The first value out of range, named by its key; nullopt when the config is usable.
std::optional<std::string> validate(const ViewerConfig& config);

}  // namespace traverse::viewer
