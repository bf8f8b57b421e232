// Checking the backend's loop closures against the reference trajectory.
//
// A closure measures Z = T_from_to, the pose of key pose `to` in the frame of key pose `from`.
// The truth is T_true = T_ref(from_utime)^-1 T_ref(to_utime), the reference interpolated at both
// times (independent of any alignment of the estimate). The error is the one the backend's pose
// graph minimises (g2o EDGE_SE2, processes/backend/pose_graph.hpp):
//   e = t2v(Z^-1 T_true)   (translation in Z's frame, angle wrapped),
// and the closure's covariance C is the covariance of that error. A closure is false when its
// Mahalanobis distance sqrt(e^T C^-1 e) exceeds a number of standard deviations (config
// false_closure_sigmas): the matcher claimed a precision the truth does not bear out.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <utility>
#include <vector>

#include "relations.hpp"
#include "trajectory.hpp"

namespace traverse::evaluator {

struct LoopClosure {
  int64_t from_id = 0;     // older key pose
  int64_t to_id = 0;       // current key pose
  int64_t from_utime = 0;  // [us] time of from_id
  int64_t to_utime = 0;    // [us] time of to_id
  Pose2 T_from_to;         // the measurement Z
  // Covariance of the error (x [m], y [m], theta [rad]) in to's frame: m^2, m*rad, rad^2.
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
};

// Closures by (from_id, to_id): a repeated closure replaces the earlier copy.
class LoopClosureSet {
 public:
  void add(const LoopClosure& closure);
  std::vector<LoopClosure> closures() const;  // ordered by (from_id, to_id)
  std::size_t size() const { return by_ids_.size(); }
  std::size_t repeated() const { return repeated_; }

 private:
  std::map<std::pair<int64_t, int64_t>, LoopClosure> by_ids_;
  std::size_t repeated_ = 0;
};

struct ClosureCheck {
  LoopClosure closure;
  bool matched = false;  // both times inside the reference (trajectory.hpp's matching rules)
  Pose2 T_true;          // T_ref(from)^-1 T_ref(to), when matched
  Eigen::Vector3d error = Eigen::Vector3d::Zero();  // e: [m], [m], [rad], when matched
  Eigen::Vector3d sigma = Eigen::Vector3d::Zero();  // sqrt(diag C): [m], [m], [rad]
  // sqrt(e^T C^-1 e) [unitless]; nullopt when C is not a finite positive-definite matrix.
  std::optional<double> mahalanobis;
  bool is_false = false;  // mahalanobis > false_closure_sigmas
  // By relations: the error of the frontend's own relative pose F(from)^-1 F(to) against the same
  // T_true, as `error`: where the closure is not nearer the truth, it cannot straighten the path.
  std::optional<Eigen::Vector3d> frontend_error;
};

struct ClosureEvaluation {
  std::vector<ClosureCheck> checks;  // one per closure, same order as given
  std::size_t closures = 0;
  std::size_t false_closures = 0;
  std::size_t unmatched = 0;
  std::size_t bad_covariance = 0;  // matched, but C not positive definite: neither true nor false
  std::optional<double> max_mahalanobis;  // [unitless] over matched closures with a valid C
  std::optional<double> max_error_m;      // [m] largest |e_xy| over matched closures
  std::optional<double> rms_error_m;      // [m] RMS of |e_xy| over matched closures
  // By relations: the frontend's error over a bridge added to the truth's covariance (m^2, rad^2;
  // zero when too few short relations measure it, or against a reference).
  Eigen::Matrix3d bridge_covariance = Eigen::Matrix3d::Zero();
};

// Medians over the matched closures (the mean of the middle two for an even count), and the
// frontend's error over the same pairs where it is known.
struct ClosureMedians {
  std::size_t checked = 0;                   // matched closures
  std::optional<double> error_m;             // [m] of |e_xy|
  std::optional<double> error_rad;           // [rad] of |e_theta|
  std::optional<double> max_error_rad;       // [rad] largest |e_theta|
  std::optional<double> mahalanobis;         // [unitless] over those with a valid covariance
  std::optional<double> frontend_error_m;    // [m] of the frontend's |e_xy|
  std::optional<double> frontend_error_rad;  // [rad] of the frontend's |e_theta|
  std::size_t closure_nearer = 0;  // closures nearer the truth than the frontend by over 1 um
};
ClosureMedians medians(const ClosureEvaluation& evaluation);

// `reference` in any order (repeated times keep their first pose); `false_sigmas` > 0.
ClosureEvaluation check_closures(const std::vector<LoopClosure>& closures, Trajectory reference,
                                 const MatchConfig& match, double false_sigmas);

// The same check with ground truth from relations (relations.hpp) instead of a reference
// trajectory. A closure links two key poses at times no relation names, so it is checked where a
// relation has one scan within `window_us` of each key pose (either way round; the nearest pair
// of ends): the truth between the key poses is then the frontend's own motion from the first key
// pose to the relation's scan, the relation, and the frontend's motion from its other scan to the
// second key pose,
//   T_true = F(from)^-1 F(t1) * R(t1, t2) * F(t2)^-1 F(to),
// F the frontend's pose nearest each time. The frontend's error over each bridge enters the truth:
// it is measured on the same log, by the relations whose two scans lie within `window_us` of each
// other (their mean e e^T, x and y made isotropic; on the subsampled freiburg-079 log 0.3 deg
// median, up to 4 deg through fast turns), and added to the closure's covariance, carried through
// the composition, for each bridge that is not empty. A closure no relation reaches is unmatched.
// `frontend` in any order.
ClosureEvaluation check_closures_by_relations(const std::vector<LoopClosure>& closures,
                                              Trajectory frontend,
                                              const std::vector<Relation>& relations,
                                              int64_t window_us, double false_sigmas);

}  // namespace traverse::evaluator
