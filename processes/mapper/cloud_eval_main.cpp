// traverse-cloud-eval: accuracy of a mapper cloud (PLY) against the simulator's true world:
// point-to-surface distances, fitted pillar centres and corridor lengths. Prints a summary with
// units and one JSON object as the last line.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <sstream>

#include "cloud_eval.hpp"
#include "config.hpp"
#include "ply.hpp"

namespace {

std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.6f", v);
  return b;
}

std::string opt(const std::optional<double>& v) { return v ? num(*v) : "null"; }

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("traverse-cloud-eval: a mapper cloud against the simulator's true surfaces, "
               "pillars and corridors; JSON last");
  std::string world_file, cloud_file, config_file;
  std::size_t max_points = 5'000'000;
  app.add_option("--world", world_file, "world YAML (configs/worlds/*.yaml)")->required();
  app.add_option("--cloud", cloud_file, "PLY written by traverse-mapper")->required();
  app.add_option("--config", config_file, "evaluation settings (configs/cloud-eval-office.yaml)");
  app.add_option("--max-points", max_points,
                 "surface distances on at most this many points (evenly spread)");
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
  std::string error;
  auto cloud = traverse::mapper::read_ply(cloud_file, &error);
  if (!cloud) {
    spdlog::error("{}", error);
    return 1;
  }
  const traverse::sim::World world(spec);
  const std::size_t stride = std::max<std::size_t>(1, cloud->size() / std::max<std::size_t>(1, max_points));
  const auto r = traverse::mapper::evaluate_cloud(*cloud, world, spec, config, stride);

  std::printf("cloud: %zu points, %d evaluated against the true surfaces\n", cloud->size(),
              r.surface.n);
  std::printf("point to surface: mode %.2f mm, mean %.2f mm, RMSE %.2f mm, p95 %.2f mm\n",
              1e3 * r.surface.mode, 1e3 * r.surface.mean, 1e3 * r.surface.rmse,
              1e3 * r.surface.p95);
  std::ostringstream pillars, corridors;
  for (const auto& p : r.pillars) {
    std::printf("pillar %s: %d points, centre error %s\n", p.id.c_str(), p.points,
                p.error_m ? (num(1e3 * *p.error_m) + " mm").c_str() : "not fitted");
    pillars << (pillars.tellp() > 0 ? ", " : "") << "{\"id\": \"" << p.id
            << "\", \"points\": " << p.points << ", \"error_m\": " << opt(p.error_m) << "}";
  }
  std::printf("pillars: n %d, mean %.2f mm, SD %.2f mm, RMSE %.2f mm, min %.2f mm, max %.2f mm\n",
              r.pillar.n, 1e3 * r.pillar.mean, 1e3 * r.pillar.sd, 1e3 * r.pillar.rmse,
              1e3 * r.pillar.min, 1e3 * r.pillar.max);
  for (const auto& c : r.corridors) {
    std::printf("corridor %s: %s m in the cloud, %.3f m true\n", c.name.c_str(),
                opt(c.length_m).c_str(), c.true_length_m);
    corridors << (corridors.tellp() > 0 ? ", " : "") << "{\"name\": \"" << c.name
              << "\", \"length_m\": " << opt(c.length_m)
              << ", \"true_length_m\": " << num(c.true_length_m) << ", \"error_m\": "
              << (c.length_m ? num(*c.length_m - c.true_length_m) : "null") << "}";
  }
  const bool fitted = r.pillar.n > 0;
  std::printf(
      "{\"cloud_points\": %zu, \"cloud_points_evaluated\": %d, \"cloud_mode_m\": %s, "
      "\"cloud_mean_m\": %s, \"cloud_rmse_m\": %s, \"cloud_p95_m\": %s, \"pillar_n\": %d, "
      "\"pillar_mean_m\": %s, \"pillar_sd_m\": %s, \"pillar_rmse_m\": %s, \"pillar_min_m\": %s, "
      "\"pillar_max_m\": %s, \"pillars\": [%s], \"corridors\": [%s]}\n",
      cloud->size(), r.surface.n, num(r.surface.mode).c_str(), num(r.surface.mean).c_str(),
      num(r.surface.rmse).c_str(), num(r.surface.p95).c_str(), r.pillar.n,
      fitted ? num(r.pillar.mean).c_str() : "null", fitted ? num(r.pillar.sd).c_str() : "null",
      fitted ? num(r.pillar.rmse).c_str() : "null", fitted ? num(r.pillar.min).c_str() : "null",
      fitted ? num(r.pillar.max).c_str() : "null", pillars.str().c_str(), corridors.str().c_str());
  return 0;
}
