#include "extrinsic_yaw.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "config.hpp"

namespace traverse::calibration {
namespace {

// A chord turning more than this is left out: a turn on the spot, a corner, where its direction
// is not its mean heading (on a path that turns by t over a chord, to about t^3).
constexpr double kMaxChordTurnRad = 0.2;
// A chord further than this from the heading is no forward motion (a glitch, reversing).
constexpr double kMaxChordAngleRad = 0.2;
// The noise of a matched position, for the information of a chord's angle against the priors'
// (the fit's result depends only on the ratio): 5 mm.
constexpr double kPositionSigmaM = 0.005;
constexpr double kYawPriorSigmaRad = 0.01;
constexpr double kLeverArmPriorSigmaM = 0.5;

}  // namespace

std::optional<std::string> validate(const ExtrinsicYawConfig& c) {
  ConfigCheck check;
  check.in_range("chord_m", c.chord_m, 0.05, 100.0);
  check.in_range("min_travel_m", c.min_travel_m, 0.0, 1e6);
  check.in_range("max_yaw_rad", c.max_yaw_rad, 0.0, 0.5);
  return check.problem();
}

Pose2 turned_about(const Pose2& T_map_bhat, const Eigen::Vector2d& origin, double delta) {
  const Eigen::Vector2d p =
      origin + Pose2(0.0, 0.0, delta).rotation() * (T_map_bhat.translation() - origin);
  return Pose2(p.x(), p.y(), T_map_bhat.theta());
}

void ExtrinsicYawEstimator::reset() {
  chord_.clear();
  A_.setZero();
  b_.setZero();
  c_ = 0.0;
  travel_m_ = 0.0;
  chords_ = rejected_ = 0;
}

void ExtrinsicYawEstimator::restart(const Pose2& T) {
  chord_.clear();
  chord_.push_back(T);
}

ExtrinsicYawEstimator::ExtrinsicYawEstimator(const ExtrinsicYawConfig& config) : config_(config) {}

void ExtrinsicYawEstimator::add_pose(const Pose2& T) {
  if (chord_.empty()) {
    chord_.push_back(T);
    return;
  }
  const Pose2 T_anchor = chord_.front();
  const Eigen::Vector2d chord = T.translation() - T_anchor.translation();
  const double turn = wrap_angle(T.theta() - T_anchor.theta());
  if (std::abs(turn) > kMaxChordTurnRad) {
    restart(T);
    ++rejected_;
    return;
  }
  const double d = chord.norm();
  if (d < config_.chord_m) {
    chord_.push_back(T);
    return;
  }
  chord_.push_back(T);
  // The heading averaged along the chord (by distance travelled): the chord's direction for a
  // path whose heading varies little over it (exact on an arc; a pushed cart's weave, its wobble
  // and the matcher's noise average out).
  double heading_sum = 0.0, length = 0.0;
  for (std::size_t k = 1; k < chord_.size(); ++k) {
    const double ds = (chord_[k].translation() - chord_[k - 1].translation()).norm();
    const double mid = 0.5 * (wrap_angle(chord_[k].theta() - T_anchor.theta()) +
                              wrap_angle(chord_[k - 1].theta() - T_anchor.theta()));
    heading_sum += ds * mid;
    length += ds;
  }
  const double mean_heading = T_anchor.theta() + (length > 0.0 ? heading_sum / length : 0.0);
  restart(T);
  const double phi = wrap_angle(std::atan2(chord.y(), chord.x()) - mean_heading);
  if (std::abs(phi) > kMaxChordAngleRad) {
    ++rejected_;
    return;
  }
  // phi = -delta + a * kappa: one row of the weighted least squares.
  const Eigen::Vector2d h(-1.0, turn / d);
  // Information of the chord's angle: two positions of kPositionSigmaM, d apart.
  const double w = d * d / (2.0 * kPositionSigmaM * kPositionSigmaM);
  A_ += w * h * h.transpose();
  b_ += w * phi * h;
  c_ += w * phi * phi;
  travel_m_ += d;
  ++chords_;
}

Eigen::Matrix2d ExtrinsicYawEstimator::normal_matrix() const {
  // The priors (zero mean) keep the fit defined before any chord, and a before any turn.
  Eigen::Matrix2d A = A_;
  A(0, 0) += 1.0 / (kYawPriorSigmaRad * kYawPriorSigmaRad);
  A(1, 1) += 1.0 / (kLeverArmPriorSigmaM * kLeverArmPriorSigmaM);
  return A;
}

Eigen::Vector2d ExtrinsicYawEstimator::solution() const { return normal_matrix().inverse() * b_; }

double ExtrinsicYawEstimator::yaw_sigma_rad() const {
  const Eigen::Matrix2d covariance = normal_matrix().inverse();
  // The chords' weighted squared residuals about the fit (c - 2 x'b + x'A x) over their degrees
  // of freedom: the factor by which the assumed position noise was too small, if it was.
  double factor = 1.0;
  if (chords_ > 2) {
    const Eigen::Vector2d x = solution();
    const double chi2 = c_ - 2.0 * x.dot(b_) + x.dot(A_ * x);
    factor = std::max(1.0, chi2 / static_cast<double>(chords_ - 2));
  }
  return std::sqrt(factor * covariance(0, 0));
}

std::optional<double> ExtrinsicYawEstimator::yaw_rad() const {
  if (travel_m_ < config_.min_travel_m) return std::nullopt;
  const double delta = solution().x();
  if (std::abs(delta) > config_.max_yaw_rad) return std::nullopt;
  return delta;
}

}  // namespace traverse::calibration
