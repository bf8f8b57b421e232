// The frontend on the real CARMEN logs (SICK, 180 beams, no IMU, about one scan per 0.5 m of
// travel), compared with each log's corrected reference trajectory: relative pose error over 1 m
// and 10 m of travel, and the largest jump (step of the estimate beyond the reference's step).
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

#include "carmen_log.hpp"
#include "frontend.hpp"

namespace traverse::frontend {
namespace {

struct Metrics {
  int scans = 0;
  int predicted = 0;
  double rpe_1m_m = 0.0, rpe_10m_m = 0.0, max_jump_m = 0.0;
};

// RMS translational error of the relative motion over `distance_m` of reference travel.
double relative_pose_error(const std::vector<Pose2>& ref, const std::vector<Pose2>& est,
                           double distance_m) {
  std::vector<double> travelled{0.0};
  for (std::size_t i = 1; i < ref.size(); ++i) {
    travelled.push_back(travelled.back() + (ref[i].translation() - ref[i - 1].translation()).norm());
  }
  double sum = 0.0;
  int n = 0;
  std::size_t j = 0;
  for (std::size_t i = 0; i < ref.size(); ++i) {
    j = std::max(j, i);
    while (j < ref.size() && travelled[j] - travelled[i] < distance_m) ++j;
    if (j == ref.size()) break;
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
  Frontend frontend(config);
  std::vector<Pose2> ref, est;
  Metrics m;
  while (auto s = reader.next()) {
    Scan scan;
    scan.utime_first = scan.utime_last = s->utime;
    scan.angle_first = s->beams.angle_first;
    scan.angle_step = s->beams.angle_step;
    scan.range_min = 0.0;
    scan.range_max = s->range_max_m.value_or(40.0);
    scan.ranges = s->ranges;
    const FrontendResult r = frontend.process(scan);
    if (r.status == ScanStatus::kDropped) continue;
    if (r.status == ScanStatus::kPredicted) ++m.predicted;
    ref.emplace_back(s->x_m, s->y_m, s->theta_rad);
    est.push_back(r.T_map_base);
  }
  m.scans = static_cast<int>(est.size());
  for (std::size_t i = 1; i < est.size(); ++i) {
    const Eigen::Vector2d e = between(ref[i - 1], ref[i]).translation() -
                              between(est[i - 1], est[i]).translation();
    m.max_jump_m = std::max(m.max_jump_m, e.norm());
  }
  m.rpe_1m_m = relative_pose_error(ref, est, 1.0);
  m.rpe_10m_m = relative_pose_error(ref, est, 10.0);
  return m;
}

class CarmenLog : public ::testing::TestWithParam<const char*> {};

TEST_P(CarmenLog, NeverLosesTrackAgainstReference) {
  const std::string path = std::string("../shared/data/carmen/") + GetParam() + "-corrected.log.gz";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "no data at " << path;
  const Metrics m = run_log(path);
  std::printf("%s: %d scans, %d predicted, rpe_1m %.4f m, rpe_10m %.4f m, max_jump %.4f m\n",
              GetParam(), m.scans, m.predicted, m.rpe_1m_m, m.rpe_10m_m, m.max_jump_m);
  RecordProperty("rpe_1m_m", std::to_string(m.rpe_1m_m));
  RecordProperty("rpe_10m_m", std::to_string(m.rpe_10m_m));
  RecordProperty("max_jump_m", std::to_string(m.max_jump_m));
  EXPECT_GT(m.scans, 400);
  EXPECT_EQ(m.predicted, 0);
  EXPECT_LT(m.max_jump_m, 0.5);
  EXPECT_LT(m.rpe_1m_m, 0.1);
  EXPECT_LT(m.rpe_10m_m, 0.5);
}

INSTANTIATE_TEST_SUITE_P(Logs, CarmenLog, ::testing::Values("intel", "aces", "csail", "freiburg-079"),
                         [](const auto& info) {
                           std::string name = info.param;
                           for (auto& c : name) if (c == '-') c = '_';
                           return name;
                         });

}  // namespace
}  // namespace traverse::frontend
