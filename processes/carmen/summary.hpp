// traverse-carmen's report of a run: what the log held, what was published, and every
// correction made (times, no-return code, thinned scans, odometry), as text for people and one
// JSON line (printed last) for scripts.
#pragma once

#include <cstdint>
#include <string>

#include "carmen_config.hpp"
#include "carmen_node.hpp"
#include "log_reader.hpp"

namespace traverse::carmen {

struct RunFacts {
  int64_t scans_published = 0;
  int64_t poses_published = 0;
  int64_t odometry_published = 0;
  int64_t scans_thinned = 0;
  int64_t odometry_behind_scans = 0;
  OdometrySource odometry_source = OdometrySource::kNone;
  int64_t first_utime = 0;  // [us] first and last scan's time as published
  int64_t last_utime = 0;
  double wall_s = 0.0;
  bool interrupted = false;
  std::string out_path;
};

// One line each for what a user must know before trusting the output: a clock that carries no
// time, a no-return code below the range limit, re-anchored or dropped odometry. Empty when none.
std::string survey_warnings(const Summary& s, const CarmenConfig& cfg, OdometrySource source);

std::string summary_text(const Summary& s, const RunFacts& run);
std::string summary_json(const Summary& s, const RunFacts& run, const CarmenConfig& cfg);

}  // namespace traverse::carmen
