// traverse-export: turns a run into files other tools open. From the recorded run (an LCM log
// with KEY_POSES and DENSE_SEGMENTS, and POSE_GROUND_TRUTH when simulated) and the mapper's
// cloud.ply it writes, in the frame asked for:
//   trajectory.tum  the final dense trajectory in TUM format (evo and others read it)
//   trajectory.csv  the same with each pose's covariance, 95 % bound and level of accuracy
//   ground_truth.tum  the simulator's ground truth (reference.tum: a CARMEN log's reference poses)
//   cloud.las       LAS 1.4 (format 7: GPS time, intensity, accuracy colour as RGB; extra bytes
//                   loa_level, bound95_m, key_id), cloud.ply the same as binary PLY
// and prints one JSON summary line last.
#include <CLI/CLI.hpp>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "export_cloud.hpp"
#include "json.hpp"
#include "products.hpp"
#include "version.hpp"

namespace fs = std::filesystem;
namespace ex = traverse::exporter;

int main(int argc, char** argv) {
  CLI::App app(
      "Writes a run's trajectory (TUM, CSV with covariance) and cloud (LAS 1.4, PLY with accuracy "
      "colours) in the map frame or the simulator's world frame",
      "traverse-export");
  traverse::add_version_flag(app);
  std::string log, cloud, out = ".", frame = "map", reference = "POSE_GROUND_TRUTH";
  int thin = 1, top = 40, bottom = 20;
  bool no_cloud_ply = false;
  app.add_option("--log", log, "recorded run (LCM log with KEY_POSES, DENSE_SEGMENTS)")
      ->required()
      ->check(CLI::ExistingFile);
  app.add_option("--cloud", cloud, "the mapper's cloud.ply (omit: trajectories only)")
      ->check(CLI::ExistingFile);
  app.add_option("--out", out, "output folder")->capture_default_str();
  app.add_option("--frame", frame,
                 "map (the estimate's own frame) or world (tied to the simulator's ground truth "
                 "at the first pose)")
      ->check(CLI::IsMember({"map", "world"}))
      ->capture_default_str();
  app.add_option("--reference", reference,
                 "channel of the reference poses: the simulator's POSE_GROUND_TRUTH, or a CARMEN "
                 "log's POSE_REFERENCE (written as ground_truth.tum or reference.tum)")
      ->capture_default_str();
  app.add_option("--thin", thin, "keep every n-th point of the cloud")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--top-level", top, "USIBD LOA shown green (this level and better)")
      ->check(CLI::IsMember({10, 20, 30, 40, 50}))
      ->capture_default_str();
  app.add_option("--bottom-level", bottom, "USIBD LOA below which points are red")
      ->check(CLI::IsMember({10, 20, 30, 40, 50}))
      ->capture_default_str();
  app.add_flag("--no-cloud-ply", no_cloud_ply, "write the cloud as LAS only");
  CLI11_PARSE(app, argc, argv);
  if (bottom > top) {
    std::cerr << "traverse-export: --bottom-level " << bottom << " is above --top-level " << top
              << "\n";
    return 2;
  }

  ex::RunEstimate run;
  try {
    run = ex::read_run(log, reference);
  } catch (const std::exception& e) {
    std::cerr << "traverse-export: " << e.what() << "\n";
    return 1;
  }
  std::vector<ex::DensePose> dense = ex::dense_trajectory(run);
  if (dense.size() < 2) {
    std::cerr << "traverse-export: " << log << " holds " << dense.size()
              << " dense pose(s) on DENSE_SEGMENTS: nothing to export\n";
    return 1;
  }
  traverse::Pose2 T_out_map;
  const std::optional<traverse::Pose2> T_world_map = ex::world_from_map(run, dense);
  if (frame == "world") {
    if (!T_world_map) {
      std::cerr << "traverse-export: --frame world needs " << reference
                << " covering the first pose; " << log << " has none\n";
      return 1;
    }
    T_out_map = *T_world_map;
  }
  for (auto& p : dense) p = ex::transformed(p, T_out_map);

  std::error_code ec;
  fs::create_directories(out, ec);
  const fs::path dir(out);
  traverse::Json j;
  j["frame"] = frame;
  j["log"] = log;
  j["log_damaged_records"] = run.damaged_records;
  j["decode_failures"] = run.decode_failures;
  j["dense_poses"] = dense.size();
  j["key_poses"] = run.key_poses.size();
  j["segments"] = run.segments.size();
  if (T_world_map) {
    j["T_world_map"] = {
        {"x_m", T_world_map->x()}, {"y_m", T_world_map->y()}, {"theta_rad", T_world_map->theta()}};
  }
  auto file_entry = [](const fs::path& p) {
    std::error_code e;
    return traverse::Json{{"path", fs::absolute(p).string()},
                          {"bytes", static_cast<int64_t>(fs::file_size(p, e))}};
  };
  traverse::Json files = traverse::Json::object();
  bool ok = ex::write_tum((dir / "trajectory.tum").string(), dense, frame) &&
            ex::write_trajectory_csv((dir / "trajectory.csv").string(), dense, frame);
  files["trajectory_tum"] = file_entry(dir / "trajectory.tum");
  files["trajectory_csv"] = file_entry(dir / "trajectory.csv");
  if (!run.ground_truth.empty() && T_world_map) {
    // Ground truth in the same frame: world as it is, or the map frame through T_world_map^-1.
    const traverse::Pose2 T_frame_world =
        frame == "world" ? traverse::Pose2() : T_world_map->inverse();
    std::vector<ex::DensePose> gt;
    gt.reserve(run.ground_truth.size());
    for (const auto& [t, pose] : run.ground_truth) {
      ex::DensePose g;
      g.utime = t;
      g.pose = T_frame_world * pose;
      gt.push_back(g);
    }
    const std::string name =
        reference == "POSE_GROUND_TRUTH" ? "ground_truth.tum" : "reference.tum";
    ok = ok && ex::write_tum((dir / name).string(), gt, frame);
    files[name == "reference.tum" ? "reference_tum" : "ground_truth_tum"] = file_entry(dir / name);
  }
  if (!ok) {
    std::cerr << "traverse-export: cannot write the trajectories into " << out << "\n";
    return 1;
  }
  // Levels of the key poses (seed 004's 95 % bound against USIBD LOA).
  std::map<int, int> key_levels;
  double bound_max = 0;
  for (const auto& [id, k] : run.key_poses) {
    const double b = ex::bound95_m(k.covariance);
    bound_max = std::max(bound_max, b);
    ++key_levels[ex::loa_level(b)];
  }
  for (const auto& [level, n] : key_levels)
    j["key_poses_per_level"]["LOA" + std::to_string(level)] = n;
  j["key_pose_bound95_max_m"] = bound_max;

  if (!cloud.empty()) {
    ex::CloudOptions o;
    o.las_path = (dir / "cloud.las").string();
    if (!no_cloud_ply) o.ply_path = (dir / "cloud.ply").string();
    o.frame = frame;
    o.T_out_map = T_out_map;
    o.thin_every = thin;
    o.top_level = top;
    o.bottom_level = bottom;
    ex::CloudSummary s;
    std::string error;
    if (!ex::export_cloud(cloud, run, o, &s, &error)) {
      std::cerr << "traverse-export: " << error << "\n";
      return 1;
    }
    j["cloud_points_read"] = s.read;
    j["cloud_points_written"] = s.written;
    j["thin_every"] = thin;
    for (const auto& [level, n] : s.points_per_level) {
      j["cloud_points_per_level"]["LOA" + std::to_string(level)] = n;
    }
    files["cloud_las"] = file_entry(o.las_path);
    if (!no_cloud_ply) files["cloud_ply"] = file_entry(o.ply_path);
  }
  j["levels"] = {{"top", top}, {"bottom", bottom}};
  j["files"] = files;
  std::ofstream(dir / "export.json")
      << j.dump(2, ' ', true, traverse::Json::error_handler_t::replace) << "\n";
  std::cout << traverse::json_line(j) << std::endl;
  return 0;
}
