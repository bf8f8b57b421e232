#include <gtest/gtest.h>

#include <Eigen/LU>
#include <algorithm>
#include <map>

#include "backend.hpp"
#include "synthetic.hpp"

namespace traverse::backend {
namespace {

double rms(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x * x;
  return std::sqrt(s / static_cast<double>(v.size()));
}

// Runs a drifting frontend through the backend; returns the RMS position error of the key poses
// of the input and of the backend [m].
std::pair<double, double> run_drive(const test::Drive& d, const BackendConfig& config) {
  EXPECT_EQ(validate(config), std::nullopt);
  Backend backend(config);
  int updates = 0;
  for (std::size_t k = 0; k < d.utimes.size(); ++k) {
    backend.add_scan(d.scans[k]);
    if (backend.add_pose(d.utimes[k], d.input[k])) ++updates;
  }
  if (backend.finish()) ++updates;

  std::map<int64_t, std::size_t> index_of;
  for (std::size_t k = 0; k < d.utimes.size(); ++k) index_of[d.utimes[k]] = k;
  const auto& keys = backend.key_poses();
  EXPECT_GT(keys.size(), 60u);  // a key pose every fourth 10 Hz pose (>= 333 ms)
  EXPECT_GE(updates, static_cast<int>(keys.size()));  // one per key pose (+1 at the end)
  std::vector<double> err_in, err_out;
  for (std::size_t i = 0; i < keys.size(); ++i) {
    const std::size_t k = index_of.at(keys[i].utime);
    err_in.push_back((d.input[k].translation() - d.truth[k].translation()).norm());
    err_out.push_back((backend.graph().poses[i].translation() - d.truth[k].translation()).norm());
  }

  // Loops were closed on the second lap, none of them false: each agrees with the truth within
  // five standard deviations of its own covariance.
  EXPECT_GE(backend.closures().size(), 2u);
  for (const LoopClosure& c : backend.closures()) {
    const Pose2 T_true =
        between(d.truth[index_of.at(keys[c.from].utime)], d.truth[index_of.at(keys[c.to].utime)]);
    const Eigen::Vector3d e = edge_error(Pose2(), T_true, c.T_from_to);
    EXPECT_LT(std::sqrt(e.dot(c.covariance.inverse() * e)), 5.0) << c.from << " -> " << c.to;
  }
  // Marginals: the first key pose fixes the frame, the others are positive and grow away from it
  // until a loop closure ties them back.
  EXPECT_EQ(keys.front().covariance.norm(), 0.0);
  for (std::size_t i = 1; i < keys.size(); ++i) EXPECT_GT(keys[i].covariance(0, 0), 0.0);
  EXPECT_EQ(backend.counters().optimisations_failed, 0);
  // Key scans are kept at reduced density: well under the 1440 x 4 bytes of a raw sweep... in
  // points (8 bytes each), a few hundred per key pose.
  EXPECT_LT(backend.scans().bytes_per_key_pose(), 8.0 * 800);
  return {rms(err_in), rms(err_out)};
}

TEST(Backend, ClosesLoopsAndReducesTheErrorOfADriftingFrontend) {
  const test::Drive d = test::drive_ellipse(25.0);  // 1.7 laps of 14.5 m
  // Links by scan matching only: the matcher removes the frontend's drift between key poses.
  BackendConfig matching_only;
  matching_only.frontend_sigma_xy_m = 0.0;
  const auto [in, out] = run_drive(d, matching_only);
  EXPECT_GT(in, 0.3);  // [m] the input drifts
  EXPECT_LT(out, 0.25 * in);
  EXPECT_LT(out, 0.05);  // [m]
  // Links by matching and by the frontend's motion, declared with this frontend's real precision
  // (about 1.2 cm and 4 mrad per link): the graph's marginals then admit the closures.
  BackendConfig both;
  both.frontend_sigma_xy_m = 0.015;
  both.frontend_sigma_theta_rad = 0.005;
  const auto [in2, out2] = run_drive(d, both);
  EXPECT_LT(out2, 0.8 * in2);
}

TEST(Backend, SmoothsAFrontendJumpAway) {
  test::Drive d = test::drive_ellipse(6.0);
  for (auto& T : d.input) T = d.truth[&T - d.input.data()];  // a perfect frontend ...
  for (std::size_t k = 30; k < d.input.size(); ++k) d.input[k] = Pose2(0.6, -0.4, 0.0) * d.input[k];
  Backend backend{BackendConfig{}};  // ... that jumps at scan 30
  for (std::size_t k = 0; k < d.utimes.size(); ++k) {
    backend.add_scan(d.scans[k]);
    backend.add_pose(d.utimes[k], d.input[k]);
  }
  backend.finish();
  EXPECT_EQ(backend.counters().jumps_smoothed, 1);
  const int64_t utime = backend.key_poses().back().utime;
  const std::size_t k = static_cast<std::size_t>(
      std::find(d.utimes.begin(), d.utimes.end(), utime) - d.utimes.begin());
  ASSERT_LT(k, d.utimes.size());
  EXPECT_LT((backend.graph().poses.back().translation() - d.truth[k].translation()).norm(), 0.05);
}

TEST(Backend, ConfigValidation) {
  BackendConfig config;
  EXPECT_EQ(validate(config), std::nullopt);
  config.link.resolution_m = -1.0;
  ASSERT_TRUE(validate(config));
  EXPECT_NE(validate(config)->find("key 'link."), std::string::npos);
  config = BackendConfig{};
  config.optimize_every = 0;
  EXPECT_TRUE(validate(config));
  // A key pose at least every 0 or -1 us is no interval.
  for (const int64_t interval_us : {0, -1}) {
    config = BackendConfig{};
    config.key_poses.interval_us = interval_us;
    ASSERT_TRUE(validate(config));
    EXPECT_NE(validate(config)->find("key 'key_poses.interval_us'"), std::string::npos);
  }
}

}  // namespace
}  // namespace traverse::backend
