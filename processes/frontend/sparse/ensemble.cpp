#include "ensemble.hpp"

#include <Eigen/Geometry>
#include <cmath>

#include "vote.hpp"

namespace traverse::frontend {
namespace {

// This many results in a row that are not sparse make a scanner's stream (on the CARMEN logs
// every scan after the first is sparse; a stream pays for three scans).
constexpr int kNotSparseEndingEnsemble = 3;

// Offset of member k (1, 2, ...) from the initial pose: fractions of a cell of `cell_m` in x and y
// and up to a degree of heading, from an additive recurrence of irrational steps (spread evenly,
// the same every run).
Eigen::Vector3d member_offset(int k, double cell_m) {
  const auto frac = [](double v) { return v - std::floor(v); };
  return {cell_m * frac(k * 0.6180339887), cell_m * frac(k * 0.7548776662),
          (2.0 * frac(k * 0.5698402910) - 1.0) * M_PI / 180.0};
}

}  // namespace

SparseEnsemble::SparseEnsemble(const MakeMember& make_member, const Pose2& T_map_base_initial,
                               int members, double cell_m)
    : T_published_last_(T_map_base_initial) {
  for (int k = 0; k < members; ++k) {
    const Eigen::Vector3d o = k == 0 ? Eigen::Vector3d::Zero() : member_offset(k, cell_m);
    const Pose2 T(T_map_base_initial.x() + o.x(), T_map_base_initial.y() + o.y(),
                  T_map_base_initial.theta() + o.z());
    members_.push_back(make_member(T));
    last_.push_back(T);
  }
}

bool SparseEnsemble::add_imu(int64_t utime, const Eigen::Vector3d& angular_velocity_imu) {
  bool taken = false;
  for (std::size_t k = 0; k < members_.size(); ++k) {
    const bool t = members_[k]->add_imu(utime, angular_velocity_imu);
    if (k == 0) taken = t;
  }
  return taken;
}

bool SparseEnsemble::add_odometry(const OdometrySample& odometry) {
  bool taken = false;
  for (std::size_t k = 0; k < members_.size(); ++k) {
    const bool t = members_[k]->add_odometry(odometry);
    if (k == 0) taken = t;
  }
  return taken;
}

FrontendResult SparseEnsemble::process(const Scan& scan) {
  std::vector<std::optional<FrontendResult>> results;
  for (auto& m : members_) results.push_back(m->process(scan));
  if (!results[0]->has_pose()) {
    remember(results);
    return *results[0];
  }
  const FrontendResult result = vote(results);
  remember(results);
  not_sparse_in_a_row_ = result.sparse ? 0 : not_sparse_in_a_row_ + 1;
  if (not_sparse_in_a_row_ >= kNotSparseEndingEnsemble) {
    members_.resize(1);
    last_.resize(1);
  }
  return result;
}

std::optional<FrontendResult> SparseEnsemble::finish() {
  std::vector<std::optional<FrontendResult>> results;
  for (auto& m : members_) results.push_back(m->finish());
  if (!results[0] || !results[0]->has_pose()) return std::nullopt;
  const FrontendResult result = vote(results);
  remember(results);
  return result;
}

FrontendResult SparseEnsemble::vote(const std::vector<std::optional<FrontendResult>>& results) {
  // A member without a pose for this scan does not vote. On the first scan every step is zero
  // (each starts where it was put).
  FrontendResult result = *results[0];
  std::vector<Pose2> steps;
  std::vector<std::size_t> voters;
  for (std::size_t k = 0; k < results.size(); ++k) {
    if (!results[k] || !results[k]->has_pose() || results[k]->utime != result.utime) continue;
    steps.push_back(between(last_[k], results[k]->T_map_base));
    voters.push_back(k);
  }
  const StepVote v = vote_on_steps(steps, T_published_last_.rotation());
  const std::size_t chosen = voters[v.chosen];
  const FrontendResult& c = *results[chosen];
  const Pose2 published = T_published_last_ * steps[v.chosen];
  // The chosen member's covariance, turned from its map frame into the published one, plus the
  // spread of all members' steps about the chosen step.
  const double turn = wrap_angle(published.theta() - c.T_map_base.theta());
  result.covariance =
      rotate_covariance(c.covariance, Eigen::Rotation2Dd(turn).toRotationMatrix()) + v.spread;
  if (result.diagnostics && c.diagnostics) {
    result.diagnostics->T_map_base_predicted =
        T_published_last_ * between(last_[chosen], c.diagnostics->T_map_base_predicted);
    result.diagnostics->ensemble_agreeing = v.support;
    result.diagnostics->ensemble_voting = static_cast<int>(steps.size());
  }
  if (v.support < static_cast<int>(steps.size())) ++steps_disputed_;
  if (!poses_agree(steps[0], steps[v.chosen])) ++steps_outvoted_;
  result.T_map_base = published;
  T_published_last_ = published;
  return result;
}

void SparseEnsemble::remember(const std::vector<std::optional<FrontendResult>>& results) {
  for (std::size_t k = 0; k < results.size(); ++k) {
    if (results[k] && results[k]->has_pose()) last_[k] = results[k]->T_map_base;
  }
}

std::size_t SparseEnsemble::map_bytes() const {
  std::size_t bytes = 0;
  for (const auto& m : members_) bytes += m->map_bytes();
  return bytes;
}

void SparseEnsemble::report(const CounterSink& sink) const {
  members_[0]->report(sink);
  sink("steps_disputed", static_cast<double>(steps_disputed_));
  sink("steps_outvoted", static_cast<double>(steps_outvoted_));
}

}  // namespace traverse::frontend
