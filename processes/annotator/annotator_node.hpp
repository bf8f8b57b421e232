// Adapts LCM messages to the Annotator: the backend's pose-graph edges (pose_graph_edges_t on
// POSE_GRAPH_EDGES) and key poses with marginals (key_poses_t on KEY_POSES, incremental, in parts)
// in; after the last part of each optimisation, the annotations that are new or changed out
// (annotations_t on ANNOTATIONS, with the legend, in parts of at most max_keys_per_message). At
// the end of data every annotation is sent once more (REASON_FINAL), so a late listener or the
// recorded log's last word holds them all.
//
// Joining late (common/resend.hpp): the backend's updates are incremental, so an annotator that
// starts after the backend, or misses an edge or key pose message, holds part of the graph and can
// compute no local bound. It asks for the whole graph (resend_request_t naming KEY_POSES and
// POSE_GRAPH_EDGES) when it starts and after every optimisation that leaves it holding fewer key
// poses or edges than the backend says the graph has; the backend answers on KEY_POSES_FULL and
// POSE_GRAPH_EDGES_FULL (backend_node.hpp), which this node reads like the incremental channels.
// In turn, a listener that started after the annotator (the viewer, the mapper) asks for every
// annotation (naming ANNOTATIONS) and gets them on ANNOTATIONS_FULL.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "annotator.hpp"
#include "bus.hpp"
#include "channels.hpp"
#include "resend.hpp"
#include "traverse/annotations_t.hpp"
#include "traverse/key_poses_t.hpp"
#include "traverse/pose_graph_edges_t.hpp"

namespace traverse::annotator {

struct AnnotatorNodeConfig {
  std::string key_poses_channel = channels::kKeyPoses;
  std::string edges_channel = channels::kPoseGraphEdges;
  std::string annotations_channel = channels::kAnnotations;
  bool ask_for_state = true;        // ask the backend for its whole graph when something is missing
  int max_keys_per_message = 1000;  // 52 bytes each: a part stays under 64 KB
  // resend.pace_s: a late listener (the mapper, the viewer) is answered at most once per this
  // much key pose time (common/resend.hpp)
  ResendConfig resend;
  AnnotatorConfig annotator;  // its keys sit at the top level of the file

  template <class V>
  void visit(V& v) {
    v("key_poses_channel", key_poses_channel);
    v("edges_channel", edges_channel);
    v("annotations_channel", annotations_channel);
    v("ask_for_state", ask_for_state);
    v("max_keys_per_message", max_keys_per_message);
    v("resend", resend);
    annotator.visit(v);
  }
};

// The first value out of range, named by its key; nullopt when the config is usable.
std::optional<std::string> validate(const AnnotatorNodeConfig& config);

// The messages that carry `annotations` (at most `per_message` each) with the legend; sets
// everything but seq.
std::vector<annotations_t> pack_annotations(const Annotator& annotator,
                                            const std::vector<Annotation>& annotations,
                                            int64_t utime, int32_t optimisation, int8_t reason,
                                            int32_t loop_closures, int32_t changed_level,
                                            int per_message);

class AnnotatorNode {
 public:
  using CounterSink = std::function<void(const std::string& name, double value)>;
  // The config must pass validate().
  AnnotatorNode(Bus& bus, const AnnotatorNodeConfig& config, CounterSink counters = {});
  // End of data: publishes every annotation once more.
  void finish();
  void report_counters();
  const Annotator& annotator() const { return annotator_; }

 private:
  void on_edges(const pose_graph_edges_t& msg);
  void on_key_poses(const key_poses_t& msg);
  void publish(const std::vector<Annotation>& annotations, int8_t reason, int32_t changed_level,
               const std::string& channel);
  std::vector<Annotation> all_annotations() const;
  // Asks the backend for its whole graph (at most once per optimisation heard).
  void ask_for_graph();

  Bus& bus_;
  AnnotatorNodeConfig config_;
  Annotator annotator_;
  CounterSink counters_;
  int64_t utime_ = 0;          // [us] newest key pose time heard
  int32_t optimisation_ = 0;   // newest optimisation heard
  int32_t loop_closures_ = 0;  // loop closures in the graph
  bool closure_pending_ = false;
  int32_t graph_key_poses_ = 0, graph_edges_ = 0;  // the backend's graph, as its messages say
  int32_t requested_at_ = -1;                      // optimisation of the last request
  double resend_requests_sent_ = 0;
  std::unique_ptr<ResendAnswerer> resend_;  // for ANNOTATIONS
  double messages_ = 0, updates_ = 0, update_s_total_ = 0, update_s_max_ = 0;
};

}  // namespace traverse::annotator
