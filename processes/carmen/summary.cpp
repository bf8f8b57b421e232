#include "summary.hpp"

#include <fmt/format.h>

#include "json.hpp"

namespace traverse::carmen {

std::string survey_warnings(const Summary& s, const CarmenConfig& cfg, OdometrySource source) {
  std::string out;
  if (s.time.clock != Clock::kIpc) {
    out += fmt::format("the scans' ipc timestamps carry no time ({})", s.time.ipc_fault);
    if (s.time.clock == Clock::kLogger) {
      out += "; scans are timed by the logger timestamps\n";
    } else {
      out += fmt::format(
          "{}; scans are placed {} s apart (nominal_scan_period_s), as a log subsampled by "
          "travel\n",
          s.time.logger_fault.empty() ? "" : ", nor do the logger's (" + s.time.logger_fault + ")",
          cfg.nominal_scan_period_s);
    }
  }
  if (s.no_return && s.no_return->code_m <= cfg.range_max_m) {
    out += fmt::format(
        "no-return code {:.3f} m ({} beams, {:.2f} %) below range_max_m {} m: readings from it up "
        "are published as no return\n",
        s.no_return->code_m, s.no_return->beams, 100.0 * s.no_return->fraction, cfg.range_max_m);
  }
  if (s.max_beams_in_scan > cfg.max_beams) {
    out += fmt::format("scans of up to {} beams are thinned to at most max_beams {}\n",
                       s.max_beams_in_scan, cfg.max_beams);
  }
  if (source == OdometrySource::kOdom && s.odometry_reanchors > 0) {
    out += fmt::format(
        "{} ODOM lines restart the odometry at the pose of the scan before them (a corrected "
        "log): only the increments between them are used\n",
        s.odometry_reanchors);
  }
  if (source == OdometrySource::kOdom && s.odometry_out_of_order > 0) {
    out +=
        fmt::format("{} ODOM lines stamped out of line with their neighbours are not published\n",
                    s.odometry_out_of_order);
  }
  return out;
}

std::string summary_text(const Summary& s, const RunFacts& run) {
  std::string t = fmt::format("lines read:        {}\n", s.lines);
  for (const auto& [type, n] : s.scans_by_type) t += fmt::format("scans ({}): {}\n", type, n);
  t += fmt::format("scans published:   {}\nreference poses:   {}\nodometry ({}):   {}\n",
                   run.scans_published, run.poses_published,
                   odometry_source_name(run.odometry_source), run.odometry_published);
  t += fmt::format("log time span:     {:.3f} s\n", 1e-6 * (run.last_utime - run.first_utime));
  t += fmt::format("timestamps:        {}\n", clock_name(s.time.clock));
  if (run.odometry_behind_scans) {
    t += fmt::format("odometry dropped:  {} stamped before a scan already published\n",
                     run.odometry_behind_scans);
  }
  for (const auto& [type, n] : s.skipped_by_type)
    t += fmt::format("skipped {:<10} {} lines\n", type, n);
  t += fmt::format("malformed lines:   {}{}{}\n", s.malformed_count,
                   s.malformed_count ? ", first: " : "", s.first_malformed_reason);
  if (s.backwards_count) {
    t += fmt::format(
        "time going back:   {} scans stamped before the previous one (by up to {:.3f} s), "
        "restamped 1 us after it\n",
        s.backwards_count, 1e-6 * static_cast<double>(s.max_backstep_us));
  }
  if (s.no_return) {
    t += fmt::format("no-return code:    {:.3f} m ({} beams)\n", s.no_return->code_m,
                     s.no_return->beams);
  }
  if (!s.input_error.empty()) t += "input error:       " + s.input_error + "\n";
  return t;
}

std::string summary_json(const Summary& s, const RunFacts& run, const CarmenConfig& cfg) {
  Json j;
  j["scans"] = run.scans_published;
  j["reference_poses"] = run.poses_published;
  j["odometry"] = run.odometry_published;
  j["lines"] = s.lines;
  j["scans_by_type"] = Json(s.scans_by_type);
  j["odometry_lines"] = s.odometry;
  j["skipped_by_type"] = Json(s.skipped_by_type);
  j["malformed_count"] = s.malformed_count;
  j["malformed_lines"] = s.malformed_lines;
  j["malformed_lines_capped"] = s.malformed_count > static_cast<int64_t>(s.malformed_lines.size());
  j["timestamps"] = clock_name(s.time.clock);
  j["timestamps_fault"] = s.time.ipc_fault;
  j["logger_timestamps_fault"] = s.time.logger_fault;
  j["backwards_timestamps"] = s.backwards_count;
  j["backwards_lines"] = s.backwards_lines;
  j["max_backstep_us"] = s.max_backstep_us;
  j["timestamp_quantum_s"] = json_significant(s.max_quantum_s, 6);
  j["quantised_timestamps"] = s.quantised_count;
  j["restamped_from_logger"] = s.restamped_logger;
  j["restamped_nominal"] = s.restamped_nominal;
  j["nominal_scan_period_s"] = json_significant(cfg.nominal_scan_period_s, 6);
  j["no_return_code_m"] = s.no_return ? json_fixed(s.no_return->code_m, 3) : Json();
  j["no_return_beams"] = s.no_return ? s.no_return->beams : 0;
  j["max_beams_in_scan"] = s.max_beams_in_scan;
  j["scans_thinned"] = run.scans_thinned;
  j["odometry_source"] = odometry_source_name(run.odometry_source);
  j["odometry_reanchors"] = s.odometry_reanchors;
  j["odometry_out_of_order"] = s.odometry_out_of_order;
  j["odometry_behind_scans"] = run.odometry_behind_scans;
  j["odometry_velocity"] = s.odometry_velocity;
  j["first_utime"] = run.first_utime;
  j["last_utime"] = run.last_utime;
  j["wall_s"] = json_fixed(run.wall_s, 3);
  j["interrupted"] = run.interrupted;
  j["input_error"] = s.input_error;
  j["out"] = run.out_path;
  return json_line(j);
}

}  // namespace traverse::carmen
