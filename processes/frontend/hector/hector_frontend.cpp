#include "hector_frontend.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <vector>

#include "degeneracy.hpp"
#include "deskew.hpp"
#include "grid_search.hpp"
#include "moved_points.hpp"
#include "scan_matcher.hpp"
#include "sweep_input.hpp"

namespace traverse::frontend {
namespace {

// Gives `result` the pose of a match and its figures (iterations add up).
void take_match(FrontendResult& result, const MatchResult& m) {
  result.T_map_base = m.T_map_base;
  result.covariance = m.covariance;
  FrontendDiagnostics& d = *result.diagnostics;
  d.matched_points = m.points;
  d.iterations += m.iterations;
  d.residual_rms = m.residual_rms;
  d.searched = d.searched || m.searched;
}

}  // namespace

HectorFrontend::HectorFrontend(const FrontendConfig& config)
    : config_(config),
      T_initial_(config.initial_pose.pose()),
      scan_points_(config.T_base_laser.pose(), config.matcher.min_range_m,
                   config.matcher.max_range_m),
      motion_(T_initial_, R_base_imu(config.deskew), config.motion_prior),
      map_(config.map),
      open_hold_(config.matcher) {}

bool HectorFrontend::add_imu(int64_t utime, const Eigen::Vector3d& angular_velocity_imu) {
  return counted(motion_.add_imu(utime, angular_velocity_imu), counters_.imu_samples,
                 counters_.imu_dropped);
}

bool HectorFrontend::add_odometry(const OdometrySample& odometry) {
  return counted(motion_.add_odometry(odometry), counters_.odometry_samples,
                 counters_.odometry_dropped);
}

Measurement HectorFrontend::measure(const Scan& scan) {
  ++counters_.scans_received;
  Measurement m;
  FrontendResult& r = m.result;
  r.utime = scan.utime_last;
  FrontendDiagnostics& d = r.diagnostics.emplace();
  const bool initialised = motion_.initialised();
  // Times first: a sweep ending before it starts, or not after the last pose, is dropped.
  const int64_t last_utime = motion_.last_utime();
  if (sweep_times_wrong(scan, initialised ? &last_utime : nullptr)) {
    ++counters_.scans_dropped_time;
    return m;
  }
  ScanPoints points = scan_points_(scan);
  counters_.readings_invalid += points.invalid;
  d.valid_points = static_cast<int>(points.points_base.size());
  // The IMU must reach back to the last pose (or, for the first scan, to its first point).
  const bool use_imu =
      motion_.imu_covers(initialised ? motion_.last_utime() : scan.utime_first, scan.utime_last);
  d.imu_used = use_imu;
  // Sparse: this scan comes long after the last, or the stream's recent scans did (a log
  // subsampled by travel, whose timestamps also hold repeats and near repeats that say nothing
  // about the motion in between: intel has 23 of 910 scans under 0.5 s apart, some 0 s).
  m.subsampled_by_travel =
      initialised && motion_.subsampled_by_travel(config_.matcher.wide_search_gap_us);
  r.sparse =
      initialised && (scan.utime_last - motion_.last_utime() > config_.matcher.wide_search_gap_us ||
                      m.subsampled_by_travel);

  if (d.valid_points < config_.matcher.min_valid_points) {
    ++counters_.scans_predicted;
    if (initialised) {
      take_prediction(m, motion_.extrapolate(scan.utime_last, use_imu, r.sparse));
    } else {  // nothing to predict from yet: where the trajectory starts
      r.T_map_base = T_initial_;
      d.T_map_base_predicted = T_initial_;
      r.status = ScanStatus::kPredicted;
    }
    return m;
  }

  const auto deskew = [&] {
    if (config_.deskew.enabled) {
      deskew_sweep(points.points_base, points.utimes, scan.utime_last, motion_, use_imu,
                   config_.deskew.translation);
    }
  };
  r.status = ScanStatus::kMatched;
  if (!initialised) {
    // The first scan's pose is given (initial_pose, the identity by default): exact by definition.
    deskew();
    r.T_map_base = T_initial_;
    d.T_map_base_predicted = T_initial_;
    r.covariance = Eigen::Matrix3d::Identity() * 1e-12;
    d.matched_points = d.valid_points;
  } else {
    // A log subsampled by travel takes odometry only if configured (motion_prior.subsampled_logs).
    const MotionModel::Prediction with =
        motion_.predict(scan.utime_last, use_imu, r.sparse,
                        !m.subsampled_by_travel || config_.motion_prior.subsampled_logs);
    deskew();
    if (!r.sparse) drop_moved(points.points_base, with.T_map_base);
    m.points_matched = subsample(points.points_base, config_.matcher.min_point_spacing_m);
    // The coarse-cell check (MatcherConfig::coarse_check_m) on a driver's fast stream only: the
    // scan carries its sweep's duration (a log's one stamp per scan may be the logger's arrival
    // time: intel, a quarter of its intervals under 1.2 ms, its median 97 ms), and it came, as
    // the stream's recent scans did, at most coarse_check_max_gap_us after the one before.
    const int64_t fast = config_.matcher.coarse_check_max_gap_us;
    const bool coarse_check = scan.utime_last > scan.utime_first && motion_.pace_known() &&
                              !motion_.subsampled_by_travel(fast) &&
                              scan.utime_last - motion_.last_utime() <= fast;
    Attempt attempt = match_from(m, with, coarse_check);
    // Odometry's step is checked against the scan (a scanner's stream): matched also from the
    // prediction without it, the result that fits clearly better stands (a wheel slipped, the
    // odometry's stamps are off), if the scan tells the two apart (not along a corridor's axis,
    // where the map made at the last pose favours standing still).
    if (with.odometry && !r.sparse && config_.motion_prior.odometry_check_margin > 0.0) {
      const MotionModel::Prediction without =
          motion_.predict(scan.utime_last, use_imu, r.sparse, false);
      if (differ(with.T_map_base, without.T_map_base)) {
        Attempt other = match_from(m, without, coarse_check);
        if (better(other, attempt, config_.motion_prior.odometry_check_margin) &&
            apart(other, attempt, determined(attempt.match, m.points_matched),
                  config_.motion_prior.odometry_check_sigmas)) {
          ++counters_.odometry_overruled;
          attempt = std::move(other);
        }
      }
    }
    count_odometry(attempt.prediction);
    if (attempt.prediction.odometry) m.odometry_step = attempt.prediction.odometry->T_base0_base1;
    const Pose2& T_pred = attempt.prediction.T_map_base;
    d.T_map_base_predicted = T_pred;
    const MatchResult& match = attempt.match;
    if (match.searched) ++counters_.scans_searched;
    // A match far behind both the prediction and the last pose, on the path before it, is a
    // scan taken back there and stamped late (a logger that stamps on arrival: intel holds about a
    // hundred): its pose is where it fits, and the motion goes on from the prediction at its
    // stamp (integrate()). Taking it as the pose at its stamp turns the trajectory back and the
    // next prediction with it (intel from a start 1 mrad off: the frontend lost, relations 6.85 m).
    if (!attempt.unverified && attempt.prediction.odometry && !r.sparse &&
        motion_.taken_earlier(match.T_map_base, T_pred, config_.motion_prior.search_min_linear_m,
                              config_.motion_prior.search_min_angular_rad)) {
      ++counters_.scans_late;
      r.late = true;
    }
    // A scanner's stream predicts the pose a period ahead to centimetres. A match that ends far
    // from that with a poor fit (after the recovery search, see search_max_unverified_m) comes
    // from a scan that fits nowhere (people round the scanner, a view the map has not seen).
    // Sparse scans are predicted too poorly for this (their steps of a metre are what the wide
    // search is for).
    if (attempt.unverified) {
      ++counters_.scans_unverified;
      take_prediction(m, T_pred);
      d.residual_rms = match.residual_rms;
      d.searched = match.searched;
      return m;
    }
    take_match(r, match);
    // Directions the scan does not determine keep the prediction (degeneracy.hpp). Sparse scans
    // are predicted too poorly for it: their wide search's spread already says what is open.
    if (!r.sparse) hold_degenerate(r, match, m.points_matched, attempt.prediction);
  }
  ++counters_.scans_matched;
  m.points = std::move(points.points_base);
  return m;
}

HectorFrontend::Attempt HectorFrontend::match_from(const Measurement& m,
                                                   const MotionModel::Prediction& p,
                                                   bool coarse_check) const {
  const Pose2& T_pred = p.T_map_base;
  const Pose2& T_last = motion_.last_pose();
  const bool sparse = m.result.sparse;
  // Should the prediction fail, the recovery also searches around the last pose (no motion),
  // unless odometry gave the step.
  std::vector<Pose2> other_centres;
  if (!p.odometry && differ(T_pred, T_last)) {
    other_centres.push_back(T_last);
  }
  MatcherConfig matcher = matcher_for(p);
  // A coarse cell's flip shows as a result far from the prediction only where the prediction is
  // good to well under that distance.
  if (!coarse_check) matcher.coarse_check_m = 0.0;
  // The sub-cell map is read on a scanner's stream, a pause in it included (a scan matched on the
  // plain map there is placed with the grid's pull and lays the map down so: intel, relations,
  // frontend alone 0.016 m -> 0.31 m); a log subsampled by travel (or whose first scans come so
  // far apart that it may be one) is matched on the plain map throughout (MatcherConfig).
  matcher.read_at_hits = !(m.subsampled_by_travel || (sparse && !motion_.pace_known()));
  Attempt a;
  a.prediction = p;
  // The step prior holds for a log subsampled by travel, not for a pause in a scanner's stream
  // (freiburg-079: 40 gaps over 0.5 s, the robot standing still).
  a.match = sparse ? match_scan_wide(map_, m.points_matched, {T_pred}, matcher,
                                     m.subsampled_by_travel ? &T_last : nullptr)
                   : match_scan(map_, m.points_matched, T_pred, matcher, -1, 0, other_centres);
  a.unverified = !sparse && unverified(a.match, T_pred, config_.matcher);
  return a;
}

void HectorFrontend::drop_moved(std::vector<Eigen::Vector2d>& points_base,
                                const Pose2& T_map_base_predicted) {
  const double p_max = config_.matcher.moved_max_probability;
  if (p_max <= 0.0) return;
  const std::vector<bool> moved = seen_through(map_.level(std::min(1, map_.levels() - 1)),
                                               points_base, T_map_base_predicted, p_max);
  const auto n = static_cast<std::size_t>(std::count(moved.begin(), moved.end(), true));
  // Most of a scan in free space says the prediction is off, not that the world moved.
  if (n == 0 || 2 * n > points_base.size()) return;
  std::size_t kept = 0;
  for (std::size_t i = 0; i < points_base.size(); ++i) {
    if (!moved[i]) points_base[kept++] = points_base[i];
  }
  points_base.resize(kept);
  counters_.points_moved += static_cast<int64_t>(n);
}

Degeneracy HectorFrontend::degeneracy(const Eigen::Matrix3d& information,
                                      const std::vector<Eigen::Vector2d>& points_matched) const {
  return analyse_degeneracy(information, points_rms_range_m(points_matched),
                            std::max(config_.matcher.degeneracy_min_ratio, 1e-12));
}

Eigen::Matrix3d HectorFrontend::determined(
    const MatchResult& match, const std::vector<Eigen::Vector2d>& points_matched) const {
  if (config_.matcher.degeneracy_min_ratio <= 0.0) return Eigen::Matrix3d::Identity();
  const Degeneracy dg = degeneracy(match.information, points_matched);
  // A match that determines no direction at all has no surface under its points: the prediction
  // put the scan where the map knows nothing (intel: odometry jumps 5.5 m in one step), which says
  // the pose is wrong, not that the scan cannot tell.
  if (dg.directions == 3) return Eigen::Matrix3d::Identity();
  return dg.projector;
}

void HectorFrontend::hold_degenerate(FrontendResult& r, const MatchResult& match,
                                     const std::vector<Eigen::Vector2d>& points_matched,
                                     const MotionModel::Prediction& prediction) {
  const Degeneracy dg = degeneracy(match.information, points_matched);
  r.diagnostics->degeneracy_ratio = dg.ratio;
  open_hold_.note(r.utime, dg.directions == 0);
  if (config_.matcher.degeneracy_min_ratio <= 0.0 || dg.directions == 0) return;
  ++counters_.scans_degenerate;
  r.diagnostics->degenerate_directions = dg.directions;
  // Odometry measures the motion along such a direction. Without it the velocity of the last
  // poses carries on the speed the corridor was entered with, and the match's faint grip (an end
  // wall 40 m ahead, a door recess) does better than that in a long bare corridor; held there
  // only on request, and where the scans measured that velocity (open_direction_hold.hpp). Either
  // way the covariance says how little the scan fixed there.
  if (prediction.odometry || open_hold_.holds(r.utime))
    r.T_map_base = remap(dg, prediction.T_map_base, r.T_map_base);
  r.covariance = remapped_covariance(dg, prediction.covariance);
}

bool HectorFrontend::differ(const Pose2& a, const Pose2& b) const {
  const Pose2 d = between(a, b);
  return d.translation().norm() > config_.map.resolution_m || std::abs(d.theta()) > 0.01;
}

bool HectorFrontend::better(const Attempt& a, const Attempt& b, double margin) {
  if (a.unverified != b.unverified) return !a.unverified;
  return a.match.residual_rms + margin < b.match.residual_rms;
}

bool HectorFrontend::apart(const Attempt& a, const Attempt& b, const Eigen::Matrix3d& determined,
                           double sigmas) {
  // In the map frame, as the covariance is; only the part the scan determines counts: along a
  // direction it leaves open (a corridor's axis) the two matches differ by where each started
  // and by the map's history there, which the residuals favour (the map was made at the last
  // pose), and the scan would overrule odometry with that, scan after scan, into a slide.
  Eigen::Vector3d d = a.match.T_map_base.vector() - b.match.T_map_base.vector();
  d.z() = wrap_angle(d.z());
  d = determined * d;
  const Eigen::Matrix3d& C = b.match.covariance;
  if (C.determinant() <= 0.0) return true;
  return d.dot(C.ldlt().solve(d)) > sigmas * sigmas;
}

void HectorFrontend::count_odometry(const MotionModel::Prediction& p) {
  if (p.odometry) {
    ++counters_.odometry_predictions;
    if (p.odometry->extrapolated) ++counters_.odometry_extrapolated;
    return;
  }
  // A stream that never carried odometry is not short of it.
  if (counters_.odometry_samples == 0) return;
  switch (p.odometry_miss) {
    case OdometryMiss::kMissing:
      ++counters_.odometry_missing;
      break;
    case OdometryMiss::kGap:
      ++counters_.odometry_gap;
      break;
    case OdometryMiss::kStale:
      ++counters_.odometry_stale;
      break;
    case OdometryMiss::kNone:
      break;  // the source leaves odometry out
  }
}

MatcherConfig HectorFrontend::matcher_for(const MotionModel::Prediction& p) const {
  MatcherConfig c = config_.matcher;
  // Matching across surfaces only where odometry predicts the scan: it leaves a corridor's axis
  // to what holds it, the odometry prediction (degeneracy.hpp). Without odometry nothing does:
  // corridor-return realistic seed 1 with the IMU alone, moved points + normal projection +
  // degeneracy 7.8 m RMSE against 0.44 m for moved points alone; CARMEN intel (subsampled, no
  // odometry), the three units: RPE over 10 m 0.133 m with projection on every scan, 0.111 m
  // with it only here, 0.099 m with none of them.
  c.normal_projection = c.normal_projection && p.odometry.has_value();
  if (!p.odometry) return c;
  const MotionPrior& prior = motion_.prior();
  const Eigen::Matrix3d& cov = p.odometry->covariance;
  c.wide_search_linear_window_m = prior.linear_window_m(cov, c.wide_search_linear_window_m);
  c.wide_search_angular_window_rad =
      prior.angular_window_rad(cov, c.wide_search_angular_window_rad);
  c.search_linear_window_m = prior.linear_window_m(cov, c.search_linear_window_m);
  c.search_angular_window_rad = prior.angular_window_rad(cov, c.search_angular_window_rad);
  return c;
}

void HectorFrontend::take_prediction(Measurement& m, const Pose2& T_predicted) const {
  FrontendResult& r = m.result;
  r.status = ScanStatus::kPredicted;
  r.T_map_base = T_predicted;
  r.diagnostics->T_map_base_predicted = T_predicted;
  const double sxy = config_.matcher.prior_sigma_xy_m;
  const double sth = config_.matcher.prior_sigma_theta_rad;
  const Eigen::Vector3d prior(std::pow(sxy, 2), std::pow(sxy, 2), std::pow(sth, 2));
  r.covariance = motion_.last_covariance() + Eigen::Matrix3d(prior.asDiagonal());
}

void HectorFrontend::integrate(Measurement& m) {
  FrontendResult& r = m.result;
  if (r.status == ScanStatus::kPredicted) {
    // A blind first scan leaves the motion model where the trajectory starts.
    if (motion_.initialised())
      motion_.add_prediction(r.utime, r.T_map_base, r.covariance, r.sparse);
    return;
  }
  if (r.status != ScanStatus::kMatched) return;
  if (r.late) {
    motion_.add_prediction(r.utime, r.diagnostics->T_map_base_predicted, r.covariance, r.sparse,
                           true);
    return;
  }
  motion_.add_pose(r.utime, r.T_map_base, r.covariance, r.sparse);
  r.diagnostics->map_updated = false;
  if (T_map_base_last_update_ && !map_update_due(r.T_map_base)) return;
  map_.update(r.T_map_base, config_.T_base_laser.pose().translation(), m.points);
  T_map_base_last_update_ = r.T_map_base;
  counters_.map_tiles_evicted += static_cast<int64_t>(map_.bound_memory(
      r.T_map_base.translation(), static_cast<std::size_t>(config_.map.max_bytes)));
  ++counters_.map_updates;
  r.diagnostics->map_updated = true;
}

bool HectorFrontend::map_update_due(const Pose2& T_map_base) const {
  const Pose2 d = between(*T_map_base_last_update_, T_map_base);
  return d.translation().norm() >= config_.map.update_distance_m ||
         std::abs(d.theta()) >= config_.map.update_angle_rad;
}

Measurement HectorFrontend::rematch(const Measurement& measurement, const SearchArea& area) const {
  MatcherConfig config = config_.matcher;
  config.normal_projection = false;  // a sparse log's search, no odometry (matcher_for)
  config.read_at_hits = false;       // nor the hits' offsets (match_from)
  config.wide_search_linear_window_m = area.linear_window_m;
  config.wide_search_angular_window_rad = area.angular_window_rad;
  Measurement m = measurement;
  take_match(m.result,
             match_scan_wide(map_, m.points_matched, {area.T_centre}, config, &area.T_from));
  return m;
}

double HectorFrontend::evidence(const Measurement& m, const Pose2& T_map_base) const {
  // The wide search's level, scored as the wide search scores a pose.
  return pose_evidence(map_.level(std::min(1, map_.levels() - 1)), m.points_matched, T_map_base);
}

void HectorFrontend::begin_tentative() {
  map_.begin_journal();
  before_tentative_ = Integrated{motion_.state(), T_map_base_last_update_, counters_.map_updates};
}

void HectorFrontend::rollback() {
  map_.rollback();
  motion_.restore(before_tentative_->motion);
  T_map_base_last_update_ = before_tentative_->T_map_base_last_update;
  counters_.map_updates = before_tentative_->map_updates;
  before_tentative_.reset();
}

void HectorFrontend::commit() {
  map_.end_journal();
  before_tentative_.reset();
}

void HectorFrontend::report(const CounterSink& sink) const {
  const Counters& c = counters_;
  sink("scans_received", static_cast<double>(c.scans_received));
  sink("scans_matched", static_cast<double>(c.scans_matched));
  sink("scans_predicted", static_cast<double>(c.scans_predicted));
  sink("scans_unverified", static_cast<double>(c.scans_unverified));
  sink("scans_late", static_cast<double>(c.scans_late));
  sink("scans_searched", static_cast<double>(c.scans_searched));
  sink("scans_degenerate", static_cast<double>(c.scans_degenerate));
  sink("scans_dropped_time", static_cast<double>(c.scans_dropped_time));
  sink("readings_invalid", static_cast<double>(c.readings_invalid));
  sink("points_moved", static_cast<double>(c.points_moved));
  sink("map_updates", static_cast<double>(c.map_updates));
  sink("map_tiles_evicted", static_cast<double>(c.map_tiles_evicted));
  sink("imu_samples", static_cast<double>(c.imu_samples));
  sink("imu_dropped", static_cast<double>(c.imu_dropped));
  sink("odometry_samples", static_cast<double>(c.odometry_samples));
  sink("odometry_dropped", static_cast<double>(c.odometry_dropped));
  sink("odometry_predictions", static_cast<double>(c.odometry_predictions));
  sink("odometry_extrapolated", static_cast<double>(c.odometry_extrapolated));
  sink("odometry_overruled", static_cast<double>(c.odometry_overruled));
  sink("odometry_missing", static_cast<double>(c.odometry_missing));
  sink("odometry_gap", static_cast<double>(c.odometry_gap));
  sink("odometry_stale", static_cast<double>(c.odometry_stale));
}

}  // namespace traverse::frontend
