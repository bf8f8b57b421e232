// The frontend's map frame held against the first key scan's: the heading the map gained while
// the frontend built it, measured by matching the first key scan directly, and taken out of the
// published trajectory.
//
// The first key pose is placed by fiat (the map frame is the base at the first pose), and every
// later pose is matched against the frontend's map. A map that stays in the first scan's frame
// keeps each relative pose right; but a scan-to-map frontend on an occupancy grid can turn its map
// in the first seconds, when walls lie within a few milliradians of the grid's axes: the grid
// holds them on its axes, and the map, with every pose matched in it, turns by h against the
// first scan (corridor-return s2, realistic profile: the frontend's heading errs by -4.4 mrad
// from the tenth second on, and its positions do not err at all, because the simulated walls lie
// on the world's axes). Headings then err by h and positions are in the turned map.
//
// That turn matters with the boresight (boresight.hpp): a scanner turned by delta on the cart
// makes the whole path turn by delta about its start, and the boresight fit sees the chords of the
// path run at -delta from the headings. Where the map turned by h, the chords still run at -delta
// from the headings (a turn of the frame moves both alike), but the positions are turned by
// delta - h and the headings by h: turning the positions back by delta alone (the boresight's
// correction) turns right positions wrong when h = delta. With h measured, the trajectory is first
// turned back by h about the first key pose (positions and headings; the first key pose's heading
// is its own definition and stays), then the boresight turns its positions.
//
// The measurement: key scans up to max_travel_m of travel from the first (and within
// max_distance_m of it, turned by at most max_turn_rad) are matched against the first key scan,
// around their graph poses; each gives h_k, the graph's heading from the first key pose minus the
// matched one. h is the median of those from min_travel_m on, applied when min_matches of them
// matched, it lies beyond min_heading_rad and beyond min_sigmas of their spread (median absolute
// deviation), and the turn came at once: the median of the h_k within early_travel_m is at least
// min_early_share of h, with its sign. The grid turns the map with its first scans (corridor-return
// s1: -3.2 mrad from the first 0.3 m on, -3.6 mrad over 2-8 m); a frontend whose map drifts away
// from the first scan gradually (office-s1 s1: -0.2 mrad over the first metre, -2.5 mrad at 2-8 m,
// +3 mrad later on) is not turned back by what it drifted near the start. The matches are made
// once, when the travel passes max_travel_m (the first scan's neighbourhood is behind the cart by
// then); h is taken again from them after every optimisation, against the graph's poses of the
// moment.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "correlative_matcher.hpp"
#include "scan_refiner.hpp"
#include "scan_store.hpp"
#include "se2.hpp"

namespace traverse::backend {

struct StartFrameConfig {
  bool enabled = false;
  double early_travel_m = 1.5;     // [m] key scans up to this far along the path: the early turn
  double min_travel_m = 2.0;       // [m] key scans from this far along the path ...
  double max_travel_m = 8.0;       // [m] ... to this far: the turn h
  double min_early_share = 0.5;    // the early turn is at least this share of h
  double max_distance_m = 8.0;     // [m] and lie within this straight distance of it
  double max_turn_rad = 0.5;       // [rad] and are turned by at most this from it
  double min_response = 0.35;      // a match below this raw response is not used [0..1]
  int min_matches = 3;             // fewer matches: no turn applied
  double min_heading_rad = 0.001;  // [rad] a smaller turn is not applied
  double min_sigmas = 3.0;         // the turn must lie this many MADs of the h_k beyond zero

  template <class V>
  void visit(V& v) {
    v("enabled", enabled);
    v("early_travel_m", early_travel_m);
    v("min_travel_m", min_travel_m);
    v("min_early_share", min_early_share);
    v("max_travel_m", max_travel_m);
    v("max_distance_m", max_distance_m);
    v("max_turn_rad", max_turn_rad);
    v("min_response", min_response);
    v("min_matches", min_matches);
    v("min_heading_rad", min_heading_rad);
    v("min_sigmas", min_sigmas);
  }
};

std::optional<std::string> validate(const StartFrameConfig& config);

class StartFrame {
 public:
  explicit StartFrame(const StartFrameConfig& config) : config_(config) {}

  // After an optimisation: the key poses (T_world_base, the graph's frame) and their travel [m].
  // Matches the key scans against the first once the travel passes max_travel_m, then takes h.
  void update(const std::vector<Pose2>& key_poses, const std::vector<double>& travel_m,
              const ScanStore& scans, const CorrelativeMatcher& matcher,
              const ScanRefiner& refiner);

  // The turn taken out [rad]: nullopt when off, before the matches, or while h does not hold.
  std::optional<double> heading_rad() const { return heading_; }
  // h as measured [rad], applied or not (0 before the matches), and the matches it rests on.
  double estimate_rad() const { return estimate_; }
  // The median h_k within early_travel_m [rad] (0 before the matches).
  double early_estimate_rad() const { return early_estimate_; }
  int matches() const { return static_cast<int>(matched_.size()); }

  // Key pose `T` (not the first) as published: turned back by h about the first key pose.
  Pose2 published(const Pose2& T_world_base, const Pose2& T_world_first) const;

 private:
  struct Match {
    int key;
    double travel_m;     // [m] along the path from the first
    double heading_rad;  // the matched heading of the key scan from the first [rad]
  };
  StartFrameConfig config_;
  bool measured_ = false;
  std::vector<Match> matched_;
  double estimate_ = 0.0;
  double early_estimate_ = 0.0;
  std::optional<double> heading_;
};

}  // namespace traverse::backend
