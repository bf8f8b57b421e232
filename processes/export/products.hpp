// What traverse-export makes of a run: the final dense trajectory with a covariance per pose, the
// accuracy level of every key pose (seed 004), and the frame the products are written in.
//
// Frames: the graph estimates in the "map" frame (the base at the first scan, or the frontend's
// initial_pose). Where the simulator's ground truth is in the run ("world" frame), the products can
// be written in "world" instead: the map frame is tied to the world at the first dense pose (the
// ground truth's pose at that time), as a surveyed start point would tie it. Nothing else is
// fitted.
//
// Covariance of a dense pose: the marginal covariances of the two key poses that bound its segment,
// interpolated linearly in time (the dense pose's own uncertainty relative to its key poses is not
// added). Accuracy level of a key pose: 2 sqrt(lambda_max) of its position covariance (the 95 %
// bound seed 004 compares) against the USIBD Level of Accuracy bands: LOA 50 up to 1 mm, LOA 40 up
// to 5 mm, LOA 30 up to 15 mm, LOA 20 up to 50 mm, LOA 10 beyond.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "se2.hpp"

namespace traverse::exporter {

struct KeyPose {
  int64_t utime = 0;                                     // [us]
  Pose2 pose;                                            // T_map_base
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  // (x [m], y [m], theta [rad])
};

struct DensePose {
  int64_t utime = 0;  // [us]
  Pose2 pose;         // T_frame_base
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  int64_t key_id_first = 0, key_id_last = 0;  // the segment's bounding key poses
};

struct Segment {
  int64_t key_id_first = 0, key_id_last = 0;
  int32_t revision = 0;
  std::vector<int64_t> utime;
  std::vector<Pose2> poses;
};

// The run's final estimate as read from a recorded log.
struct RunEstimate {
  std::map<int64_t, KeyPose> key_poses;  // newest per id (KEY_POSES)
  std::map<int64_t, Segment> segments;   // newest revision per key_id_first (DENSE_SEGMENTS)
  std::vector<std::pair<int64_t, Pose2>> ground_truth;  // T_world_base (the reference channel)
  int64_t events = 0, damaged_records = 0, decode_failures = 0;
};

// Reads KEY_POSES, DENSE_SEGMENTS and the reference (POSE_GROUND_TRUTH, or a CARMEN log's
// POSE_REFERENCE) from an LCM log (damage is skipped and counted). Throws std::runtime_error if
// the file cannot be opened.
RunEstimate read_run(const std::string& log_path,
                     const std::string& reference_channel = "POSE_GROUND_TRUTH");

// The dense trajectory in key-id order (shared segment ends once), covariances interpolated.
std::vector<DensePose> dense_trajectory(const RunEstimate& run);

// T_world_map from the ground truth at the first dense pose's time; nullopt without ground truth
// covering that time.
std::optional<Pose2> world_from_map(const RunEstimate& run, const std::vector<DensePose>& dense);

// Applies T_out_map to a pose and its covariance (rotated into the new frame).
DensePose transformed(const DensePose& p, const Pose2& T_out_map);

// [m] 2 sqrt(largest eigenvalue) of the position block: the 95 % bound of seed 004 (the
// annotator's bound_95 with its paper method); infinite for a non-finite covariance.
double bound95_m(const Eigen::Matrix3d& covariance);

// USIBD Level of Accuracy (10, 20, 30, 40, 50) of a 95 % bound: the level the annotator's default
// legend puts it in.
int loa_level(double bound95_m);

// Colour of a level for a user's top and bottom levels (seed 004): the top level and better are
// green, levels below the bottom one red, levels in between hues from yellow to orange.
std::array<uint8_t, 3> level_colour(int level, int top_level, int bottom_level);

// TUM trajectory format (timestamp tx ty tz qx qy qz qw, seconds and metres), which evo and
// other tools read; z = 0 and the rotation about z. A comment line names the frame.
bool write_tum(const std::string& path, const std::vector<DensePose>& poses,
               const std::string& frame);
// CSV with a header row: time, pose, the 3x3 covariance row-major, 95 % bound, level, key ids.
bool write_trajectory_csv(const std::string& path, const std::vector<DensePose>& poses,
                          const std::string& frame);

}  // namespace traverse::exporter
