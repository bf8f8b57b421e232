// The link from the last key pose to a new one (backend.hpp, step 3): the new key scan matched
// against the last few key scans around the frontend's relative motion, the frontend's step
// checked against the wheel odometry (odometry_check.hpp), the match refined point to line
// (scan_refiner.hpp) and held along the directions its scans leave open (common/degeneracy.hpp).
#include <Eigen/LU>
#include <algorithm>

#include "backend.hpp"
#include "degeneracy.hpp"

namespace traverse::backend {
namespace {

// A link is held along an open direction at the odometry's step only over a stream's key step
// (a third of a second; at most half a second): not where a log subsampled by travel has its key
// scans seconds apart, nor at its first poses, before five intervals tell it from a stream (one
// link held there on the CARMEN aces log moved its position RMSE from 0.186 to 0.224 m).
constexpr int64_t kMaxHeldLinkStepUs = 500000;

}  // namespace

Backend::KeyStep Backend::link_key(int index, const std::vector<Eigen::Vector2f>& points,
                                   const PreparedPose& now) {
  const int prev = index - 1;
  const Pose2& T_world_prev = key_poses_[prev].T_world_base;
  const bool frontend = frontend_edges();
  KeyStep step;
  step.motion = between(last_key_.T_world_base, now.T_world_base);
  std::vector<Eigen::Vector2d> reference;
  for (int j = std::max(0, index - config_.link_chain_length); j < index; ++j) {
    scans_.append_world(j, key_poses_[j].T_world_base, reference);
  }
  std::vector<Eigen::Vector2d> query(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) query[i] = points[i].cast<double>();
  MatchResult m = link_matcher_.match(reference, query, T_world_prev * step.motion);
  // Where the odometry's step replaces the frontend's: diag(|e_xy|^2, |e_xy|^2, e_theta^2) of the
  // two steps' difference e (first pose's frame), added to the covariance of the link and of the
  // odometry's edge (below).
  Eigen::Matrix3d disagreement = Eigen::Matrix3d::Zero();
  // A frontend step the odometry contradicts: the scans decide. The link is matched around the
  // odometry's step too, and the odometry's step replaces the frontend's only if the scans
  // agree with it better (an odometry that slips or a log's restarted odometry must not
  // replace a good frontend step).
  if (frontend) {
    const auto [ca, cb] = frontend_covariances();
    std::optional<OdometryStep> odometry =
        odometry_.check(last_key_.utime, now.utime, step.motion, ca + cb);
    std::optional<OdometryStep> net;
    if (odometry && odometry->frontend_rejected && step_before_from_odometry_) {
      net = spike_net_step(now, *step_before_from_odometry_, ca + cb);
    }
    if (net) {
      // The frontend's last key pose was a spike: its two steps cancel, and their sum agrees
      // with the odometry. The odometry placed that pose; this step takes the frontend's net.
      const MatchResult mn = link_matcher_.match(reference, query, T_world_prev * net->motion);
      if (mn.valid) m = mn;
      step.motion = net->motion;
      step.odometry = net;
      step.netted = true;
      ++counters_.frontend_spikes_netted;
    } else if (odometry && odometry->frontend_rejected) {
      const MatchResult mo = link_matcher_.match(reference, query, T_world_prev * odometry->motion);
      if (mo.valid && scans_side_with_odometry(
                          *odometry, step.motion, ca + cb, between(T_world_prev, mo.T_world_query),
                          rotate_covariance(mo.covariance, T_world_prev.rotation().transpose()),
                          mo.raw_response, m.valid ? m.raw_response : 0.0,
                          config_.odometry.max_frontend_chi2)) {
        // The frontend's step may still be right about where the platform is, only not about how
        // it got there: a scan-to-map frontend that has drifted snaps back to its map when it
        // comes back to ground it mapped (aces from a heading 1 mrad off: a 1.19 m step in
        // 0.24 s that the relations confirm; held at the odometry's step the whole rest of the
        // run stayed 1.04 m off, and 162 true closures were refused as contradicting the
        // graph). The two steps' difference is how far apart the two stories put the platform:
        // the replacing edges carry it as covariance, so a closure can settle which holds. Its
        // length, in every direction: the drift the snap undid ran along its own path, not along
        // the one step (carried as e e^T alone, the heading start of aces stayed 0.0555 m; so,
        // 0.0395 m, its frontend's 0.0398 m).
        Eigen::Vector3d e = (step.motion.vector() - odometry->motion.vector());
        e.z() = wrap_angle(e.z());
        const double exy2 = e.head<2>().squaredNorm();
        disagreement = Eigen::Vector3d(exy2, exy2, e.z() * e.z()).asDiagonal();
        m = mo;
        step.motion = odometry->motion;
        step.odometry = odometry;
        step.odometry->covariance += disagreement;
        ++counters_.frontend_steps_replaced;
      }
    }
  }
  Edge link;
  link.from = key_vertex(prev);
  link.to = key_vertex(index);
  if (m.valid && m.raw_response >= config_.min_link_response) {
    Pose2 T_world_key = m.T_world_query;
    Eigen::Matrix3d covariance = m.covariance;  // world frame
    if (config_.link_refine.enabled) {
      const RefineResult r = link_refiner_.refine(reference, query, T_world_key);
      if (r.valid) {
        ++counters_.links_refined;
        T_world_key = r.T_world_query;
        hold_open_directions(r, now, T_world_prev, step.motion, T_world_key, covariance);
      }
    }
    link.T_from_to = between(T_world_prev, T_world_key);
    const Eigen::Matrix3d information =
        (rotate_covariance(config_.link_covariance_scale * covariance +
                               rotate_covariance(disagreement, T_world_prev.rotation()),
                           T_world_key.rotation().transpose()))
            .inverse();
    // Symmetric as published: the inverse of a covariance as ill-conditioned as a held link's
    // (1e-2 along a corridor, 1e-6 in heading) is symmetric only to rounding.
    link.information = 0.5 * (information + information.transpose());
    step.link = link;
    ++counters_.links_matched;
  } else if (!frontend) {
    ++counters_.links_fallback;
    const double sxy = config_.fallback_sigma_xy_m, sth = config_.fallback_sigma_theta_rad;
    link.T_from_to = step.motion;
    link.information =
        Eigen::Vector3d(1.0 / (sxy * sxy), 1.0 / (sxy * sxy), 1.0 / (sth * sth)).asDiagonal();
    step.link = link;
  }
  return step;
}

std::optional<OdometryStep> Backend::spike_net_step(const PreparedPose& now,
                                                    const Pose2& step_before,
                                                    const Eigen::Matrix3d& step_covariance) const {
  // The frontend's motion over both steps against the odometry's over the same interval, with
  // both steps' frontend covariances.
  const Pose2 frontend_net = between(key_before_last_.T_world_base, now.T_world_base);
  const std::optional<OdometryStep> both =
      odometry_.compare(key_before_last_.utime, now.utime, frontend_net, 2.0 * step_covariance);
  if (!both || both->frontend_rejected) return std::nullopt;
  OdometryStep step = *both;
  step.motion = step_before.inverse() * frontend_net;
  return step;
}

void Backend::hold_open_directions(const RefineResult& refined, const PreparedPose& now,
                                   const Pose2& T_world_from, const Pose2& frontend_motion,
                                   Pose2& T_world_key, Eigen::Matrix3d& covariance) {
  if (config_.link_degeneracy_min_ratio <= 0.0) return;
  if (now.sparse || now.utime - last_key_.utime > kMaxHeldLinkStepUs) return;
  const Degeneracy d =
      analyse_degeneracy(refined.information, refined.lever_m, config_.link_degeneracy_min_ratio);
  if (d.directions == 0) return;
  ++counters_.links_opened;
  const std::optional<OdometryStep> odometry =
      odometry_.compare(last_key_.utime, now.utime, frontend_motion, Eigen::Matrix3d::Zero());
  if (!odometry || odometry->frontend_rejected) {
    covariance = opened_covariance(d, covariance, config_.link_open_sigma_m);
    return;
  }
  T_world_key = remap(d, T_world_from * odometry->motion, T_world_key);
  covariance = held_covariance(d, covariance,
                               rotate_covariance(odometry->covariance, T_world_from.rotation()));
  ++counters_.links_held;
}

}  // namespace traverse::backend
