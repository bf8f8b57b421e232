// traverse-preview-bench: what the mapper keeps to answer a late viewer over a whole route.
// Simulates the route (the tilted profiles, 30 Hz), places them with the true trajectory in the
// Mapper, takes the screen preview (preview.hpp) every second of data as the node does, and gives
// it to the capped store the node answers from (preview_resend.hpp). Prints, every
// --every seconds of data, what keeping every preview message (the node before the cap) would
// hold against what the store holds, then the answer a viewer asking at the end gets: its points
// and how much of the route's preview it covers. One JSON object last.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <set>

#include "bench_sim.hpp"
#include "json.hpp"
#include "preview_resend.hpp"
#include "version.hpp"

namespace {

namespace tm = traverse::mapper;
namespace ts = traverse::sim;

// Encoded bytes of a cloud_preview_t holding `profiles` (lcmtypes/cloud_preview_t.lcm): the
// fingerprint, utime, seq, parent_frame "map", cell_m and the count, then per profile its utime,
// count and three int16 per point. A decoded message held in memory takes more than this.
int64_t message_bytes(const std::vector<tm::PreviewProfile>& profiles) {
  int64_t bytes = 8 + 8 + 8 + (4 + 4) + 8 + 4;
  for (const auto& p : profiles) bytes += 8 + 4 + 6 * static_cast<int64_t>(p.p_base_mm.size());
  return bytes;
}

// The 2D cells of `cell_m` [m] that the profiles' points fall in (placed at first placement).
std::set<std::pair<int64_t, int64_t>> cells_2d(const std::vector<tm::PreviewProfile>& profiles,
                                               double cell_m) {
  std::set<std::pair<int64_t, int64_t>> out;
  for (const auto& p : profiles) {
    for (const auto& q : p.p_base_mm) {
      const Eigen::Vector2d w = p.T_world_base * Eigen::Vector2d(q[0] * 1e-3, q[1] * 1e-3);
      out.emplace(static_cast<int64_t>(std::floor(w.x() / cell_m)),
                  static_cast<int64_t>(std::floor(w.y() / cell_m)));
    }
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("traverse-preview-bench: memory kept for a late viewer over a whole route");
  std::string world_file = "configs/worlds/office.yaml",
              route_file = "configs/routes/office-x2.yaml", rig_file = "configs/rig.yaml";
  double duration_s = 0, every_s = 120, coverage_cell_m = 0.5;
  tm::PreviewConfig preview_config;
  app.add_option("--world", world_file);
  app.add_option("--route", route_file);
  app.add_option("--rig", rig_file);
  app.add_option("--duration", duration_s, "[s] of the route; 0: all of it");
  app.add_option("--every", every_s, "[s] of data between two printed lines");
  app.add_option("--resend-max-bytes", preview_config.resend_max_bytes, "[bytes] the cap");
  app.add_option("--coverage-cell", coverage_cell_m, "[m] 2D cells the coverage is counted in");
  bool inline_thinning = false;
  app.add_flag("--inline-thinning", inline_thinning,
               "thin inside add() (offline) instead of on a thread of its own (live)");
  traverse::add_version_flag(app);
  CLI11_PARSE(app, argc, argv);

  ts::RunOptions opt;
  opt.duration_s = duration_s;
  tm::BenchSim bench(world_file, route_file, rig_file, opt);

  tm::MapperConfig mapper_config;
  mapper_config.move_threads = 1;
  tm::Mapper mapper(mapper_config, bench.rig.laser_profile.transform());
  tm::CloudPreview preview(preview_config);
  mapper.on_first_placement(
      [&](int64_t t, const traverse::Pose2& T, const auto& pts) { preview.add(t, T, pts); });
  // As the live node: the passes on a thread of their own, merged once a second (--inline-thinning:
  // inside add(), as the node does offline).
  tm::PreviewResend resend(preview_config.cell_m, preview_config.resend_max_bytes,
                           !inline_thinning);
  std::vector<tm::PreviewProfile> everything;  // every profile sent live, for the coverage
  int64_t sent_bytes = 0, sent_points = 0, kept_max = 0, first_utime = -1, next_take = 0,
          next_print = 0;
  tm::TrajectorySegment open;
  const auto t0 = std::chrono::steady_clock::now();
  const auto take = [&] {
    resend.poll();
    for (auto& group : preview.take()) {
      sent_bytes += message_bytes(group);
      for (auto& p : group) {
        sent_points += static_cast<int64_t>(p.p_base_mm.size());
        resend.add(p);
        kept_max = std::max(kept_max, resend.bytes());
        everything.push_back(std::move(p));
      }
    }
  };
  while (auto e = bench.simulator->next()) {
    if (first_utime < 0) first_utime = e->utime;
    const double data_s = 1e-6 * static_cast<double>(e->utime - first_utime);
    if (e->kind == ts::SimEvent::Kind::kGroundTruth) {
      // The true trajectory in segments of 40 poses, as a pose stream reaches the mapper node.
      open.utimes.push_back(e->utime);
      open.T_world_base.push_back(e->ground_truth.T_world_base);
      if (open.utimes.size() > 40) {
        mapper.set_segment(open);
        tm::TrajectorySegment next;
        next.key_id_first = open.key_id_first + 1;
        next.utimes.push_back(open.utimes.back());
        next.T_world_base.push_back(open.T_world_base.back());
        open = std::move(next);
      }
    } else if (e->kind == ts::SimEvent::Kind::kScanProfile) {
      const tm::Profile p = tm::profile_of(e->scan);
      mapper.add_profile(p);
    }
    if (data_s >= next_take) {  // the node publishes its preview once a second
      take();
      next_take += 1;
    }
    if (data_s >= next_print) {
      std::printf(
          "%7.0f s of data: %9lld preview points sent; every message kept %8.2f MB, the "
          "capped store %6.2f MB (%lld points, cell %.2f m, %lld thinning passes)\n",
          data_s, static_cast<long long>(sent_points), sent_bytes / 1e6, resend.bytes() / 1e6,
          static_cast<long long>(resend.points()), resend.cell_m(),
          static_cast<long long>(resend.counters().compactions));
      std::fflush(stdout);
      next_print += every_s;
    }
  }
  mapper.set_segment(open);
  take();
  resend.wait();
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double data_s = next_take;

  // What a viewer asking now is sent, in messages of max_points_per_message points.
  resend.answer();
  std::vector<tm::PreviewProfile> answer;
  int64_t answer_points = 0, answer_bytes = 0;
  while (resend.resending()) {
    auto part = resend.next(static_cast<std::size_t>(preview_config.max_points_per_message));
    answer_bytes += message_bytes(part);
    for (auto& p : part) {
      answer_points += static_cast<int64_t>(p.p_base_mm.size());
      answer.push_back(std::move(p));
    }
  }
  const auto all_cells = cells_2d(everything, coverage_cell_m);
  const auto answer_cells = cells_2d(answer, coverage_cell_m);
  const double coverage =
      all_cells.empty() ? 0.0 : static_cast<double>(answer_cells.size()) / all_cells.size();
  std::printf(
      "%.0f s of data (%.0f s wall): every preview message kept %.2f MB (%lld points); "
      "the capped store %.2f MB (cap %.2f MB, largest %.2f MB), %lld points at one per "
      "%.2f m cell; %lld points thinned in %lld passes (longest %.1f ms, all %.1f ms wall; the "
      "caller held up %.2f ms at most, %.2f ms in all); a late "
      "viewer gets %lld points in %.2f MB, in %.1f %% of the %zu %.1f m cells of the route's "
      "preview\n",
      data_s, wall_s, sent_bytes / 1e6, static_cast<long long>(sent_points), resend.bytes() / 1e6,
      preview_config.resend_max_bytes / 1e6, kept_max / 1e6,
      static_cast<long long>(resend.points()), resend.cell_m(),
      static_cast<long long>(resend.counters().points_compacted),
      static_cast<long long>(resend.counters().compactions), 1e3 * resend.counters().compact_max_s,
      1e3 * resend.counters().compact_total_s, 1e3 * resend.counters().blocked_max_s,
      1e3 * resend.counters().blocked_total_s, static_cast<long long>(answer_points),
      answer_bytes / 1e6, 100 * coverage, all_cells.size(), coverage_cell_m);
  using traverse::json_fixed;
  traverse::Json j;
  j["bench"] = "preview";
  j["route"] = route_file;
  j["data_s"] = json_fixed(data_s, 0);
  j["preview_points_sent"] = static_cast<long long>(sent_points);
  j["preview_sent_bytes"] = static_cast<long long>(sent_bytes);
  j["resend_max_bytes"] = static_cast<long long>(preview_config.resend_max_bytes);
  j["resend_bytes"] = static_cast<long long>(resend.bytes());
  j["resend_bytes_max"] = static_cast<long long>(kept_max);
  j["resend_points"] = static_cast<long long>(resend.points());
  j["resend_cell_m"] = json_fixed(resend.cell_m(), 3);
  j["compactions"] = static_cast<long long>(resend.counters().compactions);
  j["points_compacted"] = static_cast<long long>(resend.counters().points_compacted);
  // [ms] wall time of the longest thinning pass and of all of them, wherever they ran.
  j["compact_max_ms"] = json_fixed(1e3 * resend.counters().compact_max_s, 1);
  j["compact_total_ms"] = json_fixed(1e3 * resend.counters().compact_total_s, 1);
  // [ms] what thinning held up the thread that adds (the mapper's message thread), at worst and
  // in all: the whole pass inline, the hand-over and the merge on a thread of its own.
  j["thinning"] = inline_thinning ? "inline" : "background";
  j["compact_blocked_max_ms"] = json_fixed(1e3 * resend.counters().blocked_max_s, 2);
  j["compact_blocked_total_ms"] = json_fixed(1e3 * resend.counters().blocked_total_s, 2);
  j["answer_points"] = static_cast<long long>(answer_points);
  j["answer_bytes"] = static_cast<long long>(answer_bytes);
  j["coverage_cell_m"] = json_fixed(coverage_cell_m, 2);
  j["answer_coverage"] = json_fixed(coverage, 4);
  std::printf("%s\n", traverse::json_line(j).c_str());
  return 0;
}
