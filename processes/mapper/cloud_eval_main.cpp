// traverse-cloud-eval: accuracy of a mapper cloud (PLY) against the simulator's true world:
// point-to-surface distances, fitted pillar centres and corridor lengths. Prints a summary with
// units and one JSON object as the last line.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <map>

#include "cloud_eval.hpp"
#include "config.hpp"
#include "json.hpp"
#include "lcm_log.hpp"
#include "ply.hpp"
#include "traverse/pose2d_t.hpp"
#include "version.hpp"

namespace {

std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.6f", v);
  return b;
}

std::string opt(const std::optional<double>& v) { return v ? num(*v) : "null"; }

// First-pose alignment as the trajectory evaluator does it (seed 000: the runs were tied to the
// reference only through the starting pose): T_world_map = T_ref(t0) T_est(t0)^-1 at the first
// estimate pose t0, the reference interpolated there.
std::optional<traverse::Pose2> first_pose_alignment(const std::string& log,
                                                    const std::string& estimate,
                                                    const std::string& reference) {
  traverse::LogReader reader(log);
  std::optional<traverse::pose2d_t> est;
  std::map<int64_t, traverse::Pose2> ref;
  while (auto e = reader.next()) {
    if (e->channel != estimate && e->channel != reference) continue;
    traverse::pose2d_t m;
    if (m.decode(e->data.data(), 0, static_cast<int>(e->data.size())) !=
        static_cast<int>(e->data.size())) {
      continue;
    }
    if (e->channel == estimate && (!est || m.utime < est->utime)) est = m;
    if (e->channel == reference) ref[m.utime] = traverse::Pose2(m.x, m.y, m.theta);
  }
  if (!est) return std::nullopt;
  auto hi = ref.lower_bound(est->utime);
  if (hi == ref.end() || (hi == ref.begin() && hi->first != est->utime)) return std::nullopt;
  traverse::Pose2 T_world_base = hi->second;
  if (hi->first != est->utime) {
    auto lo = std::prev(hi);
    const double s =
        static_cast<double>(est->utime - lo->first) / static_cast<double>(hi->first - lo->first);
    T_world_base = traverse::interpolate(lo->second, hi->second, s);
  }
  return T_world_base * traverse::Pose2(est->x, est->y, est->theta).inverse();
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app(
      "traverse-cloud-eval: a mapper cloud against the simulator's true surfaces, "
      "pillars and corridors; JSON last");
  std::string world_file, cloud_file, config_file;
  std::size_t max_points = 5'000'000;
  app.add_option("--world", world_file, "world YAML (configs/worlds/*.yaml)")->required();
  app.add_option("--cloud", cloud_file, "PLY written by traverse-mapper")->required();
  app.add_option("--config", config_file, "evaluation settings (configs/cloud-eval-office.yaml)");
  std::string log, estimate = "POSE_DENSE", reference = "POSE_GROUND_TRUTH";
  app.add_option("--log", log,
                 "run log: align the cloud's map frame to the world by the first poses");
  app.add_option("--estimate", estimate, "trajectory channel the cloud was built with");
  app.add_option("--reference", reference, "true trajectory channel");
  app.add_option("--max-points", max_points,
                 "surface distances on at most this many points (evenly spread)");
  traverse::add_version_flag(app);
  CLI11_PARSE(app, argc, argv);

  traverse::sim::WorldSpec spec;
  traverse::mapper::CloudEvalConfig config;
  try {
    traverse::load_config(world_file, spec);
    if (!config_file.empty()) traverse::load_config(config_file, config);
  } catch (const traverse::ConfigError& e) {
    spdlog::error("{}", e.what());
    return traverse::kConfigErrorExitCode;
  }
  if (const auto problem = traverse::mapper::validate(config)) {
    spdlog::error("{}: {}", config_file.empty() ? "default config" : config_file, *problem);
    return traverse::kConfigErrorExitCode;
  }
  std::string error;
  auto cloud = traverse::mapper::read_ply(cloud_file, &error);
  if (!cloud) {
    spdlog::error("{}", error);
    return 1;
  }
  traverse::Pose2 T_world_map;
  if (!log.empty()) {
    std::optional<traverse::Pose2> align;
    try {
      align = first_pose_alignment(log, estimate, reference);
    } catch (const std::exception& e) {
      spdlog::error("{}", e.what());
      return 1;
    }
    if (!align) {
      spdlog::error("{}: no {} pose inside the {} poses to align with", log, estimate, reference);
      return 1;
    }
    T_world_map = *align;
    traverse::mapper::transform_cloud(*cloud, T_world_map);
  }
  std::printf("alignment T_world_map: x %.4f m, y %.4f m, theta %.4f rad\n", T_world_map.x(),
              T_world_map.y(), T_world_map.theta());
  const traverse::sim::World world(spec);
  const std::size_t stride =
      std::max<std::size_t>(1, cloud->size() / std::max<std::size_t>(1, max_points));
  const auto r = traverse::mapper::evaluate_cloud(*cloud, world, spec, config, stride);

  std::printf("cloud: %zu points, %d evaluated against the true surfaces\n", cloud->size(),
              r.surface.n);
  std::printf("point to surface: mode %.2f mm, mean %.2f mm, RMSE %.2f mm, p95 %.2f mm\n",
              1e3 * r.surface.mode, 1e3 * r.surface.mean, 1e3 * r.surface.rmse,
              1e3 * r.surface.p95);
  const auto fixed6 = [](std::optional<double> v) { return traverse::json_fixed(v, 6); };
  traverse::Json pillars = traverse::Json::array(), corridors = traverse::Json::array();
  for (const auto& p : r.pillars) {
    std::printf("pillar %s: %d points, centre error %s\n", p.id.c_str(), p.points,
                p.error_m ? (num(1e3 * *p.error_m) + " mm").c_str() : "not fitted");
    pillars.push_back({{"id", p.id}, {"points", p.points}, {"error_m", fixed6(p.error_m)}});
  }
  std::printf("pillars: n %d, mean %.2f mm, SD %.2f mm, RMSE %.2f mm, min %.2f mm, max %.2f mm\n",
              r.pillar.n, 1e3 * r.pillar.mean, 1e3 * r.pillar.sd, 1e3 * r.pillar.rmse,
              1e3 * r.pillar.min, 1e3 * r.pillar.max);
  for (const auto& c : r.corridors) {
    std::printf("corridor %s: %s m in the cloud, %.3f m true (%d and %d points at its ends)\n",
                c.name.c_str(), opt(c.length_m).c_str(), c.true_length_m, c.points_a, c.points_b);
    corridors.push_back(
        {{"name", c.name},
         {"length_m", fixed6(c.length_m)},
         {"true_length_m", fixed6(c.true_length_m)},
         {"points_a", c.points_a},
         {"points_b", c.points_b},
         {"error_m", c.length_m ? fixed6(*c.length_m - c.true_length_m) : traverse::Json()}});
  }
  const bool fitted = r.pillar.n > 0;
  const auto pillar = [&](double v) { return fitted ? fixed6(v) : traverse::Json(); };
  traverse::Json j;
  j["cloud_points"] = cloud->size();
  j["cloud_points_evaluated"] = r.surface.n;
  j["cloud_mode_m"] = fixed6(r.surface.mode);
  j["cloud_mean_m"] = fixed6(r.surface.mean);
  j["cloud_rmse_m"] = fixed6(r.surface.rmse);
  j["cloud_p95_m"] = fixed6(r.surface.p95);
  j["pillar_n"] = r.pillar.n;
  j["pillar_mean_m"] = pillar(r.pillar.mean);
  j["pillar_sd_m"] = pillar(r.pillar.sd);
  j["pillar_rmse_m"] = pillar(r.pillar.rmse);
  j["pillar_min_m"] = pillar(r.pillar.min);
  j["pillar_max_m"] = pillar(r.pillar.max);
  j["cloud_align_x_m"] = fixed6(T_world_map.x());
  j["cloud_align_y_m"] = fixed6(T_world_map.y());
  j["cloud_align_theta_rad"] = fixed6(T_world_map.theta());
  j["pillars"] = std::move(pillars);
  j["corridors"] = std::move(corridors);
  std::printf("%s\n", traverse::json_line(j).c_str());
  return 0;
}
