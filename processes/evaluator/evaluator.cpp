#include "evaluator.hpp"

#include <algorithm>
#include <cmath>

#include "config.hpp"

namespace traverse::evaluator {

std::optional<std::string> validate(const EvaluatorConfig& config) {
  ConfigCheck check;
  check.require(parse_align(config.align).has_value(), "align",
                "must be one of none, first_pose, se2, got '" + config.align + "'");
  check.positive("max_reference_gap_us", config.match.max_reference_gap_us);
  check.not_negative("edge_tolerance_us", config.match.edge_tolerance_us);
  check.positive("false_closure_sigmas", config.false_closure_sigmas);
  check.not_empty("key_poses_channel", config.key_poses_channel);
  check.in_range("min_reference_share", config.min_reference_share, 0.0, 1.0);
  check.not_negative("relation_time_tolerance_us", config.relation_time_tolerance_us);
  return check.problem();
}

void shift(Trajectory& trajectory, double dx_m, double dy_m, double dtheta_rad) {
  for (StampedPose& p : trajectory) {
    p.pose = Pose2(p.pose.x() + dx_m, p.pose.y() + dy_m, p.pose.theta() + dtheta_rad);
  }
}

Evaluation evaluate(Trajectory estimate, Trajectory reference, const EvaluatorConfig& config) {
  sort_unique(estimate);
  sort_unique(reference);
  Evaluation ev;
  ev.estimate_poses = estimate.size();
  ev.reference_poses = reference.size();

  // 1. Match: the reference interpolated at every estimate time.
  const ReferenceInterpolator interpolator(reference, config.match);
  std::vector<Pose2> est, ref;
  std::vector<Eigen::Matrix3d> cov;
  std::vector<double> travel_m;
  std::vector<int64_t> utimes;
  for (const StampedPose& e : estimate) {
    const auto r = interpolator.at(e.utime);
    if (!r) {
      ++ev.unmatched;
      continue;
    }
    est.push_back(e.pose);
    cov.push_back(e.covariance);
    ref.push_back(r->pose);
    travel_m.push_back(r->travel_m);
    utimes.push_back(e.utime);
  }
  ev.matched = est.size();
  if (!utimes.empty()) {
    ev.reference_covered = static_cast<std::size_t>(
        std::count_if(reference.begin(), reference.end(), [&](const StampedPose& r) {
          return r.utime >= utimes.front() && r.utime <= utimes.back();
        }));
  }
  ev.reference_share = reference.empty() ? 0.0
                                         : static_cast<double>(ev.reference_covered) /
                                               static_cast<double>(reference.size());
  ev.refused = ev.reference_share < config.min_reference_share;

  // 2. Align the estimate's frame to the reference frame.
  ev.alignment = compute_alignment(*parse_align(config.align), est, ref);
  for (Pose2& p : est) p = ev.alignment.T_ref_est * p;
  Eigen::Matrix3d A = Eigen::Matrix3d::Identity();  // (x, y, theta) into the reference frame
  A.topLeftCorner<2, 2>() = ev.alignment.T_ref_est.rotation();
  for (Eigen::Matrix3d& c : cov) c = A * c * A.transpose();

  // 3. Absolute errors per matched pose.
  std::vector<double> position_m, heading_rad;
  ev.samples.reserve(est.size());
  for (std::size_t i = 0; i < est.size(); ++i) {
    ErrorSample s;
    s.utime = utimes[i];
    s.T_ref_est = est[i];
    s.T_ref_true = ref[i];
    s.position_error_m = (est[i].translation() - ref[i].translation()).norm();
    s.heading_error_rad = wrap_angle(est[i].theta() - ref[i].theta());
    s.travel_m = travel_m[i];
    position_m.push_back(s.position_error_m);
    heading_rad.push_back(std::abs(s.heading_error_rad));
    ev.samples.push_back(s);
  }
  ev.position_m = error_stats(position_m);
  ev.heading_rad = error_stats(heading_rad);

  // 4. Relative errors over travel, and the largest jump.
  ev.rpe_1m = relative_pose_error(est, ref, travel_m, 1.0);
  ev.rpe_10m = relative_pose_error(est, ref, travel_m, 10.0);
  ev.max_jump = max_jump(est, ref);
  ev.step_consistency = step_consistency(est, cov, ref);
  if (!utimes.empty()) {
    ev.duration_s = 1e-6 * static_cast<double>(utimes.back() - utimes.front());
    ev.length_m = travel_m.back() - travel_m.front();
  }
  return ev;
}

}  // namespace traverse::evaluator
