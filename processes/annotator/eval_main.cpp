// traverse-annotator-eval: the annotator's bounds on a recorded run against the simulator's ground
// truth (coverage.hpp): coverage of the absolute and local 95 % bounds, the NEES of the backend's
// raw covariances and the covariance scale it asks for, and the mean true point error per level
// (seed 004's claim). Reads the newest KEY_POSES and ANNOTATIONS of every key pose, the ground
// truth, and the horizontal scan of each key pose (its points are the points the key pose
// placed). Prints a summary with units and one JSON object as the last line; --csv writes one row
// per key pose.
//
// --recompute CONFIG runs the annotator node (configs/annotator.yaml or another) on the log's
// KEY_POSES and POSE_GRAPH_EDGES, on an in-process bus, and evaluates its annotations instead of
// the recorded ones: a new calibration is evaluated without running the graph again.
// --compact OUT writes a small log holding only what this evaluation reads (the backend's and the
// annotator's channels, the ground truth and the scans of the key poses) and the backend's status
// (scripts/fit_marginal_scale.py reads the boresight's sigma from it), so a run's large log need
// not be kept.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <memory>
#include <set>

#include "annotator_node.hpp"
#include "bus.hpp"
#include "config.hpp"
#include "coverage.hpp"
#include "json.hpp"
#include "lcm_log.hpp"
#include "traverse/annotations_t.hpp"
#include "traverse/key_poses_t.hpp"
#include "traverse/planar_scan_t.hpp"
#include "traverse/pose2d_t.hpp"
#include "version.hpp"

namespace {

using traverse::annotator::KeyRecord;

template <class T>
bool decode(const traverse::LogEvent& e, T& msg) {
  return msg.decode(e.data.data(), 0, static_cast<int>(e.data.size())) ==
         static_cast<int>(e.data.size());
}

std::string num(double v) {
  if (!std::isfinite(v)) return "null";
  char b[32];
  std::snprintf(b, sizeof b, "%.6g", v);
  return b;
}

struct Options {
  std::string log, csv, key_poses = "KEY_POSES", annotations = "ANNOTATIONS",
                        truth = "POSE_GROUND_TRUTH", scans = "SCAN_HORIZONTAL",
                        backend_status = "STATUS_BACKEND";
  std::string recompute, compact, edges = "POSE_GRAPH_EDGES";
  bool compact_graph_only = false;
  int points_every = 10;
  double laser_x = 0.0, laser_y = 0.0, laser_yaw = 0.0;
};

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{"Annotator bounds against ground truth: coverage, NEES, point error per level"};
  app.add_option("--log", o.log, "recorded run (LCM log)")->required();
  app.add_option("--csv", o.csv, "write one row per key pose here");
  app.add_option("--key-poses", o.key_poses, "key_poses_t channel");
  app.add_option("--annotations", o.annotations, "annotations_t channel");
  app.add_option("--truth", o.truth, "ground-truth pose2d_t channel");
  app.add_option("--scans", o.scans, "horizontal planar_scan_t channel");
  app.add_option("--recompute", o.recompute,
                 "annotator config: recompute the annotations from the log's backend messages");
  app.add_option("--compact", o.compact, "write the events this evaluation reads into this log");
  app.add_option("--backend-status", o.backend_status,
                 "process_status_t channel --compact keeps (the boresight's sigma, which "
                 "scripts/fit_marginal_scale.py reads)");
  app.add_flag("--compact-graph-only", o.compact_graph_only,
               "--compact keeps only the backend's and the annotator's channels");
  app.add_option("--points-every", o.points_every, "use every Nth beam of a key pose's scan")
      ->check(CLI::PositiveNumber);
  app.add_option("--laser-x", o.laser_x, "[m] horizontal scanner in the base frame (rig.yaml)");
  app.add_option("--laser-y", o.laser_y, "[m]");
  app.add_option("--laser-yaw", o.laser_yaw, "[rad]");
  traverse::add_version_flag(app);
  CLI11_PARSE(app, argc, argv);

  std::map<int64_t, KeyRecord> keys;
  std::vector<traverse::annotator::StampedTruth> truth;
  double local_radius_m = 0.0, published_scale = 1.0;
  std::string coloured_by = "none", standard;
  std::vector<std::string> level_names;
  auto on_annotations = [&](const traverse::annotations_t& m) {
    local_radius_m = m.local_radius_m;
    published_scale = m.covariance_scale;
    coloured_by = m.coloured_by;
    standard = m.standard;
    level_names.clear();
    for (const auto& l : m.levels) level_names.push_back(l.name);
    for (const auto& a : m.keys) {
      KeyRecord& r = keys[a.id];
      r.bound_m = a.bound_m;
      r.local_bound_m = a.local_bound_m;
      r.level = a.level;
    }
  };
  // --recompute: the annotator node on an in-process bus, fed the backend's messages.
  std::unique_ptr<traverse::Bus> bus;
  std::unique_ptr<traverse::annotator::AnnotatorNode> node;
  if (!o.recompute.empty()) {
    traverse::annotator::AnnotatorNodeConfig config;
    try {
      traverse::load_config(o.recompute, config);
    } catch (const traverse::ConfigError& ex) {
      std::fprintf(stderr, "traverse-annotator-eval: %s\n", ex.what());
      return 2;
    }
    if (const auto problem = traverse::annotator::validate(config)) {
      std::fprintf(stderr, "traverse-annotator-eval: %s: %s\n", o.recompute.c_str(),
                   problem->c_str());
      return 2;
    }
    bus = std::make_unique<traverse::Bus>("memq://");
    node = std::make_unique<traverse::annotator::AnnotatorNode>(*bus, config);
    bus->subscribe<traverse::annotations_t>(config.annotations_channel, on_annotations, true);
  }
  auto handle_all = [&] {
    while (bus->lcm().handleTimeout(0) > 0) {
    }
  };
  std::unique_ptr<lcm::LogFile> compact;
  if (!o.compact.empty()) {
    compact = std::make_unique<lcm::LogFile>(o.compact, "w");
    if (!compact->good()) {
      std::fprintf(stderr, "traverse-annotator-eval: cannot write %s\n", o.compact.c_str());
      return 2;
    }
  }
  auto keep = [&](traverse::LogEvent& e) {
    if (!compact) return;
    lcm::LogEvent out;
    out.eventnum = e.event_number;
    out.timestamp = e.utime;
    out.channel = e.channel;
    out.datalen = static_cast<int32_t>(e.data.size());
    out.data = e.data.data();
    compact->writeEvent(&out);
  };
  // Pass 1: the newest key poses and annotations, the ground truth.
  int64_t events = 0;
  try {
    traverse::LogReader reader(o.log);
    while (auto e = reader.next()) {
      ++events;
      const bool backend = e->channel == o.key_poses || e->channel == o.edges;
      if (backend || e->channel == o.annotations || e->channel == o.backend_status) keep(*e);
      if (e->channel == o.truth && !o.compact_graph_only) keep(*e);
      if (node && backend) {
        bus->lcm().publish(e->channel, e->data.data(), static_cast<unsigned>(e->data.size()));
        handle_all();
      }
      if (e->channel == o.key_poses) {
        traverse::key_poses_t m;
        if (!decode(*e, m)) continue;
        for (const auto& k : m.poses) {
          KeyRecord& r = keys[k.id];
          r.id = k.id;
          r.utime = k.utime;
          r.T_world_base = traverse::Pose2(k.x, k.y, k.theta);
          for (int i = 0; i < 9; ++i) r.covariance(i / 3, i % 3) = k.covariance[i];
        }
      } else if (e->channel == o.annotations && !node) {
        traverse::annotations_t m;
        if (decode(*e, m)) on_annotations(m);
      } else if (e->channel == o.truth) {
        traverse::pose2d_t m;
        if (!decode(*e, m)) continue;
        if (truth.empty() || m.utime > truth.back().utime) {
          truth.push_back({m.utime, traverse::Pose2(m.x, m.y, m.theta)});
        }
      }
    }
    if (node) {
      node->finish();
      handle_all();
    }
    // Pass 2: the scan of each key pose (a key pose's time is its scan's last point).
    std::map<int64_t, int64_t> id_of_utime;
    for (const auto& [id, k] : keys) id_of_utime[k.utime] = id;
    const traverse::Pose2 T_base_laser(o.laser_x, o.laser_y, o.laser_yaw);
    traverse::LogReader scans(o.log);
    while (auto e = scans.next()) {
      if (e->channel != o.scans) continue;
      traverse::planar_scan_t m;
      if (!decode(*e, m)) continue;
      auto it = id_of_utime.find(m.utime_last);
      if (it == id_of_utime.end()) continue;
      if (!o.compact_graph_only) keep(*e);
      auto& pts = keys[it->second].points_base;
      pts.clear();
      for (int i = 0; i < m.n_ranges; i += o.points_every) {
        const double r = m.ranges[i];
        if (!(r >= m.range_min && r <= m.range_max)) continue;
        const double a = m.angle_first + i * m.angle_step;
        pts.push_back(T_base_laser * Eigen::Vector2d(r * std::cos(a), r * std::sin(a)));
      }
    }
  } catch (const std::exception& ex) {
    std::fprintf(stderr, "traverse-annotator-eval: %s\n", ex.what());
    return 2;
  }
  std::vector<KeyRecord> sorted;
  for (auto& [id, k] : keys) sorted.push_back(std::move(k));
  const auto r =
      traverse::annotator::evaluate_coverage(sorted, truth, local_radius_m, published_scale);

  if (!o.csv.empty()) {
    std::ofstream csv(o.csv);
    csv << "id,utime,bound_m,local_bound_m,level,sigma_max_raw_m\n";
    for (const KeyRecord& k : sorted) {
      const double l = k.covariance.topLeftCorner<2, 2>().trace();
      csv << k.id << ',' << k.utime << ',' << num(k.bound_m) << ',' << num(k.local_bound_m) << ','
          << k.level << ',' << num(std::sqrt(std::max(l, 0.0))) << '\n';
    }
  }
  std::printf("key poses with ground truth and a bound: %d (of %zu)\n", r.key_poses, sorted.size());
  std::printf("coverage of the 95 %% bound: %.3f (mean bound %.4f m, key pose RMSE %.4f m)\n",
              r.coverage, r.mean_bound_m, r.position_rmse_m);
  std::printf("local coverage (radius %.1f m): %.3f over %d key poses\n", local_radius_m,
              r.local_coverage, r.local_key_poses);
  std::printf("raw NEES (2 dof, 2 if consistent): mean %.3g, median %.3g, q95 %.3g\n", r.nees_mean,
              r.nees_median, r.nees_q95);
  const auto figure = [](double v) { return traverse::json_significant(v, 6); };
  traverse::Json levels = traverse::Json::array();
  for (const auto& f : r.levels) {
    const std::string name =
        f.level < static_cast<int>(level_names.size()) ? level_names[f.level] : "?";
    std::printf(
        "level %s: %d key poses, %lld points, mean true point error %.4f m, mean bound "
        "%.4f m\n",
        name.c_str(), f.key_poses, static_cast<long long>(f.points), f.mean_point_error_m,
        f.mean_bound_m);
    levels.push_back({{"level", name},
                      {"key_poses", f.key_poses},
                      {"points", f.points},
                      {"mean_point_error_m", figure(f.mean_point_error_m)},
                      {"mean_bound_m", figure(f.mean_bound_m)}});
  }
  const auto figures = [&](const std::vector<double>& v) {
    traverse::Json out = traverse::Json::array();
    for (double x : v) out.push_back(figure(x));
    return out;
  };
  traverse::Json j;
  j["log"] = o.log;
  j["events"] = events;
  j["key_poses"] = r.key_poses;
  j["coverage"] = figure(r.coverage);
  j["local_coverage"] = figure(r.local_coverage);
  j["local_key_poses"] = r.local_key_poses;
  j["local_radius_m"] = figure(local_radius_m);
  j["position_rmse_m"] = figure(r.position_rmse_m);
  j["mean_bound_m"] = figure(r.mean_bound_m);
  j["nees_mean"] = figure(r.nees_mean);
  j["nees_median"] = figure(r.nees_median);
  j["nees_q95"] = figure(r.nees_q95);
  j["scale_by_mean"] = figure(r.scale_by_mean);
  j["scale_by_q95"] = figure(r.scale_by_q95);
  j["scale_by_coverage"] = figure(r.scale_by_coverage);
  j["covariance_scale"] = figure(published_scale);
  j["coloured_by"] = coloured_by;
  j["standard"] = standard;
  j["levels"] = std::move(levels);
  j["levels_increasing"] = r.levels_increasing;
  j["nees"] = figures(r.nees);
  j["needed_scale"] = figures(r.needed_scale);
  std::printf("%s\n", traverse::json_line(j).c_str());
  return r.key_poses > 0 ? 0 : 1;
}
