// traverse-frontend-bench: per-scan processing time of the frontend on 8,536-point sweeps of a
// 47.7 Hz scanner carried at 0.5 m/s down a synthetic office corridor with 200 Hz IMU, on one
// core. Prints median and p99 [ms], the real-time factor, and a JSON line last.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <vector>

#include "frontend.hpp"
#include "synthetic_scans.hpp"

namespace fe = traverse::frontend;

int main(int argc, char** argv) {
  CLI::App app("Frontend benchmark on synthetic 8,536-point sweeps", "traverse-frontend-bench");
  int scans = 400;
  double spacing_m = fe::MatcherConfig{}.min_point_spacing_m;
  double resolution_m = fe::MapConfig{}.resolution_m;
  app.add_option("--scans", scans, "number of sweeps")->capture_default_str();
  app.add_option("--min-point-spacing", spacing_m, "matcher subsampling [m]")->capture_default_str();
  app.add_option("--resolution", resolution_m, "finest grid resolution [m]")->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  const double rate_hz = 47.7, speed = 0.5;
  const int64_t period_us = std::llround(1e6 / rate_hz);
  const auto world = fe::synthetic::office_block(80.0);
  // Down the corridor with a gentle weave (heading oscillates +-0.15 rad at 0.2 Hz).
  auto truth = [&](int64_t t) {
    const double s = 1e-6 * static_cast<double>(t);
    const double w = 2.0 * M_PI * 0.2;
    return traverse::Pose2(-30.0 + speed * s, 0.2 * std::sin(w * s), 0.15 * std::cos(w * s));
  };
  auto yaw_rate = [&](int64_t t) {
    const double w = 2.0 * M_PI * 0.2;
    return -0.15 * w * std::sin(w * 1e-6 * static_cast<double>(t));
  };
  fe::FrontendConfig config;
  config.matcher.min_point_spacing_m = spacing_m;
  config.map.resolution_m = resolution_m;
  fe::Frontend frontend(config);
  std::mt19937 rng(1);
  fe::synthetic::SweepSpec spec;
  spec.noise_sigma_m = 0.002;

  std::vector<double> ms;
  double final_error_m = 0.0;
  int64_t imu_t = 0;
  int matched_points = 0;
  for (int k = 0; k < scans; ++k) {
    spec.utime_first = k * period_us;
    const fe::Scan scan = fe::synthetic::make_sweep(world, truth, traverse::Pose2(), spec, &rng);
    for (; imu_t <= scan.utime_last; imu_t += 5000) {
      frontend.add_imu(imu_t, Eigen::Vector3d(0, 0, yaw_rate(imu_t)));
    }
    const auto t0 = std::chrono::steady_clock::now();
    const fe::FrontendResult r = frontend.process(scan);
    const auto t1 = std::chrono::steady_clock::now();
    ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    matched_points = r.matched_points;
    // The map frame is the base at the first scan's last point.
    const traverse::Pose2 T_map_base_true =
        truth(spec.duration_us).inverse() * truth(scan.utime_last);
    final_error_m = (r.T_map_base.translation() - T_map_base_true.translation()).norm();
  }
  std::vector<double> sorted = ms;
  std::sort(sorted.begin(), sorted.end());
  const double median = sorted[sorted.size() / 2];
  const double p99 = sorted[std::min(sorted.size() - 1, static_cast<std::size_t>(0.99 * sorted.size()))];
  const double mean = std::accumulate(ms.begin(), ms.end(), 0.0) / static_cast<double>(ms.size());
  const double rtf = (1000.0 / rate_hz) / mean;
  std::printf("sweeps: %d x 8536 points, %.1f Hz, matched points per scan: %d\n", scans, rate_hz,
              matched_points);
  std::printf("per-scan time: median %.2f ms, p99 %.2f ms, mean %.2f ms, max %.2f ms\n", median,
              p99, mean, sorted.back());
  std::printf("real-time factor at %.1f Hz on one core: %.1fx\n", rate_hz, rtf);
  std::printf("map: %zu bytes, %lld updates; final position error %.4f m\n",
              frontend.map().memory_bytes(), static_cast<long long>(frontend.counters().map_updates),
              final_error_m);
  std::printf(
      "{\"scans\": %d, \"points_per_scan\": 8536, \"matched_points_per_scan\": %d, "
      "\"per_scan_median_ms\": %.3f, \"per_scan_p99_ms\": %.3f, \"per_scan_mean_ms\": %.3f, "
      "\"real_time_factor\": %.2f, \"scanner_rate_hz\": %.1f, \"map_bytes\": %zu, "
      "\"final_position_error_m\": %.4f}\n",
      scans, matched_points, median, p99, mean, rtf, rate_hz, frontend.map().memory_bytes(),
      final_error_m);
  return 0;
}
