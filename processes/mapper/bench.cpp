// traverse-mapper-bench: speed of the Mapper on simulated profiles (one core), against plain
// OcTree::insertPointCloud on the same points in the same run. Simulates the route first (not
// timed), places the profiles with the true trajectory at 2 cm and 5 cm, times a loop closure
// that moves the second half of the trajectory, and prints one JSON object last.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>

#include "bench_sim.hpp"
#include "json.hpp"
#include "version.hpp"

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

namespace tm = traverse::mapper;
namespace ts = traverse::sim;

struct Run {
  double mapper_s = 0, octomap_s = 0, move_s = 0, small_move_s = 0, small_move_2threads_s = 0;
  int64_t points = 0, octomap_points = 0, moved_profiles = 0, small_moved_profiles = 0;
  std::size_t voxels = 0, profile_bytes = 0;
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("traverse-mapper-bench: Mapper points per second vs OcTree::insertPointCloud");
  std::string world_file = "configs/worlds/office.yaml",
              route_file = "configs/routes/office-x2.yaml";
  std::string rig_file = "configs/rig.yaml";
  double duration_s = 60, begin_s = 10, baseline_s = 2;
  app.add_option("--world", world_file);
  app.add_option("--route", route_file);
  app.add_option("--rig", rig_file);
  app.add_option("--duration", duration_s, "[s] of profiles");
  app.add_option("--begin", begin_s, "[s] into the route");
  app.add_option("--baseline", baseline_s, "[s] of profiles given to insertPointCloud");
  traverse::add_version_flag(app);
  CLI11_PARSE(app, argc, argv);

  ts::RunOptions opt;
  opt.begin_s = begin_s;
  opt.duration_s = duration_s;
  tm::BenchSim bench(world_file, route_file, rig_file, opt);
  const ts::RigConfig& rig = bench.rig;
  std::vector<tm::Profile> profiles;
  std::vector<int64_t> gt_t;
  std::vector<traverse::Pose2> gt;
  const auto t_sim = Clock::now();
  while (auto e = bench.simulator->next()) {
    if (e->kind == ts::SimEvent::Kind::kGroundTruth) {
      gt_t.push_back(e->utime);
      gt.push_back(e->ground_truth.T_world_base);
    } else if (e->kind == ts::SimEvent::Kind::kScanProfile) {
      profiles.push_back(tm::profile_of(e->scan));
    }
  }
  std::fprintf(stderr, "simulated %.0f s: %zu profiles, %zu true poses in %.1f s\n", duration_s,
               profiles.size(), gt.size(), seconds_since(t_sim));
  // The true trajectory in segments of 40 poses (0.2 s), as the densifier would send them.
  auto segments = [&](double shift_y, double turn, std::size_t from) {
    std::vector<tm::TrajectorySegment> out;
    for (std::size_t i = 0; i + 1 < gt.size(); i += 40) {
      tm::TrajectorySegment s;
      s.key_id_first = static_cast<int64_t>(out.size());
      for (std::size_t j = i; j <= std::min(i + 40, gt.size() - 1); ++j) {
        s.utimes.push_back(gt_t[j]);
        const double dy = i >= from ? shift_y : 0.0, dth = i >= from ? turn : 0.0;
        s.T_world_base.emplace_back(gt[j].x(), gt[j].y() + dy, gt[j].theta() + dth);
      }
      if (s.utimes.size() >= 2) out.push_back(s);
    }
    return out;
  };
  const auto base_segments = segments(0, 0, 0);
  // A typical loop closure on the office routes moves segments by 1-3 mm and 1e-4 rad.
  const auto small_moved_segments = segments(0.002, 1e-4, gt.size() / 2);
  const auto moved_segments = segments(0.05, 0, gt.size() / 2);
  int64_t beams = 0;
  for (const auto& p : profiles) beams += static_cast<int64_t>(p.ranges.size());
  const Eigen::Isometry3d T_base_laser = rig.laser_profile.transform();

  Run runs[2];
  const double resolutions[2] = {0.02, 0.05};
  for (int r = 0; r < 2; ++r) {
    tm::MapperConfig cfg;
    cfg.resolution_m = resolutions[r];
    cfg.move_threads = 1;
    tm::Mapper mapper(cfg, T_base_laser);
    for (const auto& s : base_segments) mapper.set_segment(s);
    auto t0 = Clock::now();
    for (const auto& p : profiles) mapper.add_profile(p);
    runs[r].mapper_s = seconds_since(t0);
    runs[r].points = mapper.points();
    runs[r].voxels = mapper.occupied_voxels();
    runs[r].profile_bytes = mapper.profile_bytes();
    // The same points, profile by profile, through plain insertPointCloud (rays from the laser).
    octomap::OcTree tree(resolutions[r]);
    std::vector<octomap::Pointcloud> clouds(profiles.size());
    std::size_t k = 0;
    mapper.for_each_point([&](const tm::CloudPoint& p) {
      while (k + 1 < profiles.size() && p.utime > profiles[k].utime_last) ++k;
      clouds[k].push_back(p.p_world.x(), p.p_world.y(), p.p_world.z());
    });
    const int64_t t_end = profiles.front().utime_first + static_cast<int64_t>(baseline_s * 1e6);
    t0 = Clock::now();
    for (std::size_t i = 0; i < profiles.size() && profiles[i].utime_last <= t_end; ++i) {
      const int64_t t_mid = (profiles[i].utime_first + profiles[i].utime_last) / 2;
      auto it = std::lower_bound(gt_t.begin(), gt_t.end(), t_mid);
      const traverse::Pose2& T = gt[static_cast<std::size_t>(it - gt_t.begin())];
      const Eigen::Vector2d o = T * Eigen::Vector2d(T_base_laser.translation().head<2>());
      tree.insertPointCloud(clouds[i],
                            octomap::point3d(o.x(), o.y(), T_base_laser.translation().z()));
      runs[r].octomap_points += static_cast<int64_t>(clouds[i].size());
    }
    runs[r].octomap_s = seconds_since(t0);
    // A small loop closure moves the second half of the trajectory by 2 mm and 1e-4 rad, then a
    // large one moves it by 5 cm.
    t0 = Clock::now();
    for (const auto& s : small_moved_segments) mapper.set_segment(s);
    runs[r].small_moved_profiles = static_cast<int64_t>(mapper.apply_moves());
    runs[r].small_move_s = seconds_since(t0);
    {  // The same small move with the changes found on two threads (the default).
      cfg.move_threads = 2;
      tm::Mapper two(cfg, T_base_laser);
      for (const auto& s : base_segments) two.set_segment(s);
      for (const auto& p : profiles) two.add_profile(p);
      t0 = Clock::now();
      for (const auto& s : small_moved_segments) two.set_segment(s);
      two.apply_moves();
      runs[r].small_move_2threads_s = seconds_since(t0);
    }
    t0 = Clock::now();
    for (const auto& s : moved_segments) mapper.set_segment(s);
    runs[r].moved_profiles = static_cast<int64_t>(mapper.apply_moves());
    runs[r].move_s = seconds_since(t0);
  }
  const double span_s =
      1e-6 * static_cast<double>(profiles.back().utime_last - profiles.front().utime_first);
  double pps[2], octo[2], ratio[2];
  for (int r = 0; r < 2; ++r) {
    pps[r] = runs[r].points / runs[r].mapper_s;
    octo[r] = runs[r].octomap_points / runs[r].octomap_s;
    ratio[r] = pps[r] / octo[r];
    std::printf(
        "%.0f cm: mapper %.0f points/s (%.0f beams/s, %lld points in %.2f s); insertPointCloud "
        "%.0f points/s (%lld points of the first %.1f s in %.2f s); ratio %.1f; %zu occupied "
        "voxels; moving %lld profiles took %.2f s by 2 mm and 1e-4 rad (%.2f s on two threads), "
        "%.2f s by 5 cm\n",
        100 * resolutions[r], pps[r], beams / runs[r].mapper_s,
        static_cast<long long>(runs[r].points), runs[r].mapper_s, octo[r],
        static_cast<long long>(runs[r].octomap_points), baseline_s, runs[r].octomap_s, ratio[r],
        runs[r].voxels, static_cast<long long>(runs[r].moved_profiles), runs[r].small_move_s,
        runs[r].small_move_2threads_s, runs[r].move_s);
  }
  const double bytes_per_s = runs[0].profile_bytes / span_s;
  std::printf("stored profiles: %.2f MB per s of data -> %.2f GB for a 30-minute session\n",
              bytes_per_s / 1e6, bytes_per_s * 1800 / 1e9);
  using traverse::json_fixed;
  traverse::Json j;
  j["bench"] = "mapper";
  j["route"] = route_file;
  j["profiles"] = profiles.size();
  j["data_s"] = json_fixed(span_s, 2);
  j["beams"] = static_cast<long long>(beams);
  j["points_per_s_2cm"] = json_fixed(pps[0], 0);
  j["points_per_s_5cm"] = json_fixed(pps[1], 0);
  j["beams_per_s_2cm"] = json_fixed(beams / runs[0].mapper_s, 0);
  j["beams_per_s_5cm"] = json_fixed(beams / runs[1].mapper_s, 0);
  j["octomap_points_per_s_2cm"] = json_fixed(octo[0], 0);
  j["octomap_points_per_s_5cm"] = json_fixed(octo[1], 0);
  j["ratio_to_octomap_2cm"] = json_fixed(ratio[0], 2);
  j["ratio_to_octomap_5cm"] = json_fixed(ratio[1], 2);
  j["octomap_baseline_s"] = json_fixed(baseline_s, 1);
  j["move_s_2cm"] = json_fixed(runs[0].move_s, 3);
  j["small_move_s_2cm"] = json_fixed(runs[0].small_move_s, 3);
  j["small_move_s_2cm_2threads"] = json_fixed(runs[0].small_move_2threads_s, 3);
  j["moved_profiles"] = static_cast<long long>(runs[0].moved_profiles);
  j["moved_profiles_per_s_2cm"] = json_fixed(runs[0].moved_profiles / runs[0].move_s, 0);
  j["small_moved_profiles_per_s_2cm"] =
      json_fixed(runs[0].small_moved_profiles / runs[0].small_move_s, 0);
  j["profile_bytes_per_s"] = json_fixed(bytes_per_s, 0);
  j["keeps_up_244k"] = beams / runs[0].mapper_s >= 244000 && beams / runs[1].mapper_s >= 244000;
  std::printf("%s\n", traverse::json_line(j).c_str());
  return 0;
}
