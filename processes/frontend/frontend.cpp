#include "frontend.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>

#include "deskew.hpp"

namespace traverse::frontend {
namespace {

// A sweep longer than this is not a sweep of a planar scanner: its times are wrong.
constexpr int64_t kMaxSweepUs = 1'000'000;
// IMU silent for longer than this: rotation comes from constant velocity instead.
constexpr int64_t kImuStaleUs = 500'000;
// Velocity estimates closer than this in time are averaged (exponentially) to tame the noise of
// differencing poses a few milliseconds apart.
constexpr double kVelocitySmoothingS = 0.1;
// Weight of the newest step in the average step of sparse scans (see update_motion()).
constexpr double kSparseStepSmoothing = 0.3;
// Two members' steps agree when they differ by less than this (about three times what a
// member's steps scatter where all are right, a tenth of a typical sparse step).
constexpr double kAgreeM = 0.15, kAgreeRad = 0.05;
// This many scans in a row that are not sparse make a scanner's stream: the ensemble is dropped
// (on the CARMEN logs every scan after the first is sparse; a stream pays for three scans).
constexpr int kDenseScansEndingEnsemble = 3;

// Offset of ensemble member k (1, 2, ...) from the initial pose: fractions of a cell of
// `cell_m` in x and y and up to a degree of heading, from an additive recurrence of irrational
// steps (spread evenly, the same every run).
Pose2 member_offset(int k, double cell_m) {
  const auto frac = [](double v) { return v - std::floor(v); };
  return Pose2(cell_m * frac(k * 0.6180339887), cell_m * frac(k * 0.7548776662),
               (2.0 * frac(k * 0.5698402910) - 1.0) * M_PI / 180.0);
}

Eigen::Matrix3d rotation_rpy(double roll, double pitch, double yaw) {
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

}  // namespace

bool poses_agree(const Pose2& a, const Pose2& b) {
  return (a.translation() - b.translation()).norm() < kAgreeM &&
         std::abs(wrap_angle(a.theta() - b.theta())) < kAgreeRad;
}

StepVote vote_on_steps(const std::vector<Pose2>& steps, const Eigen::Matrix2d& R_map_last) {
  StepVote v;
  if (steps.empty()) return v;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    int support = 0;
    for (const Pose2& other : steps) support += poses_agree(steps[i], other) ? 1 : 0;
    if (support > v.support) {
      v.support = support;
      v.chosen = i;
    }
  }
  const Pose2& step = steps[v.chosen];
  for (const Pose2& other : steps) {
    Eigen::Vector3d d;
    d.head<2>() = R_map_last * (other.translation() - step.translation());
    d.z() = wrap_angle(other.theta() - step.theta());
    v.spread += d * d.transpose();
  }
  v.spread /= static_cast<double>(steps.size());
  return v;
}

Frontend::Frontend(const FrontendConfig& config)
    : config_(config),
      T_base_laser_(config.T_base_laser.x_m, config.T_base_laser.y_m,
                    config.T_base_laser.theta_rad),
      map_(config.map),
      yaw_(rotation_rpy(config.deskew.imu_roll_rad, config.deskew.imu_pitch_rad,
                        config.deskew.imu_yaw_rad)) {
  // Before the first scan the last pose is where the trajectory starts.
  T_map_base_last_ = initial_pose();
  T_published_last_ = T_map_base_last_;
  T_emitted_last_ = T_map_base_last_;
  if (config.matcher.sparse_ensemble_members <= 1) return;
  // The members' grids are offset by fractions of a cell of the wide search's level.
  const double cell_m = config.map.resolution_m * std::pow(2.0, std::min(1, config.map.levels - 1));
  for (int k = 1; k < config.matcher.sparse_ensemble_members; ++k) {
    FrontendConfig member = config;
    member.matcher.sparse_ensemble_members = 1;
    const Pose2 offset = member_offset(k, cell_m);
    member.initial_pose.x_m += offset.x();
    member.initial_pose.y_m += offset.y();
    member.initial_pose.theta_rad += offset.theta();
    members_.push_back(std::make_unique<Frontend>(member));
  }
}

void Frontend::add_imu(int64_t utime, const Eigen::Vector3d& angular_velocity_imu) {
  if (!angular_velocity_imu.allFinite() || !yaw_.add(utime, angular_velocity_imu)) {
    ++counters_.imu_dropped_time;
    return;
  }
  ++counters_.imu_samples;
}

std::optional<int64_t> Frontend::last_imu_utime() const {
  if (yaw_.empty()) return std::nullopt;
  return yaw_.last_utime();
}

bool Frontend::imu_active(const Scan& scan) const {
  // Samples must reach back to the previous pose (or, for the first scan, to its first point)
  // and be recent.
  const int64_t from = initialised_ ? last_utime_ : scan.utime_first;
  return !yaw_.empty() && yaw_.first_utime() <= from &&
         yaw_.last_utime() + kImuStaleUs >= scan.utime_last;
}

void Frontend::valid_points(const Scan& scan, std::vector<Eigen::Vector2d>& points_base,
                            std::vector<int64_t>& utimes) {
  const std::size_t n = scan.ranges.size();
  double lo = config_.matcher.min_range_m, hi = config_.matcher.max_range_m;
  if (std::isfinite(scan.range_min) && scan.range_min > lo) lo = scan.range_min;
  if (std::isfinite(scan.range_max) && scan.range_max > 0.0 && scan.range_max < hi)
    hi = scan.range_max;
  const double duration = static_cast<double>(scan.utime_last - scan.utime_first);
  points_base.clear();
  utimes.clear();
  if (!std::isfinite(scan.angle_first) || !std::isfinite(scan.angle_step)) {
    counters_.readings_invalid += static_cast<int64_t>(n);
    return;
  }
  // Beam directions in the base frame, computed once per scan geometry (it rarely changes).
  if (beam_n_ != n || beam_angle_first_ != scan.angle_first ||
      beam_angle_step_ != scan.angle_step) {
    beam_directions_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      const double a = scan.angle_first + static_cast<double>(i) * scan.angle_step;
      beam_directions_[i] = T_base_laser_.rotation() * Eigen::Vector2d(std::cos(a), std::sin(a));
    }
    beam_n_ = n;
    beam_angle_first_ = scan.angle_first;
    beam_angle_step_ = scan.angle_step;
  }
  points_base.reserve(n);
  utimes.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double r = scan.ranges[i];
    if (!std::isfinite(r) || r <= 0.0 || r < lo || r > hi) {
      ++counters_.readings_invalid;
      continue;
    }
    points_base.push_back(T_base_laser_.translation() + r * beam_directions_[i]);
    const double s = n > 1 ? static_cast<double>(i) / static_cast<double>(n - 1) : 1.0;
    utimes.push_back(scan.utime_first + std::llround(s * duration));
  }
}

Pose2 Frontend::predict(int64_t utime, bool use_imu, bool sparse_scan) const {
  // A scanner's stream: constant velocity over the elapsed time, but over at most twice the last
  // interval (after a pause it would predict an arbitrarily long step). Scans further apart than
  // any scanner's period are a log subsampled by travel (the CARMEN sets): their times say little
  // about the motion; the average of the last steps predicts better (see update_motion()).
  const int64_t elapsed = utime - last_utime_;
  if (sparse_scan && have_sparse_step_ && !use_imu) {
    return T_map_base_last_ * Pose2::exp(sparse_step_);
  }
  const int64_t horizon = std::min(elapsed, 2 * last_interval_us_);
  Eigen::Vector3d xi = velocity_ * (1e-6 * static_cast<double>(horizon));
  if (use_imu) xi.z() = yaw_.heading_change(last_utime_, utime);
  return T_map_base_last_ * Pose2::exp(xi);
}

void Frontend::deskew(std::vector<Eigen::Vector2d>& points_base, const std::vector<int64_t>& utimes,
                      int64_t utime_ref, bool use_imu) const {
  if (!config_.deskew.enabled) return;
  // Heading change from the IMU's yaw rate, or from the constant angular velocity without IMU.
  // The IMU's integral is evaluated at kKnots times across the sweep and interpolated linearly
  // per point (the integral is smooth: a few samples fall within a sweep), instead of a search
  // in the IMU buffer for each of thousands of points.
  constexpr int kKnots = 33;
  const double omega = velocity_.z();
  const int64_t t0 = utimes.empty() ? utime_ref : std::min(utimes.front(), utime_ref);
  const double span = static_cast<double>(std::max<int64_t>(1, utime_ref - t0));
  std::array<double, kKnots> knots{};
  if (use_imu) {
    for (int k = 0; k < kKnots; ++k) {
      knots[k] = yaw_.heading_change(utime_ref, t0 + std::llround(span * k / (kKnots - 1)));
    }
  }
  auto heading_change = [&](int64_t t) {
    if (!use_imu) return omega * 1e-6 * static_cast<double>(t - utime_ref);
    const double x = std::clamp(static_cast<double>(t - t0) / span, 0.0, 1.0) * (kKnots - 1);
    const int k = std::min(kKnots - 2, static_cast<int>(x));
    return knots[k] + (x - k) * (knots[k + 1] - knots[k]);
  };
  deskew_points(points_base, utimes, utime_ref, heading_change, velocity_.head<2>(),
                config_.deskew.translation);
}

std::vector<Eigen::Vector2d> Frontend::subsample(const std::vector<Eigen::Vector2d>& points) const {
  const double spacing = config_.matcher.min_point_spacing_m;
  if (spacing <= 0.0 || points.empty()) return points;
  std::vector<Eigen::Vector2d> kept{points.front()};
  const double spacing2 = spacing * spacing;
  for (const auto& p : points) {
    if ((p - kept.back()).squaredNorm() >= spacing2) kept.push_back(p);
  }
  return kept;
}

void Frontend::update_motion(const Pose2& T_map_base, int64_t utime, bool sparse_scan) {
  if (initialised_) {
    const double dt = 1e-6 * static_cast<double>(utime - last_utime_);
    const Eigen::Vector3d v = between(T_map_base_last_, T_map_base).log() / dt;
    const double alpha = std::min(1.0, dt / kVelocitySmoothingS);
    velocity_ = alpha * v + (1.0 - alpha) * velocity_;
    last_interval_us_ = utime - last_utime_;
    // Sparse scans: the step per scan, averaged over the last few. A log subsampled by travel
    // moves about the same distance per scan, so the average keeps predicting forward motion
    // where one step was underestimated (a corridor that does not show motion along its axis):
    // repeating the last step would repeat the stall.
    if (sparse_scan) {
      const Eigen::Vector3d step = between(T_map_base_last_, T_map_base).log();
      constexpr double a = kSparseStepSmoothing;
      sparse_step_ =
          have_sparse_step_ ? Eigen::Vector3d(a * step + (1.0 - a) * sparse_step_) : step;
      have_sparse_step_ = true;
    }
  }
  if (initialised_) {
    recent_intervals_us_.add(static_cast<double>(utime - last_utime_));
  }
  T_map_base_last_ = T_map_base;
  last_utime_ = utime;
}

bool Frontend::subsampled_by_travel() const {
  return recent_intervals_us_.size() == kRecentIntervals &&
         recent_intervals_us_.percentile(50) >
             static_cast<double>(config_.matcher.wide_search_gap_us);
}

void Frontend::take_prediction(FrontendResult& result, const Pose2& T_pred, bool sparse_scan) {
  result.T_map_base = T_pred;
  result.T_map_base_predicted = T_pred;
  const Eigen::Vector3d prior(std::pow(config_.matcher.prior_sigma_xy_m, 2),
                              std::pow(config_.matcher.prior_sigma_xy_m, 2),
                              std::pow(config_.matcher.prior_sigma_theta_rad, 2));
  result.covariance = covariance_last_ + Eigen::Matrix3d(prior.asDiagonal());
  covariance_last_ = result.covariance;
  const Eigen::Vector3d velocity = velocity_;
  update_motion(result.T_map_base, result.utime, sparse_scan);
  velocity_ = velocity;  // a prediction carries no new information about the motion
}

std::size_t Frontend::map_memory_bytes() const {
  std::size_t bytes = map_.memory_bytes();
  for (const auto& m : members_) bytes += m->map_memory_bytes();
  return bytes;
}

Pose2 Frontend::initial_pose() const {
  return Pose2(config_.initial_pose.x_m, config_.initial_pose.y_m, config_.initial_pose.theta_rad);
}

bool Frontend::map_update_due(const Pose2& T_map_base) const {
  const Pose2 d = between(T_map_base_last_update_, T_map_base);
  return d.translation().norm() >= config_.map.update_distance_m ||
         std::abs(d.theta()) >= config_.map.update_angle_rad;
}

FrontendResult Frontend::run_and_vote(const std::function<FrontendResult(Frontend&)>& own) {
  if (config_.matcher.sparse_ensemble_members <= 1) return own(*this);
  // The pose each frontend last gave: the step of its result is from there.
  std::vector<Pose2> last{T_emitted_last_};
  for (const auto& m : members_) last.push_back(m->T_emitted_last_);
  FrontendResult result = own(*this);
  std::vector<FrontendResult> member_results;
  member_results.reserve(members_.size());
  for (auto& m : members_) member_results.push_back(own(*m));
  if (result.has_pose()) vote(result, member_results, last);
  return result;
}

FrontendResult Frontend::process(const Scan& scan) {
  const FrontendResult result = run_and_vote([&](Frontend& f) { return f.process_own(scan); });
  if (config_.matcher.sparse_ensemble_members <= 1 || !result.has_pose()) return result;
  dense_in_a_row_ = result.sparse ? 0 : dense_in_a_row_ + 1;
  if (dense_in_a_row_ >= kDenseScansEndingEnsemble) members_.clear();
  return result;
}

std::optional<FrontendResult> Frontend::finish() {
  const FrontendResult result = run_and_vote([](Frontend& f) { return f.finish_own(); });
  if (!result.has_pose()) return std::nullopt;
  return result;
}

void Frontend::take_match(FrontendResult& result, const MatchResult& m) {
  result.T_map_base = m.T_map_base;
  result.covariance = m.covariance;
  result.matched_points = m.points;
  result.iterations += m.iterations;
  result.residual_rms = m.residual_rms;
  result.searched = result.searched || m.searched;
}

void Frontend::vote(FrontendResult& result, const std::vector<FrontendResult>& member_results,
                    const std::vector<Pose2>& last) {
  // results[0] is this frontend's own, results[k] member k's; a member without a pose for this
  // scan does not vote. On the first scan every step is zero (each starts where it was put).
  std::vector<const FrontendResult*> results{&result};
  for (const FrontendResult& r : member_results) results.push_back(&r);
  std::vector<Pose2> steps;
  std::vector<std::size_t> voters;
  for (std::size_t k = 0; k < results.size(); ++k) {
    if (!results[k]->has_pose() || results[k]->utime != result.utime) continue;
    steps.push_back(between(last[k], results[k]->T_map_base));
    voters.push_back(k);
  }
  const StepVote v = vote_on_steps(steps, T_published_last_.rotation());
  const FrontendResult& c = *results[voters[v.chosen]];
  const Pose2& step = steps[v.chosen];
  const Pose2 published = T_published_last_ * step;
  // The chosen member's covariance, turned from its map frame into the published one, plus the
  // spread of all members' steps about the chosen step.
  const double turn = wrap_angle(published.theta() - c.T_map_base.theta());
  Eigen::Matrix3d J = Eigen::Matrix3d::Identity();
  J.topLeftCorner<2, 2>() = Eigen::Rotation2Dd(turn).toRotationMatrix();
  const Eigen::Matrix3d covariance = J * c.covariance * J.transpose() + v.spread;
  const Pose2 predicted =
      T_published_last_ * between(last[voters[v.chosen]], c.T_map_base_predicted);

  if (v.support < static_cast<int>(steps.size())) ++counters_.steps_disputed;
  if (!poses_agree(steps[0], step)) ++counters_.steps_outvoted;
  result.T_map_base = published;
  result.T_map_base_predicted = predicted;
  result.covariance = covariance;
  result.ensemble_agreeing = v.support;
  result.ensemble_voting = static_cast<int>(steps.size());
  T_published_last_ = published;
}

FrontendResult Frontend::measure(const Scan& scan, bool& by_travel_out) {
  ++counters_.scans_received;
  FrontendResult result;
  result.utime = scan.utime_last;
  // Times first: a sweep ending before it starts, or not after the last pose, is dropped.
  if (scan.utime_last < scan.utime_first || scan.utime_last - scan.utime_first > kMaxSweepUs ||
      (initialised_ && scan.utime_last <= last_utime_)) {
    ++counters_.scans_dropped_time;
    return result;
  }
  std::vector<Eigen::Vector2d>& points = points_buffer_;
  std::vector<int64_t>& utimes = utimes_buffer_;
  valid_points(scan, points, utimes);
  result.valid_points = static_cast<int>(points.size());
  const bool use_imu = imu_active(scan);
  result.imu_used = use_imu;
  // Sparse: this scan comes long after the last, or the stream's recent scans did (a log
  // subsampled by travel, whose timestamps also hold repeats and near repeats that say nothing
  // about the motion in between: intel has 23 of 910 scans under 0.5 s apart, some 0 s). Decided
  // once per scan, before the motion state changes.
  const bool by_travel = initialised_ && subsampled_by_travel();
  by_travel_out = by_travel;
  const bool sparse_scan =
      initialised_ &&
      (scan.utime_last - last_utime_ > config_.matcher.wide_search_gap_us || by_travel);
  result.sparse = sparse_scan;

  if (static_cast<int>(points.size()) < config_.matcher.min_valid_points) {
    ++counters_.scans_predicted;
    if (initialised_) {
      take_prediction(result, predict(scan.utime_last, use_imu, sparse_scan), sparse_scan);
    } else {  // nothing to predict from yet: where the trajectory starts
      result.T_map_base = initial_pose();
      result.T_map_base_predicted = result.T_map_base;
    }
    result.status = ScanStatus::kPredicted;
    return result;
  }

  result.status = ScanStatus::kMatched;
  if (!initialised_) {
    // The first scan's pose is given (initial_pose, the identity by default): exact by definition.
    deskew(points, utimes, scan.utime_last, use_imu);
    result.T_map_base = initial_pose();
    result.T_map_base_predicted = result.T_map_base;
    result.covariance = Eigen::Matrix3d::Identity() * 1e-12;
    result.matched_points = static_cast<int>(points.size());
  } else {
    const Pose2 T_pred = predict(scan.utime_last, use_imu, sparse_scan);
    result.T_map_base_predicted = T_pred;
    deskew(points, utimes, scan.utime_last, use_imu);
    // Should the prediction fail, the recovery also searches around the last pose (no motion).
    std::vector<Pose2> other_centres;
    if (between(T_pred, T_map_base_last_).translation().norm() > config_.map.resolution_m ||
        std::abs(between(T_pred, T_map_base_last_).theta()) > 0.01) {
      other_centres.push_back(T_map_base_last_);
    }
    // The step prior holds for a log subsampled by travel, not for a pause in a scanner's stream
    // (freiburg-079: 40 gaps over 0.5 s, the robot standing still).
    matched_buffer_ = subsample(points);
    const MatchResult m =
        sparse_scan
            ? match_scan_wide(map_, matched_buffer_, {T_pred}, config_.matcher,
                              by_travel ? &T_map_base_last_ : nullptr)
            : match_scan(map_, matched_buffer_, T_pred, config_.matcher, -1, 0, other_centres);
    // A scanner's stream predicts the pose a period ahead to centimetres. A match that ends far
    // from that with a poor fit (after the recovery search, see search_max_unverified_m) comes
    // from a scan that fits nowhere (people round the scanner, a view the map has not seen):
    // the pose is the prediction, flagged, and the scan stays out of the map. Sparse scans are
    // predicted too poorly for this (their steps of a metre are what the wide search is for).
    if (m.searched) ++counters_.scans_searched;
    if (!sparse_scan && unverified(m, T_pred, config_.matcher)) {
      ++counters_.scans_unverified;
      take_prediction(result, T_pred, sparse_scan);
      result.residual_rms = m.residual_rms;
      result.searched = m.searched;
      result.status = ScanStatus::kPredicted;
      return result;
    }
    take_match(result, m);
  }
  ++counters_.scans_matched;
  covariance_last_ = result.covariance;
  update_motion(result.T_map_base, scan.utime_last, sparse_scan);
  initialised_ = true;
  return result;
}

void Frontend::add_to_map(FrontendResult& result, const std::vector<Eigen::Vector2d>& points) {
  if (counters_.map_updates > 0 && !map_update_due(result.T_map_base)) return;
  map_.update(result.T_map_base, T_base_laser_.translation(), points);
  T_map_base_last_update_ = result.T_map_base;
  counters_.map_tiles_evicted += static_cast<int64_t>(map_.bound_memory(
      result.T_map_base.translation(), static_cast<std::size_t>(config_.map.max_bytes)));
  ++counters_.map_updates;
  result.map_updated = true;
}

}  // namespace traverse::frontend
