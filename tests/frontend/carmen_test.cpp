// The frontend on the four real CARMEN logs (SICK, 180 beams, no odometry, no IMU), configured by
// configs/frontend.yaml, compared with each log's corrected reference trajectory: relative pose
// error over 1 m and 10 m of travel, and the largest jump (step of the estimate beyond the
// reference's step), the same figures traverse-evaluator reports (rpe_1m_m, rpe_10m_m, max_jump_m).
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "carmen_log.hpp"
#include "carmen_node.hpp"
#include "config.hpp"
#include "frontend.hpp"
#include "scan_message.hpp"

namespace traverse::frontend {
namespace {

struct Metrics {
  int scans = 0;
  int predicted = 0;
  int searched = 0;
  double rpe_1m_m = 0.0, rpe_10m_m = 0.0, max_jump_m = 0.0;
  // Each step's translation error against the reported covariances: the squared Mahalanobis
  // distance (NEES, chi-square with 2 degrees of freedom if the covariances are right: median
  // 1.39, 1 % above 9.21). Its median, and the fraction of steps above 9.21.
  double nees_median = 0.0, outside_99_fraction = 0.0;
  int steps_off = 0, steps_off_inside_99 = 0;  // steps more than 0.3 m off; those inside 9.21
};

// Covariance of the step from pose a to pose b, in a's frame (x, y): both poses' position
// covariances (map frame, as the frontend reports them) rotated into a's frame, and a's heading
// variance swinging the step. Cross terms are left out (the frontend reports none between poses).
Eigen::Matrix2d step_covariance(const Pose2& a, const Eigen::Matrix3d& cov_a, const Pose2& b,
                                const Eigen::Matrix3d& cov_b) {
  const Eigen::Matrix2d R = a.rotation();
  const Eigen::Vector2d step = between(a, b).translation();
  const Eigen::Vector2d swing(step.y(), -step.x());  // d(step)/d(theta_a)
  return R.transpose() * (cov_a.topLeftCorner<2, 2>() + cov_b.topLeftCorner<2, 2>()) * R +
         cov_a(2, 2) * swing * swing.transpose();
}

// RMS translational error of the relative motion over `distance_m` of reference travel.
double relative_pose_error(const std::vector<Pose2>& ref, const std::vector<Pose2>& est,
                           double distance_m) {
  std::vector<double> travelled{0.0};
  for (std::size_t i = 1; i < ref.size(); ++i) {
    travelled.push_back(travelled.back() +
                        (ref[i].translation() - ref[i - 1].translation()).norm());
  }
  double sum = 0.0;
  int n = 0;
  std::size_t j = 0;
  for (std::size_t i = 0; i < ref.size(); ++i) {
    j = std::max(j, i + 1);
    while (j < ref.size() && travelled[j] - travelled[i] < distance_m) ++j;
    if (j >= ref.size()) break;
    const Eigen::Vector2d e =
        between(ref[i], ref[j]).translation() - between(est[i], est[j]).translation();
    sum += e.squaredNorm();
    ++n;
  }
  return n > 0 ? std::sqrt(sum / n) : 0.0;
}

Metrics run_log(const std::string& path) {
  carmen::Reader reader(path);
  EXPECT_TRUE(reader.good()) << path;
  FrontendConfig config;
  load_config("configs/frontend.yaml", config);
  Frontend frontend(config);
  std::vector<Pose2> ref, est;
  std::vector<Eigen::Matrix3d> cov;
  Metrics m;
  // The scans as traverse-carmen publishes them (configs/carmen.yaml defaults) and
  // traverse-frontend reads them: the same figures as scripts/eval-carmen.sh --stages frontend.
  const carmen::CarmenConfig carmen_config;
  while (auto s = reader.next()) {
    const Scan scan = to_planar_scan(carmen::to_scan_message(*s, carmen_config));
    const FrontendResult r = frontend.process(scan);
    if (r.status == ScanStatus::kDropped) continue;
    if (r.status == ScanStatus::kPredicted) ++m.predicted;
    if (r.searched) ++m.searched;
    ref.emplace_back(s->x_m, s->y_m, s->theta_rad);
    est.push_back(r.T_map_base);
    cov.push_back(r.covariance);
    // CARMEN_TRACE=1: every step, reference against estimate, to find where tracking fails.
    if (std::getenv("CARMEN_TRACE") && ref.size() > 1) {
      const std::size_t i = ref.size() - 1;
      const Pose2 dr = between(ref[i - 1], ref[i]), de = between(est[i - 1], est[i]);
      std::printf("TRACE %zu ref %.3f %.3f %.1f est %.3f %.3f %.1f err %.3f res %.3f\n", i, dr.x(),
                  dr.y(), dr.theta() * 57.3, de.x(), de.y(), de.theta() * 57.3,
                  (dr.translation() - de.translation()).norm(), r.residual_rms);
    }
  }
  m.scans = static_cast<int>(est.size());
  std::vector<double> nees;
  for (std::size_t i = 1; i < est.size(); ++i) {
    const Eigen::Vector2d e =
        between(ref[i - 1], ref[i]).translation() - between(est[i - 1], est[i]).translation();
    m.max_jump_m = std::max(m.max_jump_m, e.norm());
    nees.push_back(e.dot(step_covariance(est[i - 1], cov[i - 1], est[i], cov[i]).inverse() * e));
    if (e.norm() > 0.3) {
      ++m.steps_off;
      if (nees.back() <= 9.21) ++m.steps_off_inside_99;
    }
  }
  if (!nees.empty()) {
    m.outside_99_fraction = static_cast<double>(std::count_if(nees.begin(), nees.end(),
                                                              [](double d) { return d > 9.21; })) /
                            static_cast<double>(nees.size());
    std::nth_element(nees.begin(), nees.begin() + nees.size() / 2, nees.end());
    m.nees_median = nees[nees.size() / 2];
  }
  m.rpe_1m_m = relative_pose_error(ref, est, 1.0);
  m.rpe_10m_m = relative_pose_error(ref, est, 10.0);
  return m;
}

struct LogCase {
  const char* name;
  friend void PrintTo(const LogCase& c, std::ostream* os) { *os << c.name; }
  int min_scans;
  double max_rpe_1m_m, max_rpe_10m_m, max_jump_m;
  // Sparse logs only (their poses come from the wide search, whose covariance includes the score
  // surface's spread): at most this fraction of steps outside the 99 % ellipse, and a median NEES
  // between 0.1 (not inflated past 3.7 times a consistent sigma) and 1.39 (not optimistic in the
  // bulk). Negative: not checked.
  double max_outside_99_fraction = -1.0;
};

class CarmenLog : public ::testing::TestWithParam<LogCase> {};

TEST_P(CarmenLog, TracksReference) {
  const LogCase& c = GetParam();
  const std::string path = std::string("../shared/data/carmen/") + c.name + "-corrected.log.gz";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "no data at " << path;
  const Metrics m = run_log(path);
  std::printf(
      "%s: %d scans, %d predicted, %d searched, rpe_1m %.4f m, rpe_10m %.4f m, max_jump %.4f m, "
      "step NEES median %.2f, outside the 99 %% ellipse %.1f %%, steps over 0.3 m off %d (%d "
      "inside "
      "it)\n",
      c.name, m.scans, m.predicted, m.searched, m.rpe_1m_m, m.rpe_10m_m, m.max_jump_m,
      m.nees_median, 100.0 * m.outside_99_fraction, m.steps_off, m.steps_off_inside_99);
  EXPECT_GT(m.scans, c.min_scans);
  EXPECT_EQ(m.predicted, 0);
  EXPECT_LT(m.rpe_1m_m, c.max_rpe_1m_m);
  EXPECT_LT(m.rpe_10m_m, c.max_rpe_10m_m);
  EXPECT_LT(m.max_jump_m, c.max_jump_m);
  if (c.max_outside_99_fraction >= 0.0) {
    EXPECT_LT(m.outside_99_fraction, c.max_outside_99_fraction);
    EXPECT_GT(m.nees_median, 0.1);
    EXPECT_LT(m.nees_median, 1.39);
  }
}

// Bounds a little above what the frontend reaches (measured, configs/frontend.yaml; rpe_1m /
// rpe_10m / max_jump): freiburg-079 0.046 / 0.098 / 0.18 m, intel 0.098 / 0.138 / 0.84 m, aces
// 0.073 / 0.190 / 0.54 m, csail 0.056 / 0.144 / 0.41 m. Issue 4 asks for max_jump under 0.5 m
// on all four: not reached yet on intel and aces (an along-corridor step misjudged where the
// scan cannot tell and the prediction is poor; one scan of intel matched 20 degrees off in a
// view the map has not seen); these bounds guard what is reached. Before the gate on far
// searched poses (search_max_unverified_m), freiburg-079 jumped 0.75 m at a scan crowded by
// something near the scanner. Before the wide search for sparse scans, intel, aces and csail
// lost track (rpe_10m 2.97 / 4.31 / 4.18 m).
// Steps outside the 99 % ellipse of their covariance: intel 4.8 %, aces 0.9 %, csail 10.4 %
// (median NEES 0.43 / 0.30 / 0.84); with the Gauss-Newton covariance alone
// (matcher.wide_search_temperature 0): 69 / 60 / 61 %, median 18.5 / 13.9 / 14.2. freiburg-079 is
// a scanner's stream (Gauss-Newton covariance): 73.5 % outside, median 23.8, not checked.
INSTANTIATE_TEST_SUITE_P(Logs, CarmenLog,
                         ::testing::Values(LogCase{"freiburg-079", 4700, 0.06, 0.15, 0.5},
                                           LogCase{"intel", 900, 0.15, 0.2, 1.0, 0.1},
                                           LogCase{"aces", 430, 0.1, 0.3, 0.75, 0.05},
                                           LogCase{"csail", 400, 0.1, 0.25, 0.5, 0.2}),
                         [](const auto& info) {
                           std::string n = info.param.name;
                           for (char& ch : n)
                             if (ch == '-') ch = '_';
                           return n;
                         });

}  // namespace
}  // namespace traverse::frontend
