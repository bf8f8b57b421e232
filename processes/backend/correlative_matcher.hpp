// Correlative scan matching (Olson, "Real-time correlative scan matching", ICRA 2009), as Karto
// uses it to link key scans and to close loops.
//
// The reference points (one scan or a chain of scans, in the world frame) are rasterised into a
// lookup table whose cells hold exp(-d^2 / 2 sigma^2), d the distance to the nearest reference
// point (the "blurred" occupancy of the paper, section III-B). A query scan is scored at every pose
// of a discrete search volume around an initial guess (x, y at the table resolution, heading at
// `angle_step_rad`): the response is the mean table value under its points, in [0, 1].
// The search is the paper's multi-resolution one (section IV): a coarse table whose cell holds the
// maximum of a block of coarse_factor x coarse_factor fine cells bounds the response of every
// translation in that block, so coarse candidates are visited best-first and a block is expanded
// at full resolution only while its bound beats the best fine response found so far; the result is
// the exact maximum over the fine search volume.
// As in Karto, the response is multiplied by a penalty for straying from the initial guess,
// exp(-(d_xy^2 / sigma_xy^2 + d_theta^2 / sigma_theta^2) / 2); a small sigma makes the result
// follow the guess (seed 000 sets this penalty high).
// The covariance is the paper's (section III-D), taken over the fine poses around the best one
// whose response is within `covariance_response_drop` of the best, weighted by their response:
// it is wide along a direction the scene does not constrain (a corridor axis) and narrow across.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "se2.hpp"

namespace traverse::backend {

struct CorrelativeMatcherConfig {
  double resolution_m = 0.03;       // fine table cell = translation step [m]
  int coarse_factor = 8;            // coarse cell = this many fine cells per side
  double angle_step_rad = 0.005;    // heading step [rad]
  double linear_window_m = 0.3;     // search +- this around the guess in x and y [m]
  double angular_window_rad = 0.1;  // search +- this around the guess heading [rad]
  double kernel_sigma_m = 0.04;     // blur of the lookup table (range noise + cell size) [m]
  double penalty_sigma_xy_m = 0.5;  // distance from the guess at which the response drops to 61 %
  double penalty_sigma_theta_rad = 0.3;    // same for the heading [rad]
  double covariance_response_drop = 0.05;  // poses within this of the best response enter the
                                           // covariance [response units, 0..1]
  int covariance_window_cells = 10;        // ... within +- this many fine steps of the best
  int max_query_points = 400;              // query scans are thinned evenly to this many points

  template <class V>
  void visit(V& v) {
    v("resolution_m", resolution_m);
    v("coarse_factor", coarse_factor);
    v("angle_step_rad", angle_step_rad);
    v("linear_window_m", linear_window_m);
    v("angular_window_rad", angular_window_rad);
    v("kernel_sigma_m", kernel_sigma_m);
    v("penalty_sigma_xy_m", penalty_sigma_xy_m);
    v("penalty_sigma_theta_rad", penalty_sigma_theta_rad);
    v("covariance_response_drop", covariance_response_drop);
    v("covariance_window_cells", covariance_window_cells);
    v("max_query_points", max_query_points);
  }
};

// The first value out of range, named by its key; nullopt when the config is valid.
std::optional<std::string> validate(const CorrelativeMatcherConfig& config);

struct MatchResult {
  bool valid = false;         // false: no reference or query points
  Pose2 T_world_query;        // best pose of the query scan
  double response = 0.0;      // penalised response of the best pose [0..1]
  double raw_response = 0.0;  // its response without the penalty [0..1]
  // Best raw response among poses farther than `exclusion_m` from the best (only when asked, and
  // only when above the asked share of raw_response: 0 otherwise); a value close to
  // raw_response means the scene is ambiguous (repeated rooms).
  double second_peak_response = 0.0;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();  // world frame, (x, y, theta):
                                                             // m^2, m rad, rad^2
  long evaluations = 0;  // poses scored (coarse and fine), a measure of the work
};

class CorrelativeMatcher {
 public:
  // The config must pass validate().
  explicit CorrelativeMatcher(CorrelativeMatcherConfig config);

  // Matches query points (query frame) against reference points (world frame) around the guess
  // T_world_guess. If second_peak_exclusion_m > 0, also finds the best raw response outside that
  // distance from the best translation (the ambiguity check of the loop closer), if it exceeds
  // second_peak_min_share times the best's raw response: the search skips every block bounded
  // below that, which is most of a wide window (a loop closer that rejects a second peak above a
  // share of the peak needs no lower one).
  MatchResult match(const std::vector<Eigen::Vector2d>& reference_world,
                    const std::vector<Eigen::Vector2d>& query, const Pose2& T_world_guess,
                    double second_peak_exclusion_m = 0.0, double second_peak_min_share = 0.0) const;

  const CorrelativeMatcherConfig& config() const { return config_; }

 private:
  CorrelativeMatcherConfig config_;
};

}  // namespace traverse::backend
