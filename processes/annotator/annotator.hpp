// The uncertainty annotator (seed 004): turns the backend's key poses and covariances into 95 %
// bounds on each key pose's position error, the accuracy level of a surveying standard they fall
// in, and a colour for the points placed from that key pose.
//   1. absolute bound: the key pose's marginal covariance (from KEY_POSES: relative to the first
//      key pose, which fixes the frame), its translational block times the calibrated
//      covariance_scale, turned into a 95 % radius (bounds.hpp; exact by default);
//   2. local bound: the largest 95 % radius of the key pose's position relative to any key pose
//      within local_radius_m, from the joint covariance of the two (joint_covariance.hpp), with
//      the same scale. Seed 004's absolute bound grows with the distance travelled from the first
//      key pose even where the map is locally perfect; the local one is what a wall is checked
//      against;
//   3. level and colour from the bound named by colour_by (levels.hpp).
// The scale calibrates the backend's edge covariances (scan matching is over-confident): it is
// fitted on simulated runs against ground truth (scripts/eval-coverage.sh --fit) and kept in
// configs/annotator.yaml.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "bounds.hpp"
#include "joint_covariance.hpp"
#include "levels.hpp"
#include "pose_graph.hpp"
#include "se2.hpp"

namespace traverse::annotator {

struct AnnotatorConfig {
  std::string standard = "USIBD LOA";  // shown in the legend
  // Levels best first and the upper ends of all but the last [m] (USIBD LOA 2016, at 95 %).
  std::vector<std::string> levels{"LOA50", "LOA40", "LOA30", "LOA20", "LOA10"};
  std::vector<double> limits_m{0.001, 0.005, 0.015, 0.050};
  std::string best_level = "LOA30";    // green, with every better level
  std::string worst_level = "LOA10";   // red, with every worse level
  std::string bound = "exact";         // exact, chi2_max_eigen or paper (bounds.hpp)
  std::string colour_by = "absolute";  // absolute or local: the bound that gives level and colour
  double covariance_scale = 1.0;       // [unitless] factor on the backend's covariances
  double local_radius_m = 5.0;         // [m] neighbourhood of the local bound; 0: none
  // A key pose is republished when its level changes or a bound changes by this fraction.
  double republish_fraction = 0.05;

  template <class V>
  void visit(V& v) {
    v("standard", standard);
    v("levels", levels);
    v("limits_m", limits_m);
    v("best_level", best_level);
    v("worst_level", worst_level);
    v("bound", bound);
    v("colour_by", colour_by);
    v("covariance_scale", covariance_scale);
    v("local_radius_m", local_radius_m);
    v("republish_fraction", republish_fraction);
  }
};

// The first value out of range, named by its key; nullopt when the config is usable.
std::optional<std::string> validate(const AnnotatorConfig& config);

struct Annotation {
  int64_t id = 0;
  int64_t utime = 0;            // [us]
  Pose2 T_world_base;           // the key pose
  double bound_m = 0.0;         // [m] absolute 95 % radius
  double local_bound_m = -1.0;  // [m] local 95 % radius; -1 when not computed
  int level = 0;                // legend index of the bound named by colour_by
  Rgb rgb{};
};

struct AnnotatorCounters {
  long key_poses = 0;            // key poses received (with repeats)
  long edges = 0;                // edges held
  long edges_rejected = 0;       // not positive definite, or naming no key pose yet
  long edge_gaps = 0;            // edges missed (an index beyond those held)
  long local_failed = 0;         // updates whose graph could not be factored
  long local_columns = 0;        // joint-covariance columns solved
  long annotations_changed = 0;  // annotations returned by update()
  long level_changes = 0;        // ... of which with a new level
};

class Annotator {
 public:
  // The config must pass validate().
  explicit Annotator(const AnnotatorConfig& config);

  // A key pose as published on KEY_POSES (covariance of x [m], y [m], theta [rad]).
  void set_key_pose(int64_t id, int64_t utime, const Pose2& T_world_base,
                    const Eigen::Matrix3d& covariance);
  // A pose-graph edge as published on POSE_GRAPH_EDGES; edges arrive in index order. False (and
  // counted) when it is not positive definite, not symmetric beyond rounding
  // (backend::usable_information), or its index is not the next one. A refused edge still takes
  // its index: the edges after it are taken, the graph goes without it.
  bool add_edge(int index, int64_t from_id, int64_t to_id, const Pose2& T_from_to,
                const Eigen::Matrix3d& information);
  // Recomputes the key poses set since the last call and returns the annotations that are new or
  // changed (level, or a bound by republish_fraction).
  std::vector<Annotation> update();
  std::size_t key_poses_held() const { return keys_.size(); }
  // Every annotation, by id.
  const std::map<int64_t, Annotation>& annotations() const { return published_; }
  const Legend& legend() const { return legend_; }
  const AnnotatorConfig& config() const { return config_; }
  const AnnotatorCounters& counters() const { return counters_; }
  // Key poses whose level changed in the last update().
  int last_level_changes() const { return last_level_changes_; }

 private:
  struct Key {
    int64_t utime = 0;
    Pose2 T_world_base;
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  };
  struct LocalBounds {
    std::map<int64_t, double> recomputed;  // [m] local bound of each of `ids` computable
    std::map<int64_t, double> neighbours;  // [m] other key poses: worst term of one of `ids`
  };
  // Local bounds of `ids` (sorted; those not computable are left out), and for every other key
  // pose within local_radius_m of one of them the largest 95 % radius of one of them seen from it
  // (the same columns of the joint covariance give both).
  LocalBounds local_bounds(const std::vector<int64_t>& ids);
  bool differs(const Annotation& a, const Annotation& b) const;

  AnnotatorConfig config_;
  BoundMethod method_;
  Legend legend_;
  std::map<int64_t, Key> keys_;  // by id
  std::vector<backend::Edge> edges_;
  int next_edge_index_ = 0;  // index of the next edge on POSE_GRAPH_EDGES (taken or refused)
  std::vector<int64_t> dirty_;  // ids set since the last update
  std::map<int64_t, Annotation> published_;
  JointCovariance joint_;
  AnnotatorCounters counters_;
  int last_level_changes_ = 0;
};

}  // namespace traverse::annotator
