// What the operator's page shows, kept by traverse-viewer without LCM or network (tests drive it
// directly): the mapper's preview points per profile, each placed with one pose of the corrected
// trajectory (preview.hpp in processes/mapper: the points are in the base frame at the profile's
// time) and moved when a loop closure moves that pose; the corrected trajectory, decimated for
// drawing; the annotator's accuracy levels per key pose and its legend; the current pose (the
// newest frontend pose, carried onto the corrected trajectory). Every change is also noted, so the
// viewer sends browsers only what changed since the last update (take_changes()).
#pragma once

#include <array>
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "se2.hpp"
#include "trajectory_store.hpp"

namespace traverse::viewer {

struct LegendLevel {
  std::string name;
  double min_m = 0, max_m = 0;  // [m] the level's range of 95 % error
  std::array<uint8_t, 3> rgb{};
  bool accepted = false;
  bool operator==(const LegendLevel&) const = default;
};

struct Legend {
  std::string standard, coloured_by, bound_method;
  double confidence = 0;  // [0..1]
  int best_level = 0, worst_level = 0;
  std::vector<LegendLevel> levels;  // best first
  bool operator==(const Legend&) const = default;
};

struct KeyAnnotation {
  int64_t id = 0;
  int64_t utime = 0;                       // [us]
  double x = 0, y = 0;                     // [m] map frame
  double bound_m = 0, local_bound_m = -1;  // [m]
  int level = 0;                           // legend index
};

struct Profile {
  int64_t utime = 0;                              // [us] the base pose its points are in
  std::vector<std::array<int16_t, 3>> p_base_mm;  // [mm]
  Pose2 T_map_base;                               // where it is drawn now
  bool placed = false;                            // the trajectory covers utime
};

// A drawn stretch of the corrected trajectory: one densifier segment, decimated.
struct Polyline {
  int64_t key_id_first = 0;
  int32_t revision = 0;
  std::vector<std::array<float, 2>> xy;  // [m] map frame
};

struct StampedPose {
  int64_t utime = 0;  // [us]
  Pose2 T_map_base;
};

// What changed since the last take_changes().
struct Changes {
  std::vector<uint32_t> new_profiles;    // placed for the first time (index into profiles())
  std::vector<uint32_t> moved_profiles;  // placed again with a moved pose
  std::vector<int64_t> segments;         // polylines new or moved (key_id_first)
  std::vector<int64_t> annotations;      // annotations new or changed (id)
  bool legend = false;
  bool pose = false;
  bool empty() const {
    return new_profiles.empty() && moved_profiles.empty() && segments.empty() &&
           annotations.empty() && !legend && !pose;
  }
};

// Inputs that could not be used, counted (the status reports them).
struct SceneCounters {
  int64_t profiles_rejected = 0;     // empty, or over max_points
  int64_t profiles_repeated = 0;     // points already held, sent again (dropped)
  int64_t points_dropped = 0;        // beyond max_points
  int64_t segments_rejected = 0;     // fewer than two poses, or times not increasing
  int64_t segments_stale = 0;        // an older revision than the one held
  int64_t annotations_rejected = 0;  // a level outside the legend, or no legend
};

struct SceneConfig {
  double trajectory_step_m = 0.05;  // [m]
  double pose_history_s = 120.0;    // [s]
  int64_t max_points = 4'000'000;
};

class Scene {
 public:
  explicit Scene(const SceneConfig& config);

  // Preview points of the profile at `utime` (appended when that profile is already held, unless
  // they are a copy of points held).
  void add_profile(int64_t utime, std::vector<std::array<int16_t, 3>> p_base_mm);
  // A densifier segment (revision: newer ones replace older ones); places the profiles it covers.
  void set_segment(const mapper::TrajectorySegment& segment, int32_t revision);
  // The annotator's legend and key poses (the newest annotation per id is kept).
  void set_annotations(const Legend& legend, const std::vector<KeyAnnotation>& keys);
  // A frontend pose (map frame, not corrected by loop closures).
  void set_frontend_pose(int64_t utime, const Pose2& T_map_base);

  Changes take_changes();

  const std::vector<Profile>& profiles() const { return profiles_; }
  const std::map<int64_t, Polyline>& polylines() const { return polylines_; }
  const std::map<int64_t, KeyAnnotation>& annotations() const { return annotations_; }
  const std::optional<Legend>& legend() const { return legend_; }
  // The newest pose on the corrected trajectory: the newest frontend pose moved by the difference
  // between the corrected trajectory and the frontend at the trajectory's end.
  std::optional<StampedPose> current_pose() const;
  int64_t points() const { return points_; }
  const SceneCounters& counters() const { return counters_; }

 private:
  void place(uint32_t index);
  std::optional<Pose2> frontend_at(int64_t utime) const;

  SceneConfig config_;
  std::vector<Profile> profiles_;
  std::map<int64_t, uint32_t> by_utime_;  // profile index by time
  mapper::TrajectoryStore trajectory_;
  std::map<int64_t, int32_t> revisions_;  // by key_id_first
  std::map<int64_t, Polyline> polylines_;
  std::optional<Legend> legend_;
  std::map<int64_t, KeyAnnotation> annotations_;
  std::deque<StampedPose> frontend_;           // newest last
  std::optional<StampedPose> trajectory_end_;  // newest pose of the corrected trajectory
  int64_t points_ = 0;
  SceneCounters counters_;
  std::set<uint32_t> new_, moved_;
  std::set<int64_t> changed_segments_, changed_annotations_;
  bool legend_changed_ = false, pose_changed_ = false;
};

}  // namespace traverse::viewer
