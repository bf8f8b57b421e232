#include "loop_closer.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <cmath>

#include "config.hpp"
#include "degeneracy.hpp"

namespace traverse::backend {

std::optional<std::string> validate(const LoopCloserConfig& c) {
  ConfigCheck check;
  check.positive("search_radius_m", c.search_radius_m);
  check.require(c.chain_radius_m >= c.search_radius_m, "chain_radius_m",
                "must be at least search_radius_m");
  check.not_negative("min_travel_m", c.min_travel_m);
  check.in_range("max_chain_length", c.max_chain_length, 1, 10000);
  check.in_range("max_candidates", c.max_candidates, 1, 10000);
  check.in_range("min_coarse_response", c.min_coarse_response, 0.0, 1.0);
  check.in_range("min_fine_response", c.min_fine_response, 0.0, 1.0);
  check.positive("max_ambiguity_ratio", c.max_ambiguity_ratio);
  check.positive("ambiguity_exclusion_m", c.ambiguity_exclusion_m);
  check.positive("max_sigma_xy_m", c.max_sigma_xy_m);
  check.positive("max_sigma_theta_rad", c.max_sigma_theta_rad);
  check.not_negative("max_correction_mahalanobis", c.max_correction_mahalanobis);
  check.positive("covariance_scale", c.covariance_scale);
  check.in_range("degeneracy_min_ratio", c.degeneracy_min_ratio, 0.0, 1.0);
  check.positive("open_sigma_m", c.open_sigma_m);
  check.nested("coarse", validate(c.coarse));
  check.nested("fine", validate(c.fine));
  check.nested("refine", validate(c.refine));
  return check.problem();
}

LoopCloser::LoopCloser(LoopCloserConfig config)
    : config_(std::move(config)),
      coarse_(config_.coarse),
      fine_(config_.fine),
      refiner_(config_.refine) {}

std::optional<LoopClosure> LoopCloser::try_candidate(
    int current, int chain_first, int chain_last, const std::vector<Pose2>& poses,
    const ScanStore& scans, const std::vector<Eigen::Matrix3d>* marginals) {
  ++counters_.candidates;
  std::vector<Eigen::Vector2d> reference;
  for (int j = chain_first; j <= chain_last; ++j) scans.append_world(j, poses[j], reference);
  const std::vector<Eigen::Vector2d> query = scans.points_d(current);

  // 1.-2. Coarse search over the wide window, with the ambiguity check.
  const MatchResult coarse = coarse_.match(
      reference, query, poses[current], config_.ambiguity_exclusion_m, config_.max_ambiguity_ratio);
  if (!coarse.valid || coarse.raw_response < config_.min_coarse_response) {
    ++counters_.rejected_response;
    return std::nullopt;
  }
  const double ambiguity = coarse.second_peak_response / coarse.raw_response;
  if (ambiguity > config_.max_ambiguity_ratio) {
    ++counters_.rejected_ambiguous;
    return std::nullopt;
  }
  // 3.-4. Fine search around the coarse peak, response and covariance checks.
  const MatchResult fine = fine_.match(reference, query, coarse.T_world_query);
  if (!fine.valid || fine.raw_response < config_.min_fine_response) {
    ++counters_.rejected_response;
    return std::nullopt;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(fine.covariance.topLeftCorner<2, 2>());
  if (std::sqrt(eig.eigenvalues().maxCoeff()) > config_.max_sigma_xy_m ||
      std::sqrt(fine.covariance(2, 2)) > config_.max_sigma_theta_rad) {
    ++counters_.rejected_covariance;
    return std::nullopt;
  }

  Pose2 T_world_current = fine.T_world_query;
  Eigen::Matrix3d covariance = config_.covariance_scale * fine.covariance;
  if (config_.refine.enabled) {
    const RefineResult refined = refiner_.refine(reference, query, fine.T_world_query);
    if (refined.valid) {
      ++counters_.refined;
      T_world_current = refined.T_world_query;
      if (config_.refined_covariance) covariance = refined.covariance;
      if (config_.degeneracy_min_ratio > 0.0) {
        const Degeneracy d = analyse_degeneracy(refined.information, refined.lever_m,
                                                config_.degeneracy_min_ratio);
        if (d.directions > 0) {
          ++counters_.opened;
          covariance = opened_covariance(d, covariance, config_.open_sigma_m);
        }
      }
    } else {
      ++counters_.refine_failed;
    }
  }

  LoopClosure closure;
  closure.to = current;
  double nearest = 1e300;
  for (int j = chain_first; j <= chain_last; ++j) {
    const double d = (poses[j].translation() - T_world_current.translation()).norm();
    if (d < nearest) nearest = d, closure.from = j;
  }
  closure.T_from_to = between(poses[closure.from], T_world_current);
  // 5. The implied correction of the current pose must fit the graph's own uncertainty.
  if (marginals && config_.max_correction_mahalanobis > 0.0) {
    const Eigen::Vector3d d(T_world_current.x() - poses[current].x(),
                            T_world_current.y() - poses[current].y(),
                            wrap_angle(T_world_current.theta() - poses[current].theta()));
    const Eigen::Matrix3d S = covariance + (*marginals)[closure.from] + (*marginals)[current];
    if (std::sqrt(d.dot(S.ldlt().solve(d))) > config_.max_correction_mahalanobis) {
      ++counters_.rejected_inconsistent;
      return std::nullopt;
    }
  }
  // The matcher's covariance is in the world frame; the edge error's translation is in the frame
  // of the `to` pose.
  closure.covariance = rotate_covariance(covariance, T_world_current.rotation().transpose());
  closure.response = fine.raw_response;
  return closure;
}

std::optional<LoopClosure> LoopCloser::add(int current, const std::vector<Pose2>& poses,
                                           const std::vector<double>& travel_m,
                                           const ScanStore& scans,
                                           const std::vector<Eigen::Matrix3d>* marginals) {
  // Old key poses near the newest one, and the nearest of them.
  const Eigen::Vector2d p = poses[current].translation();
  const auto old_and_within = [&](int j, double radius) {
    return travel_m[current] - travel_m[j] >= config_.min_travel_m &&
           (poses[j].translation() - p).norm() <= radius;
  };
  int nearest = -1;
  double nearest_d = 1e300;
  for (int j = 0; j < current; ++j) {
    if (!old_and_within(j, config_.search_radius_m)) continue;
    const double d = (poses[j].translation() - p).norm();
    if (d < nearest_d) nearest_d = d, nearest = j;
  }
  if (nearest < 0) return finish();  // the platform left the old chain (or never met one)

  // The chain: old key poses around the nearest, alternately extended on both sides.
  int first = nearest, last = nearest;
  bool grow_back = true, grow_fwd = true;
  while ((grow_back || grow_fwd) && last - first + 1 < config_.max_chain_length) {
    if (grow_back) {
      grow_back = first > 0 && old_and_within(first - 1, config_.chain_radius_m);
      if (grow_back) --first;
    }
    if (grow_fwd && last - first + 1 < config_.max_chain_length) {
      grow_fwd = last + 1 < current && old_and_within(last + 1, config_.chain_radius_m);
      if (grow_fwd) ++last;
    }
  }

  // A chain disjoint from the open episode's starts a new episode.
  std::optional<LoopClosure> ended;
  if (open_ && (last < chain_first_ || first > chain_last_)) ended = finish();
  if (!open_) {
    open_ = true;
    ++counters_.episodes;
    episode_candidates_ = 0;
    best_.reset();
  }
  chain_first_ = first;
  chain_last_ = last;
  ++episode_candidates_;
  if (auto candidate = try_candidate(current, first, last, poses, scans, marginals)) {
    if (!best_ || candidate->response > best_->response) best_ = candidate;
  }
  if (ended) return ended;
  if (episode_candidates_ >= config_.max_candidates) return finish();
  return std::nullopt;
}

std::optional<LoopClosure> LoopCloser::finish() {
  if (!open_) return std::nullopt;
  open_ = false;
  std::optional<LoopClosure> closure = std::move(best_);
  best_.reset();
  if (closure) {
    closure->candidates_tried = episode_candidates_;
    ++counters_.closures;
  }
  return closure;
}

}  // namespace traverse::backend
