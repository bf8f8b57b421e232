// traverse-frontend-bench: per-scan processing time of the frontend on one core, on the 8,536-point
// sweeps of a 47.7 Hz scanner: read from a log (--log: SCAN_HORIZONTAL, IMU, ODOMETRY), or made
// here (a cart at 0.5 m/s down a synthetic office corridor with 200 Hz IMU). Prints median and
// p99 [ms], the real-time factor, and a JSON line last. --trace FILE writes one CSV row per scan of
// a log: what the frontend did with it (status, the prediction and the result, the fit, the search,
// the held directions, the published sigmas) and, where the log has ground truth, the result's
// error against it (the map frame tied to the truth at the first pose).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <deque>
#include <fstream>
#include <map>
#include <memory>
#include <numeric>
#include <optional>
#include <vector>

#include "channels.hpp"
#include "config.hpp"
#include "frontend.hpp"
#include "json.hpp"
#include "lcm_log.hpp"
#include "odometry_message.hpp"
#include "scan_message.hpp"
#include "synthetic_scans.hpp"
#include "traverse/imu_t.hpp"
#include "traverse/planar_scan_t.hpp"
#include "traverse/pose2d_t.hpp"
#include "version.hpp"

namespace fe = traverse::frontend;

namespace {

// CPU time of this thread [ms]: what one core spends, unaffected by other processes sharing the
// machine (wall time is, on a busy host).
double cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}

// One scan's result, and the truth at its time in the estimate's map frame where the log has it.
struct Trace {
  int64_t utime = 0;
  fe::FrontendResult result;
  std::optional<traverse::Pose2> T_map_base_true;
};

// The trace as CSV: units in the column names, angles in degrees, sigmas from the published
// covariance.
void write_trace(const std::string& path, const std::vector<Trace>& trace) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path);
  out << "utime_us,status,sparse,x_m,y_m,theta_deg,pred_x_m,pred_y_m,pred_theta_deg,"
         "valid_points,matched_points,iterations,residual_rms,searched,degeneracy_ratio,"
         "degenerate_directions,sigma_x_m,sigma_y_m,sigma_theta_deg,err_x_m,err_y_m,"
         "err_theta_deg\n";
  const double deg = 180.0 / M_PI;
  for (const Trace& row : trace) {
    const fe::FrontendResult& r = row.result;
    const fe::FrontendDiagnostics d = r.diagnostics.value_or(fe::FrontendDiagnostics{});
    out << row.utime << ',' << static_cast<int>(r.status) << ',' << r.sparse << ','
        << r.T_map_base.x() << ',' << r.T_map_base.y() << ',' << r.T_map_base.theta() * deg << ','
        << d.T_map_base_predicted.x() << ',' << d.T_map_base_predicted.y() << ','
        << d.T_map_base_predicted.theta() * deg << ',' << d.valid_points << ',' << d.matched_points
        << ',' << d.iterations << ',' << d.residual_rms << ',' << d.searched << ','
        << d.degeneracy_ratio << ',' << d.degenerate_directions << ','
        << std::sqrt(r.covariance(0, 0)) << ',' << std::sqrt(r.covariance(1, 1)) << ','
        << std::sqrt(r.covariance(2, 2)) * deg;
    if (row.T_map_base_true && r.has_pose()) {
      const traverse::Pose2& t = *row.T_map_base_true;
      out << ',' << r.T_map_base.x() - t.x() << ',' << r.T_map_base.y() - t.y() << ','
          << traverse::wrap_angle(r.T_map_base.theta() - t.theta()) * deg << '\n';
    } else {
      out << ",,,\n";
    }
  }
}

struct Timing {
  std::vector<double> ms;  // per scan
  int points = 0;          // per scan (last)
  int matched_points = 0;  // per scan (last)
  double rate_hz = 47.7;
  double error_m = -1.0;  // final position error, synthetic run only
};

// Every SCAN_HORIZONTAL of an LCM log through the frontend, with its IMU and ODOMETRY samples in
// the log's order; POSE_GROUND_TRUTH, where the log has it, scores the result.
Timing run_log(const std::string& path, fe::Frontend& frontend, std::vector<Trace>* trace) {
  Timing timing;
  traverse::LogReader reader(path);
  std::deque<fe::Scan> pending;
  int64_t first_utime = 0, last_utime = 0;
  int scans = 0;
  std::vector<std::pair<int64_t, traverse::Pose2>> estimates, truth;
  auto process = [&](const fe::Scan& scan) {
    const double t0 = cpu_ms();
    fe::FrontendResult r = frontend.process(scan);
    timing.ms.push_back(cpu_ms() - t0);
    timing.points = static_cast<int>(scan.ranges.size());
    if (r.diagnostics) timing.matched_points = r.diagnostics->matched_points;
    if (r.has_pose()) estimates.emplace_back(r.utime, r.T_map_base);
    if (trace) trace->push_back({r.utime, std::move(r), std::nullopt});
  };
  // A scan is processed once every motion stream the log has (IMU, wheel odometry) has passed its
  // last point, as the node does.
  std::optional<int64_t> last_imu, last_odometry;
  auto flush = [&] {
    const auto covered = [](const std::optional<int64_t>& last, int64_t utime) {
      return !last || *last >= utime;
    };
    while (!pending.empty() && covered(last_imu, pending.front().utime_last) &&
           covered(last_odometry, pending.front().utime_last)) {
      process(pending.front());
      pending.pop_front();
    }
  };
  while (auto ev = reader.next()) {
    if (ev->channel == traverse::channels::kImu) {
      traverse::imu_t m;
      if (m.decode(ev->data.data(), 0, static_cast<int>(ev->data.size())) < 0) continue;
      if (frontend.add_imu(m.utime, Eigen::Vector3d(m.angular_velocity[0], m.angular_velocity[1],
                                                    m.angular_velocity[2]))) {
        last_imu = m.utime;
      }
      flush();
    } else if (ev->channel == traverse::channels::kOdometry) {
      traverse::odometry_t m;
      if (m.decode(ev->data.data(), 0, static_cast<int>(ev->data.size())) < 0) continue;
      if (frontend.add_odometry(fe::to_odometry_sample(m))) last_odometry = m.utime;
      flush();
    } else if (ev->channel == traverse::channels::kPoseGroundTruth) {
      traverse::pose2d_t m;
      if (m.decode(ev->data.data(), 0, static_cast<int>(ev->data.size())) < 0) continue;
      truth.emplace_back(m.utime, traverse::Pose2(m.x, m.y, m.theta));
    } else if (ev->channel == traverse::channels::kScanHorizontal) {
      traverse::planar_scan_t m;
      if (m.decode(ev->data.data(), 0, static_cast<int>(ev->data.size())) < 0) continue;
      if (scans++ == 0) first_utime = m.utime_first;
      last_utime = m.utime_first;
      pending.push_back(traverse::to_planar_scan(m));
      flush();
    }
  }
  for (const auto& scan : pending) process(scan);
  if (const auto r = frontend.finish()) estimates.emplace_back(r->utime, r->T_map_base);
  // Position error RMS against the simulator's ground truth (interpolated to each pose's time),
  // the estimate's map frame tied to the truth at the first pose.
  auto truth_at = [&](int64_t t) -> std::optional<traverse::Pose2> {
    auto it = std::lower_bound(truth.begin(), truth.end(), t,
                               [](const auto& a, int64_t u) { return a.first < u; });
    if (it == truth.end() || it == truth.begin()) return std::nullopt;
    const auto& [tb, b] = *it;
    const auto& [ta, a] = *(it - 1);
    return traverse::interpolate(a, b, static_cast<double>(t - ta) / static_cast<double>(tb - ta));
  };
  std::optional<traverse::Pose2> T_world_map;
  double sum = 0.0;
  int n = 0;
  for (const auto& [t, T_map_base] : estimates) {
    const auto T_world_base = truth_at(t);
    if (!T_world_base) continue;
    if (!T_world_map) T_world_map = *T_world_base * T_map_base.inverse();
    sum += ((*T_world_map * T_map_base).translation() - T_world_base->translation()).squaredNorm();
    ++n;
  }
  if (n > 0) timing.error_m = std::sqrt(sum / n);
  if (trace && T_world_map) {
    for (Trace& row : *trace) {
      if (auto T = truth_at(row.utime)) row.T_map_base_true = T_world_map->inverse() * *T;
    }
  }
  if (scans > 1)
    timing.rate_hz = (scans - 1) / (1e-6 * static_cast<double>(last_utime - first_utime));
  return timing;
}

// Synthetic sweeps: a cart at 0.5 m/s down an office corridor, weaving (heading +-0.15 rad at
// 0.2 Hz), 2 mm range noise, 200 Hz IMU.
Timing run_synthetic(int scans, fe::Frontend& frontend) {
  Timing timing;
  const double speed = 0.5, w = 2.0 * M_PI * 0.2;
  const int64_t period_us = std::llround(1e6 / timing.rate_hz);
  const auto world = fe::synthetic::office_block(80.0);
  auto truth = [&](int64_t t) {
    const double s = 1e-6 * static_cast<double>(t);
    return traverse::Pose2(-30.0 + speed * s, 0.2 * std::sin(w * s), 0.15 * std::cos(w * s));
  };
  auto yaw_rate = [&](int64_t t) {
    return -0.15 * w * std::sin(w * 1e-6 * static_cast<double>(t));
  };
  std::mt19937 rng(1);
  fe::synthetic::SweepSpec spec;
  spec.noise_sigma_m = 0.002;
  int64_t imu_t = 0;
  for (int k = 0; k < scans; ++k) {
    spec.utime_first = k * period_us;
    const fe::Scan scan = fe::synthetic::make_sweep(world, truth, traverse::Pose2(), spec, &rng);
    for (; imu_t <= scan.utime_last; imu_t += 5000) {
      frontend.add_imu(imu_t, Eigen::Vector3d(0, 0, yaw_rate(imu_t)));
    }
    const double t0 = cpu_ms();
    const fe::FrontendResult r = frontend.process(scan);
    timing.ms.push_back(cpu_ms() - t0);
    timing.points = spec.n_ranges;
    if (r.diagnostics) timing.matched_points = r.diagnostics->matched_points;
    // The map frame is the base at the first scan's last point.
    const traverse::Pose2 T_map_base_true =
        truth(spec.duration_us).inverse() * truth(scan.utime_last);
    timing.error_m = (r.T_map_base.translation() - T_map_base_true.translation()).norm();
  }
  return timing;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("Frontend per-scan processing time on 8,536-point sweeps",
               "traverse-frontend-bench");
  std::string log_path, config_path, trace_path;
  int scans = 1000;
  app.add_option("--log", log_path,
                 "LCM log with SCAN_HORIZONTAL and IMU (e.g. from traverse-sim)");
  app.add_option("--scans", scans, "synthetic sweeps when no --log")->capture_default_str();
  app.add_option("--config", config_path, "frontend config (YAML); defaults otherwise");
  app.add_option("--trace", trace_path,
                 "with --log: write one CSV row per scan (status, prediction, result, fit, "
                 "search, held directions, sigmas, error against the log's ground truth)");
  traverse::add_version_flag(app);
  CLI11_PARSE(app, argc, argv);
  fe::FrontendConfig config;
  try {
    if (!config_path.empty()) traverse::load_config(config_path, config);
    if (auto problem = fe::validate(config)) throw traverse::ConfigError(*problem);
  } catch (const traverse::ConfigError& e) {
    std::fprintf(stderr, "traverse-frontend-bench: %s\n", e.what());
    return traverse::kConfigErrorExitCode;
  }
  const std::unique_ptr<fe::Frontend> frontend = fe::make_frontend(config);
  Timing t;
  try {
    if (!trace_path.empty() && log_path.empty()) {
      std::fprintf(stderr, "traverse-frontend-bench: --trace needs --log\n");
      return 2;
    }
    std::vector<Trace> trace;
    t = log_path.empty() ? run_synthetic(scans, *frontend)
                         : run_log(log_path, *frontend, trace_path.empty() ? nullptr : &trace);
    if (!trace_path.empty()) write_trace(trace_path, trace);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "traverse-frontend-bench: %s\n", e.what());
    return 1;
  }
  if (t.ms.empty()) {
    std::fprintf(stderr, "traverse-frontend-bench: no scans\n");
    return 1;
  }
  std::vector<double> sorted = t.ms;
  std::sort(sorted.begin(), sorted.end());
  const double median = sorted[sorted.size() / 2];
  const double p99 =
      sorted[std::min(sorted.size() - 1, static_cast<std::size_t>(0.99 * sorted.size()))];
  const double mean =
      std::accumulate(t.ms.begin(), t.ms.end(), 0.0) / static_cast<double>(t.ms.size());
  const double rtf = (1000.0 / t.rate_hz) / mean;
  std::map<std::string, double> c;
  frontend->report([&c](const std::string& name, double value) { c[name] = value; });
  std::printf("input: %s\n", log_path.empty() ? "synthetic office corridor" : log_path.c_str());
  std::printf("sweeps: %zu of %d points at %.1f Hz; %d points matched per scan after subsampling\n",
              t.ms.size(), t.points, t.rate_hz, t.matched_points);
  std::printf("per-scan CPU time: median %.2f ms, p99 %.2f ms, mean %.2f ms, max %.2f ms\n", median,
              p99, mean, sorted.back());
  std::printf("real-time factor at %.1f Hz on one core: %.1fx (scan period / mean time)\n",
              t.rate_hz, rtf);
  std::printf("map: %zu bytes after %.0f updates; %.0f scans needed the recovery search\n",
              frontend->map_bytes(), c["map_updates"], c["scans_searched"]);
  if (t.error_m >= 0.0) {
    std::printf("position error: %.4f m (%s)\n", t.error_m,
                log_path.empty() ? "final, synthetic" : "RMS against ground truth");
  }
  using traverse::json_fixed;
  traverse::Json j;
  j["input"] = log_path.empty() ? "synthetic" : "log";
  j["scans"] = t.ms.size();
  j["points_per_scan"] = t.points;
  j["matched_points_per_scan"] = t.matched_points;
  j["per_scan_median_ms"] = json_fixed(median, 3);
  j["per_scan_p99_ms"] = json_fixed(p99, 3);
  j["per_scan_mean_ms"] = json_fixed(mean, 3);
  j["per_scan_max_ms"] = json_fixed(sorted.back(), 3);
  j["scanner_rate_hz"] = json_fixed(t.rate_hz, 2);
  j["real_time_factor"] = json_fixed(rtf, 2);
  j["map_bytes"] = frontend->map_bytes();
  j["map_updates"] = json_fixed(c["map_updates"], 0);
  j["position_error_m"] = json_fixed(t.error_m, 5);
  std::printf("%s\n", traverse::json_line(j).c_str());
  return 0;
}
