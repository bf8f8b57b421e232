// Where the operator should walk next, beyond seed 004's colours (which only show where the cloud
// is poor): for every level the operator may pick as the worst they accept (the "bottom" level),
// the nearest key pose whose level is worse, with its region (the run of consecutive key poses
// worse than that level around it); and the nearest well-localised key pose (at or better than
// the legend's best level, green) old enough to close a loop with (at least loop_min_age_s before
// the current pose), with its distance. Distances are straight lines in the map frame [m], not
// walking distances: the viewer knows no walls.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <vector>

#include "scene.hpp"

namespace traverse::viewer {

struct GuidanceTarget {
  int64_t id = 0;         // key pose
  double x = 0, y = 0;    // [m] map frame
  double distance_m = 0;  // [m] from the current pose
};

struct PoorRegion {
  GuidanceTarget nearest;             // the nearest key pose worse than the bottom level
  int64_t first_id = 0, last_id = 0;  // the run of consecutive key poses worse than it
  int keys = 0;                       // key poses in the run
};

struct Guidance {
  int64_t utime = 0;  // [us] of the current pose
  // Index b: the nearest region worse than level b, for the bottom level b the page shows.
  std::vector<std::optional<PoorRegion>> below;
  std::optional<GuidanceTarget> loop_target;
};

Guidance guide(const std::map<int64_t, KeyAnnotation>& annotations, const Legend& legend,
               const StampedPose& now, double loop_min_age_s);

}  // namespace traverse::viewer
