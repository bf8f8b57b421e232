// The 3D mapper (seed 000, section 2, last step): every point of the tilted profile scanner is
// placed with the corrected trajectory interpolated at that point's own time and the scanner's
// extrinsic T_base_laser, and goes into an OctoMap (Hornung et al., "OctoMap: an efficient
// probabilistic 3D mapping framework based on octrees", 2013) and a full-density cloud.
//
// Loop closures move parts of the trajectory after the points were placed, and an OctoMap cannot
// take back an insertion. So the mapper keeps every profile as it was measured (ranges quantised
// to 16 bits and 8-bit intensities, 3 bytes per beam: ~0.73 MB/s at 244,000 points/s, ~1.3 GB for
// a 30-minute session) and, per occupied voxel, how many profiles hit it (grows with the mapped
// surface, not with time, like the OctoMap). When a segment moves, the version its profiles were
// placed with is kept until the next apply_moves(), which places each such profile with the old
// and with the new poses and changes the counts of only the voxels the profile left or entered
// (a loop closure of a few millimetres leaves most of a profile's 2 cm voxels where they were).
// Exactly the voxels whose count changed are set again in the OctoMap. A voxel no profile hits any
// more becomes free (OctoMap 1.9's deleteNode aborts when a deletion empties an inner node, so
// nodes are never deleted).
//
// The OctoMap holds the occupied voxels of the points (each profile counts one hit per voxel);
// free space is not carved: casting each 6 m ray through 2 cm voxels would cost ~300 updates per
// point, which cannot keep up with 244,000 points/s on one core.
#pragma once

#include <octomap/OcTree.h>

#include <Eigen/Geometry>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "planar_scan.hpp"
#include "point_colours.hpp"
#include "preview.hpp"
#include "resend_config.hpp"
#include "trajectory_store.hpp"

namespace traverse::mapper {

// The platform's own footprint in the base frame: points inside are the cart, not the scene.
struct Footprint {
  double x_min = -0.45, x_max = 0.55;  // [m] base frame
  double y_min = -0.35, y_max = 0.35;  // [m]
  double z_min = 0.02, z_max = 1.3;    // [m] (above the floor, so the floor stays)
  template <class V>
  void visit(V& v) {
    v("x_min", x_min);
    v("x_max", x_max);
    v("y_min", y_min);
    v("y_max", y_max);
    v("z_min", z_min);
    v("z_max", z_max);
  }
};

struct MapperConfig {
  double resolution_m = 0.02;  // [m] OctoMap leaf size
  double range_min_m = 0.6;    // [m] closer returns are dropped
  double range_max_m = 6.0;    // [m] farther returns are dropped (seed 000: 6 m)
  Footprint footprint;
  std::string rig_file = "configs/rig.yaml";  // laser_profile extrinsic T_base_laser
  std::string output_dir = "out/mapper";      // exports: cloud.ply, map.bt, map.ot, map_colour.ot
  std::string pose_channel;  // "": DENSE_SEGMENTS from the densifier; else pose2d_t stream
  std::string annotations_channel = "ANNOTATIONS";  // annotations_t colours; "": none
  int poses_per_segment = 40;                       // segment length when reading a pose2d_t stream
  double max_pending_s = 30.0;  // [s] profiles waiting longer for poses are dropped
  int move_threads = 2;         // threads that place moved profiles again (counts: one thread)
  PreviewConfig preview;        // decimated points for screens on CLOUD_PREVIEW (preview.hpp)
  // resend.pace_s: a late viewer is sent the preview again at most once per this much profile
  // time (mapper_node.hpp, common/resend.hpp)
  ResendConfig resend;
  template <class V>
  void visit(V& v) {
    v("resolution_m", resolution_m);
    v("range_min_m", range_min_m);
    v("range_max_m", range_max_m);
    v("footprint", footprint);
    v("rig_file", rig_file);
    v("output_dir", output_dir);
    v("pose_channel", pose_channel);
    v("annotations_channel", annotations_channel);
    v("poses_per_segment", poses_per_segment);
    v("max_pending_s", max_pending_s);
    v("move_threads", move_threads);
    v("preview", preview);
    v("resend", resend);
  }
};

// A profile of the tilted scanner as measured: the common scan plus its intensities.
// The first value out of range, named by its key; nullopt when the config is usable.
std::optional<std::string> validate(const Footprint& footprint);
std::optional<std::string> validate(const MapperConfig& config);

struct Profile : PlanarScan {
  std::vector<uint8_t> intensities;  // [0..255], empty or one per range
};

struct CloudPoint {
  Eigen::Vector3f p_world;  // [m]
  uint8_t intensity = 0;
  int64_t utime = 0;   // [us]
  int64_t key_id = 0;  // key pose whose segment placed the profile
  PointColour colour;  // accuracy level and colour (set at export, point_colours.hpp)
};

class Mapper {
 public:
  Mapper(const MapperConfig& config, const Eigen::Isometry3d& T_base_laser);
  // The step a stored range is quantised to [m]: 16 bits over 0..range_max_m (what a saved
  // state stores ranges at too, so a resumed mapper places the same points).
  static double range_quantum_m(double range_max_m) { return range_max_m / 65535.0; }

  // Takes a profile; placed now if the trajectory covers it, else when it does. False if
  // malformed (sizes, times).
  bool add_profile(const Profile& profile);
  // Stores a trajectory segment. A new segment places waiting profiles; a moved one marks the
  // profiles it spans for re-placement at the next apply_moves(). Profiles placed while a segment
  // they span has moved and the move is not yet applied go into the map at apply_moves().
  bool set_segment(const TrajectorySegment& segment);
  // Re-places moved profiles and updates the voxels whose hit count changed. Returns their number.
  std::size_t apply_moves();
  // Drops waiting profiles older than max_pending_s before `now_utime`; returns how many.
  std::size_t drop_stale(int64_t now_utime);

  // Number of points for_each_point() gives.
  int64_t placed_points() const;
  // Calls f(point) for every stored point at its current place.
  void for_each_point(const std::function<void(const CloudPoint&)>& f) const;
  const octomap::OcTree& octree() const { return *tree_; }
  // Updates the inner nodes of the OctoMap (needed before export or queries of inner nodes).
  void finish_octree_for_export();

  std::size_t profiles() const { return stored_.size(); }
  std::size_t pending() const { return pending_.size(); }
  int64_t points() const { return points_; }
  int64_t points_filtered() const { return points_filtered_; }
  int64_t profiles_replaced() const { return profiles_replaced_; }
  std::size_t occupied_voxels() const { return hits_.size(); }
  // [bytes] memory held by the stored profiles (not the OctoMap).
  std::size_t profile_bytes() const;

  // Called (on the thread that adds profiles and segments) once for every profile when it first
  // goes into the map, with its points as placed and the pose T_world_base at its first beam time;
  // later moves do not call it again. For the screen preview (preview.hpp).
  using FirstPlacement = std::function<void(int64_t utime_first, const Pose2& T_world_base,
                                            const std::vector<Eigen::Vector3f>& p_world)>;
  void on_first_placement(FirstPlacement f) { first_placement_ = std::move(f); }

 private:
  struct Stored {
    int64_t utime_first = 0, utime_last = 0;
    uint32_t geometry = 0;          // index into beam_tables_
    std::vector<uint16_t> range_q;  // quantised range, 0 = no point
    std::vector<uint8_t> intensity;
    int64_t key_id = 0;
    int32_t n_points = 0;
    bool dirty = false;   // its poses changed: to be placed again at apply_moves()
    bool in_map = false;  // its hits are in hits_ (placed with the poses it had before a move)
  };
  // Unit beam directions in the base frame of one scan geometry (all profiles of a scanner share
  // one), so placing a point needs no trigonometry per beam.
  struct BeamTable {
    double angle_first = 0, angle_step = 0;  // [rad]
    std::vector<Eigen::Vector3d> dir_base;
  };
  // Which segment versions to place a profile with: the current ones, or those it was placed with.
  enum class Poses { kCurrent, kBeforeMoves };
  Stored compress(const Profile& p);
  uint32_t beam_table(const Profile& p);
  // World points of a stored profile (and their beam indices); false if poses are missing.
  bool place(const Stored& s, std::vector<Eigen::Vector3f>& pts, std::vector<int>& beams,
             Poses poses = Poses::kCurrent) const;
  // Distinct voxels hit by a stored profile, as packed keys, sorted.
  void voxel_keys(const Stored& s, Poses poses, std::vector<uint64_t>& keys) const;
  // Voxels a dirty profile leaves and enters when placed with the current poses.
  struct Change {
    std::vector<uint64_t> left, entered;
  };
  void change(const Stored& s, Change& c) const;
  // Segment covering `utime` in the given version; nullptr if none.
  const TrajectorySegment* segment_at(int64_t utime, Poses poses) const;
  // Stored profiles that may overlap [t0, t1]: [first, last).
  std::pair<std::size_t, std::size_t> stored_range(int64_t t0, int64_t t1) const;
  // Sets a voxel's log-odds to what `hits` profile hits give (free when none).
  void set_voxel(const octomap::OcTreeKey& key, uint32_t hits);
  void add_hit(uint64_t key);
  void remove_hit(uint64_t key);
  void try_pending();
  void first_placed(const Stored& s) const;

  MapperConfig config_;
  Eigen::Isometry3d T_base_laser_;
  double range_quantum_m_;
  double key_scale_;  // [1/m] OctoMap's resolution factor
  TrajectoryStore trajectory_;
  std::unique_ptr<octomap::OcTree> tree_;
  std::vector<BeamTable> beam_tables_;
  // Segments as they were before the moves not yet applied, by first time (the version their
  // in-map profiles were placed with).
  std::map<int64_t, TrajectorySegment> before_moves_;
  std::deque<Stored> pending_;
  std::vector<Stored> stored_;  // by utime_first
  int64_t longest_profile_us_ = 0;
  std::unordered_map<uint64_t, uint32_t> hits_;  // profiles hitting each voxel, by packed key
  std::vector<uint64_t> touched_;  // voxels whose hit count changed since the last apply_moves
  int64_t points_ = 0, points_filtered_ = 0, profiles_replaced_ = 0;
  FirstPlacement first_placement_;
};

}  // namespace traverse::mapper
