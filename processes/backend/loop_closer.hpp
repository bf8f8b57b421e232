// Loop closure as seed 000 modifies Karto's: when the platform comes near an old chain of key
// scans, EVERY nearby current key scan is matched against that chain, and the loop is closed with
// the best response of them all, not with the first one over a threshold (the match generally
// improves as the scanning positions get closer).
//
// An episode starts when the newest key pose lies within `search_radius_m` of key poses that are
// at least `min_travel_m` back along the trajectory; the chain is the run of such old key poses
// around the nearest one. Each current key scan of the episode is a candidate. The episode ends
// when the platform leaves the old chain or after `max_candidates` candidates (so a long retraced
// corridor gets several closures); its best accepted candidate becomes the closure.
//
// A wrong closure is worse than a missed one, so a candidate is accepted only if
//  1. a coarse correlative search over a wide window finds a response over min_coarse_response,
//  2. the scene is not ambiguous: the best response at least ambiguity_exclusion_m away from the
//     peak is below max_ambiguity_ratio times the peak (repeated rooms, corridors),
//  3. a fine search around the coarse peak has a response over min_fine_response, and
//  4. the fine covariance is tight (standard deviations under max_sigma_xy_m, max_sigma_theta_rad),
//  5. and the correction it implies for the current pose fits the graph's marginal covariances.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "correlative_matcher.hpp"
#include "scan_refiner.hpp"
#include "scan_store.hpp"
#include "se2.hpp"

namespace traverse::backend {

struct LoopCloserConfig {
  double search_radius_m = 2.5;       // old key poses this close to the newest start an episode [m]
  double min_travel_m = 10.0;         // ... if at least this far back along the trajectory [m]
  double chain_radius_m = 8.0;        // chain: old key poses within this of the newest pose [m]
  int max_chain_length = 30;          // key scans in a chain at most
  int max_candidates = 9;             // current key scans tried per episode (~3 s at 3 Hz)
  double min_coarse_response = 0.5;   // [0..1]
  double min_fine_response = 0.6;     // [0..1]
  double max_ambiguity_ratio = 0.85;  // second peak / peak above this: ambiguous, rejected
  // The second peak lies at least this far from the peak [m]: repeated shelves or doors 0.5 m
  // apart must count as a second peak.
  double ambiguity_exclusion_m = 0.3;
  double max_sigma_xy_m = 0.08;       // largest standard deviation of the fine match [m]
  double max_sigma_theta_rad = 0.02;  // [rad]
  // 5. The correction the closure implies for the current pose, against the sum of the match's
  //    covariance and the marginals of both key poses: above this Mahalanobis distance the
  //    closure contradicts the graph (0: not checked).
  double max_correction_mahalanobis = 5.0;
  // The closure's covariance is the fine match's (the spread of its response surface) times
  // this [unitless].
  double covariance_scale = 1.0;
  // Coarse: a wide window (the drift a loop can carry) on a 5 cm grid, almost no penalty.
  CorrelativeMatcherConfig coarse{.resolution_m = 0.05,
                                  .coarse_factor = 8,
                                  .angle_step_rad = 0.01,
                                  .linear_window_m = 2.0,
                                  .angular_window_rad = 0.35,
                                  .kernel_sigma_m = 0.06,
                                  .penalty_sigma_xy_m = 10.0,
                                  .penalty_sigma_theta_rad = 2.0,
                                  .covariance_response_drop = 0.05,
                                  .covariance_window_cells = 10,
                                  .max_query_points = 300};
  // Fine: around the coarse peak on a 2 cm grid.
  CorrelativeMatcherConfig fine{.resolution_m = 0.02,
                                .coarse_factor = 4,
                                .angle_step_rad = 0.002,
                                .linear_window_m = 0.12,
                                .angular_window_rad = 0.03,
                                .kernel_sigma_m = 0.03,
                                .penalty_sigma_xy_m = 10.0,
                                .penalty_sigma_theta_rad = 2.0,
                                .covariance_response_drop = 0.05,
                                .covariance_window_cells = 8,
                                .max_query_points = 400};
  // Then point-to-line refinement of the fine match (scan_refiner.hpp): the closure takes its pose
  // and keeps the fine match's covariance. The refinement's own covariance was measured too
  // tight on the simulated office (closure heading errors of 1e-4 rad against 2e-5 rad), and
  // weighting closures by it made the trajectory worse (2.5 mm against 0.96 mm position RMSE).
  RefinerConfig refine;
  bool refined_covariance = false;  // the closure takes the refinement's covariance instead
  // A closure whose refinement leaves a direction open (a corridor's axis: an eigenvalue of the
  // refiner's information below this share of the largest, common/degeneracy.hpp) is opened
  // there, before the correction check, by the variance its information allows, at most
  // open_sigma_m: the correlative surface claims centimetres along such an axis where the scans
  // can slip by decimetres (intel, sub-cell hits, full graph: a closure 0.37 m off along a
  // corridor with a 3.6 cm sigma bent a minute of the log by 0.27 m). 0: never opened.
  double degeneracy_min_ratio = 0.0;
  double open_sigma_m = 10.0;  // [m] of point motion

  template <class V>
  void visit(V& v) {
    v("search_radius_m", search_radius_m);
    v("min_travel_m", min_travel_m);
    v("chain_radius_m", chain_radius_m);
    v("max_chain_length", max_chain_length);
    v("max_candidates", max_candidates);
    v("min_coarse_response", min_coarse_response);
    v("min_fine_response", min_fine_response);
    v("max_ambiguity_ratio", max_ambiguity_ratio);
    v("ambiguity_exclusion_m", ambiguity_exclusion_m);
    v("max_sigma_xy_m", max_sigma_xy_m);
    v("max_sigma_theta_rad", max_sigma_theta_rad);
    v("max_correction_mahalanobis", max_correction_mahalanobis);
    v("covariance_scale", covariance_scale);
    v("coarse", coarse);
    v("fine", fine);
    v("refine", refine);
    v("refined_covariance", refined_covariance);
    v("degeneracy_min_ratio", degeneracy_min_ratio);
    v("open_sigma_m", open_sigma_m);
  }
};

std::optional<std::string> validate(const LoopCloserConfig& config);

struct LoopClosure {
  int from = 0;     // old key pose of the chain (nearest to the match)
  int to = 0;       // current key pose
  Pose2 T_from_to;  // measured pose of `to` in the frame of `from`
  // Covariance of the measurement on (x [m], y [m], theta [rad]) in the frame of `to`, as the
  // pose graph's edge error is expressed: m^2, m rad, rad^2.
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();
  double response = 0.0;     // fine raw response [0..1]
  int candidates_tried = 0;  // candidates of the episode
  // [unitless] how much the pose graph's chi2 grew when the closure was added (the backend's
  // trial optimisation); 0 when not checked.
  double chi2_increase = 0.0;
};

struct LoopCloserCounters {
  long episodes = 0;
  long candidates = 0;         // key scans matched against a chain
  long rejected_response = 0;  // coarse or fine response too low
  long rejected_ambiguous = 0;
  long rejected_covariance = 0;
  long refined = 0;                // fine matches refined point to line
  long refine_failed = 0;          // ... where refinement failed (the fine match is kept)
  long opened = 0;                 // ... left a direction open: the covariance opened there
  long rejected_inconsistent = 0;  // correction too large for the marginals
  long closures = 0;
};

class LoopCloser {
 public:
  // The config must pass validate().
  explicit LoopCloser(LoopCloserConfig config);

  // Key pose `current` is the newest; poses are the current estimates T_world_base of all key
  // poses and travel_m their distance along the trajectory [m]; marginals (world frame, per key
  // pose) enable check 5. Returns a closure when this call ends an episode that had an accepted
  // candidate.
  std::optional<LoopClosure> add(int current, const std::vector<Pose2>& poses,
                                 const std::vector<double>& travel_m, const ScanStore& scans,
                                 const std::vector<Eigen::Matrix3d>* marginals = nullptr);
  // Ends the open episode (end of data).
  std::optional<LoopClosure> finish();

  // One candidate: the current key scan against the chain [chain_first, chain_last]; nullopt when
  // a check rejects it (counted). Exposed for tests.
  std::optional<LoopClosure> try_candidate(int current, int chain_first, int chain_last,
                                           const std::vector<Pose2>& poses, const ScanStore& scans,
                                           const std::vector<Eigen::Matrix3d>* marginals = nullptr);

  const LoopCloserCounters& counters() const { return counters_; }

 private:
  LoopCloserConfig config_;
  CorrelativeMatcher coarse_, fine_;
  ScanRefiner refiner_;
  LoopCloserCounters counters_;
  bool open_ = false;
  int chain_first_ = 0, chain_last_ = 0;  // chain of the open episode
  int episode_candidates_ = 0;
  std::optional<LoopClosure> best_;
};

}  // namespace traverse::backend
