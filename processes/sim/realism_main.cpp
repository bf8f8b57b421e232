// traverse-sim-realism: compares simulated horizontal scans with real ones. Reads real CARMEN logs
// (the SICK LMS200 scans of ../shared/data/kummerle), groups them by angular step, simulates the
// same scanner class (rig models sick_lms200 for 1 deg, sick_lms200_half_deg for 0.5 deg) driven
// along a route of an office world with the realistic profile, measures both with the same code
// (realism.hpp), prints them side by side and, last, one JSON line with sigma_ratio (robust sigma
// of the local-line residuals) and outlier_ratio (mixed pixels and spikes per depth jump),
// simulated over real, each side the mean over the angular steps present.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "log_reader.hpp"
#include "config.hpp"
#include "json.hpp"
#include "realism.hpp"
#include "simulator.hpp"
#include "version.hpp"

namespace {

using traverse::sim::RealismSummary;
using traverse::sim::ScanStats;

struct Group {
  std::string model;  // rig scanner model simulated for this step
  ScanStats real, sim;
  std::vector<std::string> logs;
};

// Angular step in tenths of a degree: the key of a group.
int step_key(double step_rad) {
  return static_cast<int>(std::lround(std::abs(step_rad) * 1800.0 / M_PI));
}

void print_row(const char* name, const char* unit, const std::vector<double>& v, int digits) {
  std::printf("%-34s %-6s", name, unit);
  for (double x : v) std::printf(" %12.*f", digits, x);
  std::printf("\n");
}

}  // namespace

int main(int argc, char** argv) {
  using namespace traverse;
  CLI::App app{
      "Simulated against real horizontal scans: residuals, mixed pixels, outliers, "
      "returns per scan; JSON last"};
  std::vector<std::string> logs;
  std::string world_path = "configs/worlds/office.yaml",
              route_path = "configs/routes/office-s2.yaml";
  std::string config_path = "configs/sim.yaml";
  uint64_t seed = 1;
  int sim_scans = 3000, sim_every = 8;
  double laser_height_m = 0.35;
  sim::RealismConfig rc;
  app.add_option("--log", logs, "real CARMEN log(s) of a SICK LMS200")->required();
  app.add_option("--world", world_path, "world YAML")->capture_default_str();
  app.add_option("--route", route_path, "route YAML the simulated robot drives")
      ->capture_default_str();
  app.add_option("--config", config_path, "simulator config (configs/sim.yaml)")
      ->capture_default_str();
  app.add_option("--seed", seed, "simulator seed")->capture_default_str();
  app.add_option("--sim-scans", sim_scans, "simulated scans per angular step")
      ->capture_default_str();
  app.add_option("--sim-every", sim_every, "keep every n-th simulated sweep (75 Hz mirror)")
      ->capture_default_str();
  app.add_option("--laser-height", laser_height_m, "[m] scanner above the floor (a robot's)")
      ->capture_default_str();
  app.add_option("--max-range", rc.max_range_m, "[m] beams beyond are left out, both sides")
      ->capture_default_str();
  traverse::add_version_flag(app);
  CLI11_PARSE(app, argc, argv);

  std::map<int, Group> groups;
  for (const auto& path : logs) {
    carmen::Reader reader(path);
    if (!reader.good()) {
      std::fprintf(stderr, "traverse-sim-realism: cannot read %s\n", path.c_str());
      return 1;
    }
    while (auto scan = reader.next()) {
      Group& g = groups[step_key(scan->beams.angle_step)];
      if (g.logs.empty() || g.logs.back() != path) g.logs.push_back(path);
      g.real.add(scan->ranges, scan->beams.angle_first, scan->beams.angle_step, rc);
    }
  }
  sim::SimConfig cfg;
  sim::RigConfig rig;
  sim::WorldSpec world;
  sim::RouteSpec route;
  try {
    load_config(config_path, cfg);
    if (!cfg.rig_file.empty()) load_config(cfg.rig_file, rig);
    load_config(world_path, world);
    load_config(route_path, route);
  } catch (const ConfigError& e) {
    std::fprintf(stderr, "traverse-sim-realism: %s\n", e.what());
    return kConfigErrorExitCode;
  }
  if (auto error = sim::validate(cfg)) {
    std::fprintf(stderr, "traverse-sim-realism: config error: %s (in %s)\n", error->c_str(),
                 config_path.c_str());
    return kConfigErrorExitCode;
  }
  rig.laser_horizontal.z = laser_height_m;
  for (auto& [key, g] : groups) {
    g.model = key == 10 ? "sick_lms200" : key == 5 ? "sick_lms200_half_deg" : "";
    if (g.model.empty()) continue;
    route.horizontal_scanner = g.model;
    sim::RunOptions run;
    run.duration_s = sim_scans * sim_every / 75.0 + 1.0;
    run.profile_every = 1 << 30;  // no profiles: only the horizontal scanner is compared
    try {
      sim::Simulator simulator(world, route, rig, cfg.platform, seed, cfg.start_utime, run,
                               cfg.effects);
      int64_t sweeps = 0;
      while (auto ev = simulator.next()) {
        if (ev->kind != sim::SimEvent::Kind::kScanHorizontal || sweeps++ % sim_every != 0) continue;
        g.sim.add(ev->scan.ranges, ev->scan.angle_first, ev->scan.angle_step, rc);
        if (g.sim.scans >= sim_scans) break;
      }
    } catch (const std::exception& e) {
      std::fprintf(stderr, "traverse-sim-realism: %s\n", e.what());
      return 2;
    }
  }

  // Side by side, one real and one simulated column per angular step.
  std::vector<std::string> heads;
  std::vector<RealismSummary> cols;
  double sigma_real = 0, sigma_sim = 0, out_real = 0, out_sim = 0, share_real = 0, share_sim = 0;
  int used = 0;
  for (const auto& [key, g] : groups) {
    if (g.model.empty() || g.sim.scans == 0) continue;
    const RealismSummary r = sim::summarize(g.real), s = sim::summarize(g.sim);
    heads.push_back("real " + std::to_string(key / 10.0).substr(0, 3) + "deg");
    heads.push_back("sim " + std::to_string(key / 10.0).substr(0, 3) + "deg");
    cols.push_back(r);
    cols.push_back(s);
    sigma_real += r.sigma_m;
    sigma_sim += s.sigma_m;
    out_real += r.outliers_per_jump;
    out_sim += s.outliers_per_jump;
    share_real += r.outlier_fraction;
    share_sim += s.outlier_fraction;
    ++used;
    std::printf(
        "%.1f deg: real %s; simulated %s (%s, %s, seed %llu)\n", key / 10.0,
        [&] {
          std::string l;
          for (const auto& p : g.logs) l += (l.empty() ? "" : ", ") + p;
          return l;
        }()
            .c_str(),
        g.model.c_str(), route_path.c_str(), world_path.c_str(),
        static_cast<unsigned long long>(seed));
  }
  if (used == 0) {
    std::fprintf(stderr, "traverse-sim-realism: no LMS200 scans (1 or 0.5 deg) in the logs\n");
    return 1;
  }
  std::printf("\n%-34s %-6s", "", "");
  for (const auto& h : heads) std::printf(" %12s", h.c_str());
  std::printf("\n");
  auto row = [&](const char* name, const char* unit, auto get, int digits) {
    std::vector<double> v;
    for (const auto& c : cols) v.push_back(get(c));
    print_row(name, unit, v, digits);
  };
  row(
      "scans", "", [](const RealismSummary& c) { return double(c.scans); }, 0);
  row(
      "returns per scan", "", [](const RealismSummary& c) { return c.returns_per_scan; }, 1);
  row(
      "returns of all beams", "%", [](const RealismSummary& c) { return 100 * c.return_fraction; },
      1);
  row(
      "local-line residual sigma", "mm", [](const RealismSummary& c) { return 1e3 * c.sigma_m; },
      2);
  row(
      "local-line residual |p95|", "mm", [](const RealismSummary& c) { return 1e3 * c.p95_m; }, 2);
  row(
      "residuals beyond 3 sigma (tails)", "%",
      [](const RealismSummary& c) { return 100 * c.tail_fraction; }, 2);
  row(
      "depth jumps per scan", "", [](const RealismSummary& c) { return c.jumps_per_scan; }, 2);
  row(
      "mixed pixels per depth jump", "", [](const RealismSummary& c) { return c.mixed_per_jump; },
      3);
  row(
      "outliers (mixed + spikes) per jump", "",
      [](const RealismSummary& c) { return c.outliers_per_jump; }, 3);
  row(
      "outliers (mixed + spikes) of returns", "%",
      [](const RealismSummary& c) { return 100 * c.outlier_fraction; }, 3);
  const double sigma_ratio = sigma_sim / sigma_real, outlier_ratio = out_sim / out_real;
  std::printf(
      "\nsigma_ratio %.3f (residual sigma), outlier_ratio %.3f (outliers per depth jump); "
      "simulated over real, mean over %d step(s); outliers of returns %.3f\n",
      sigma_ratio, outlier_ratio, used, share_sim / share_real);
  traverse::Json j;
  j["sigma_ratio"] = traverse::json_fixed(sigma_ratio, 4);
  j["outlier_ratio"] = traverse::json_fixed(outlier_ratio, 4);
  j["sigma_real_m"] = traverse::json_fixed(sigma_real / used, 5);
  j["sigma_sim_m"] = traverse::json_fixed(sigma_sim / used, 5);
  j["outliers_per_jump_real"] = traverse::json_fixed(out_real / used, 4);
  j["outliers_per_jump_sim"] = traverse::json_fixed(out_sim / used, 4);
  j["outlier_fraction_real"] = traverse::json_fixed(share_real / used, 5);
  j["outlier_fraction_sim"] = traverse::json_fixed(share_sim / used, 5);
  j["outlier_fraction_ratio"] = traverse::json_fixed(share_sim / share_real, 4);
  j["steps"] = used;
  j["world"] = world_path;
  j["route"] = route_path;
  j["seed"] = seed;
  std::printf("%s\n", traverse::json_line(j).c_str());
  return 0;
}
