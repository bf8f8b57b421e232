// Statistics of planar scans that matter to a scan matcher, measured the same way on real and on
// simulated scans so that the two can be compared like with like (scripts/sim-realism.sh):
// - returns per scan (beams with a range);
// - residuals against the local surface: each beam's point against the line fitted (total least
//   squares) to its two neighbours on either side, where the five beams see one smooth surface
//   (no two neighbours' ranges differ by more than `jump_m`); spread as a robust sigma
//   (1.4826 x median absolute residual) and the share of residuals beyond 3 sigma (tails);
// - depth jumps (a step between neighbouring ranges longer than `jump_m` and unlike one of the
//   steps beside it: a wall seen at a grazing angle has long steps too, but alike), mixed pixels
//   per jump (a point between the two sides of a jump, more than `mixed_margin_m` from both; a
//   wide footprint can give a jump several), and outliers: mixed pixels and spikes (points off
//   both neighbours the same way by more than `jump_m`: thin objects, spurious returns), per depth
//   jump (what the sensor makes of the jumps a scene offers) and as a share of returns (which
//   also counts how cluttered the scene is).
// Only beams with ranges in [min_range_m, max_range_m] take part.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace traverse::sim {

struct RealismConfig {
  double min_range_m = 0.3;
  double max_range_m = 15.0;
  double jump_m = 0.3;
  double mixed_margin_m = 0.1;
};

struct ScanStats {
  int64_t scans = 0;
  int64_t beams = 0;
  int64_t returns = 0;
  std::vector<double> residuals;  // [m] signed, against the local line
  int64_t jumps = 0;
  int64_t mixed = 0;
  int64_t outliers = 0;  // spikes

  // One scan: ranges [m] (values outside [min, max] are no return), first angle and step [rad].
  void add(const std::vector<float>& ranges, double angle_first, double angle_step,
           const RealismConfig& config);
};

struct RealismSummary {
  int64_t scans = 0;
  double returns_per_scan = 0.0;  // beams with a return, mean per scan
  double return_fraction = 0.0;   // of all beams
  double sigma_m = 0.0;           // [m] robust sigma of the residuals
  double p95_m = 0.0;             // [m] 95th percentile of |residual|
  double tail_fraction = 0.0;     // share of |residual| > 3 sigma
  int64_t residual_count = 0;
  double jumps_per_scan = 0.0;
  double mixed_per_jump = 0.0;     // mixed pixels (points between the two surfaces) per jump
  double outlier_fraction = 0.0;   // mixed pixels and spikes, share of returns
  double outliers_per_jump = 0.0;  // mixed pixels and spikes per depth jump
};

RealismSummary summarize(const ScanStats& stats);

}  // namespace traverse::sim
