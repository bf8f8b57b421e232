// traverse-densifier-compare: the paper's densification (seed 000: uniform scaling) against the
// rigid one on the simulator's true cart motion for each route given. A frontend-like dense
// trajectory is made from the truth at the horizontal scanner's rate (odometry-style drift that
// grows with travel, plus independent jitter of 1 mm and 0.3 mrad per scan); key poses every
// 1/3 s are the truth with an optimiser-sized error (2 mm, 0.5 mrad). Both modes bend the dense
// trajectory to the key poses; errors are taken against the truth at every dense pose, overall
// and while the cart stands still. JSON last.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>

#include "config.hpp"
#include "densifier.hpp"
#include "json.hpp"
#include "rig.hpp"
#include "rng.hpp"
#include "trajectory.hpp"
#include "version.hpp"

namespace {

namespace td = traverse::densifier;
namespace ts = traverse::sim;
using traverse::Pose2;

struct Errors {
  double rmse_m = 0, max_m = 0, heading_rmse_rad = 0, still_rmse_m = 0, still_max_m = 0;
};

Errors errors(const std::vector<td::StampedPose>& est, const std::vector<Pose2>& truth,
              const std::vector<bool>& still) {
  Errors e;
  double sq = 0, sq_h = 0, sq_s = 0;
  int n_s = 0;
  for (std::size_t i = 0; i < est.size(); ++i) {
    const double d = (est[i].T_world_base.translation() - truth[i].translation()).norm();
    const double h = traverse::wrap_angle(est[i].T_world_base.theta() - truth[i].theta());
    sq += d * d;
    sq_h += h * h;
    e.max_m = std::max(e.max_m, d);
    if (still[i]) {
      sq_s += d * d;
      ++n_s;
      e.still_max_m = std::max(e.still_max_m, d);
    }
  }
  e.rmse_m = std::sqrt(sq / est.size());
  e.heading_rmse_rad = std::sqrt(sq_h / est.size());
  e.still_rmse_m = n_s ? std::sqrt(sq_s / n_s) : 0.0;
  return e;
}

traverse::Json json(const Errors& e) {
  traverse::Json j;
  j["rmse_m"] = traverse::json_fixed(e.rmse_m, 6);
  j["max_m"] = traverse::json_fixed(e.max_m, 6);
  j["heading_rmse_rad"] = traverse::json_fixed(e.heading_rmse_rad, 6);
  j["still_rmse_m"] = traverse::json_fixed(e.still_rmse_m, 6);
  j["still_max_m"] = traverse::json_fixed(e.still_max_m, 6);
  return j;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("traverse-densifier-compare: paper vs rigid densification on simulated routes");
  std::vector<std::string> routes;
  uint64_t seed = 1;
  app.add_option("routes", routes, "route YAML files (configs/routes/*.yaml)")->required();
  app.add_option("--seed", seed);
  traverse::add_version_flag(app);
  CLI11_PARSE(app, argc, argv);

  traverse::Json out_routes = traverse::Json::array();
  for (const std::string& file : routes) {
    ts::RouteSpec route;
    try {
      traverse::load_config(file, route);
    } catch (const traverse::ConfigError& e) {
      std::fprintf(stderr, "%s\n", e.what());
      return traverse::kConfigErrorExitCode;
    }
    ts::Rng rng(seed, 7);
    const ts::Trajectory trajectory(route, ts::PlatformConfig{}, rng);
    const double rate_hz = route.horizontal_scanner == "focus3d_x330" ? 59.7 : 47.7;
    const int key_every = static_cast<int>(std::lround(rate_hz / 3.0));
    std::vector<Pose2> truth;
    std::vector<bool> still;
    std::vector<td::StampedPose> dense;
    std::vector<td::KeyPose> keys;
    Pose2 odo;
    for (int i = 0;; ++i) {
      const double t = i / rate_hz;
      if (t > trajectory.duration_s()) break;
      const Pose2 T = trajectory.pose(t);
      const int64_t utime = static_cast<int64_t>(std::llround(t * 1e6));
      if (i == 0) {
        odo = T;
      } else {
        // Odometry-style drift: 1 % of the step's travel and 0.5 % of its turn, plus a floor.
        const Pose2 step = traverse::between(truth.back(), T);
        const double d = step.translation().norm(), a = std::abs(step.theta());
        odo = odo * Pose2(step.x() + rng.normal(0.01 * d + 5e-5),
                          step.y() + rng.normal(0.01 * d + 5e-5),
                          step.theta() + rng.normal(0.005 * a + 2e-5));
      }
      still.push_back(i > 0 &&
                      (T.translation() - truth.back().translation()).norm() * rate_hz < 0.01);
      truth.push_back(T);
      dense.push_back({utime, odo * Pose2(rng.normal(1e-3), rng.normal(1e-3), rng.normal(3e-4))});
      if (i % key_every == 0) {
        keys.push_back({static_cast<int64_t>(keys.size()), utime,
                        T * Pose2(rng.normal(2e-3), rng.normal(2e-3), rng.normal(5e-4))});
      }
    }
    traverse::Json entry;
    entry["route"] = file;
    for (const char* mode : {"paper", "rigid"}) {
      td::DensifierConfig cfg;
      cfg.mode = mode;
      td::Densifier d(cfg);
      for (const auto& p : dense) d.add_dense(p.utime, p.T_world_base, nullptr);
      d.update_key_poses(keys);
      const Errors e = errors(d.corrected_trajectory(), truth, still);
      std::printf(
          "%s %s: dense trajectory RMSE %.2f mm, max %.2f mm, heading RMSE %.3f mrad; standing "
          "still: RMSE %.2f mm, max %.2f mm\n",
          file.c_str(), mode, 1e3 * e.rmse_m, 1e3 * e.max_m, 1e3 * e.heading_rmse_rad,
          1e3 * e.still_rmse_m, 1e3 * e.still_max_m);
      entry[mode] = json(e);
    }
    out_routes.push_back(std::move(entry));
  }
  traverse::Json summary;
  summary["seed"] = seed;
  summary["routes"] = std::move(out_routes);
  std::printf("%s\n", traverse::json_line(summary).c_str());
  return 0;
}
