// Crafted CARMEN logs for tests: a simulated robot in a walled floor plan, scanned by a
// 180-degree laser (FLASER, 181 beams, ranges printed to centimetres), with its wheel odometry
// (ODOM lines), written with the timestamp pathologies real logs have. The floor plan is 20 x 12
// m with two inner walls and a pillar; `open_top` leaves out the wall at y = 12 m, so that many
// beams find nothing and get the log's no-return code.
#pragma once

#include <string>
#include <vector>

#include "se2.hpp"

namespace traverse::carmen::test {

struct CraftedLog {
  std::vector<Pose2> poses;         // T_world_laser of each scan
  std::vector<std::string> stamps;  // printed ipc (and logger) timestamp of each scan
  bool open_top = false;
  double sensor_range_m = 30.0;  // beams that hit nothing nearer get no_return_text
  std::string no_return_text = "81.83";
  bool odometry = true;  // an ODOM line (the pose, no noise) before each scan
};

// Writes the log (plain text); false if the file cannot be written.
bool write_log(const std::string& path, const CraftedLog& log);

// The relations of the log (the benchmark's format: t1 t2 dx dy dz droll dpitch dyaw, the true
// pose of scan j in the frame of scan i, stamps as the log prints them) between every scan i and
// scan i + gap.
bool write_relations(const std::string& path, const CraftedLog& log, int gap);

// Poses along the floor plan's corridor loop, one every `step_m` of travel (and every 0.35 rad of
// turn at the corners), as a log subsampled by travel keeps them.
std::vector<Pose2> loop_path(double step_m);
// The same loop with one step of `long_step_m` between two kept scans along the longest straight
// (a log subsampled so sparsely that consecutive scans are 3 m apart).
std::vector<Pose2> loop_path_with_long_step(double step_m, double long_step_m);

// Timestamps of n scans: each a pathology of real logs.
std::vector<std::string> stamps_fine(int n, double period_s);  // 1000 s + k * period, to 1 us
std::vector<std::string> stamps_all_zero(int n);
// The first `negative` scans at negative times, the rest printed to 6 significant digits (1e4 s
// steps at 1.1e9 s, like csail).
std::vector<std::string> stamps_negative_then_coarse(int n, int negative);
// Whole seconds while scans come `per_second` a second.
std::vector<std::string> stamps_whole_seconds(int n, int per_second);

}  // namespace traverse::carmen::test
