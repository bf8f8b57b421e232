#include "summary.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "json_escape.hpp"

namespace traverse::carmen {
namespace {

std::string list(const std::vector<int64_t>& v) { return fmt::format("[{}]", fmt::join(v, ",")); }

std::string counts(const std::map<std::string, int64_t>& m) {
  std::string out = "{";
  for (const auto& [type, n] : m) {
    out += (out.size() > 1 ? ",\"" : "\"") + json_escape(type) + "\":" + std::to_string(n);
  }
  return out + "}";
}

std::string quoted(const std::string& s) { return fmt::format("\"{}\"", json_escape(s)); }

}  // namespace

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
  std::string j =
      "{\"scans\":" + std::to_string(run.scans_published) +
      ",\"reference_poses\":" + std::to_string(run.poses_published) +
      ",\"odometry\":" + std::to_string(run.odometry_published) +
      ",\"lines\":" + std::to_string(s.lines) + ",\"scans_by_type\":" + counts(s.scans_by_type) +
      ",\"odometry_lines\":" + std::to_string(s.odometry) +
      ",\"skipped_by_type\":" + counts(s.skipped_by_type) +
      ",\"malformed_count\":" + std::to_string(s.malformed_count) +
      ",\"malformed_lines\":" + list(s.malformed_lines) + ",\"malformed_lines_capped\":" +
      (s.malformed_count > static_cast<int64_t>(s.malformed_lines.size()) ? "true" : "false");
  j += ",\"timestamps\":" + quoted(clock_name(s.time.clock)) +
       ",\"timestamps_fault\":" + quoted(s.time.ipc_fault) +
       ",\"logger_timestamps_fault\":" + quoted(s.time.logger_fault);
  j += ",\"backwards_timestamps\":" + std::to_string(s.backwards_count) +
       ",\"backwards_lines\":" + list(s.backwards_lines) +
       ",\"max_backstep_us\":" + std::to_string(s.max_backstep_us);
  j += fmt::format(
      ",\"timestamp_quantum_s\":{:g},\"quantised_timestamps\":{},\"restamped_from_logger\":{},"
      "\"restamped_nominal\":{},\"nominal_scan_period_s\":{:g}",
      s.max_quantum_s, s.quantised_count, s.restamped_logger, s.restamped_nominal,
      cfg.nominal_scan_period_s);
  if (s.no_return) {
    j += fmt::format(",\"no_return_code_m\":{:.3f},\"no_return_beams\":{}", s.no_return->code_m,
                     s.no_return->beams);
  } else {
    j += ",\"no_return_code_m\":null,\"no_return_beams\":0";
  }
  j += fmt::format(",\"max_beams_in_scan\":{},\"scans_thinned\":{}", s.max_beams_in_scan,
                   run.scans_thinned);
  j += ",\"odometry_source\":" + quoted(odometry_source_name(run.odometry_source)) +
       ",\"odometry_reanchors\":" + std::to_string(s.odometry_reanchors) +
       ",\"odometry_out_of_order\":" + std::to_string(s.odometry_out_of_order) +
       ",\"odometry_behind_scans\":" + std::to_string(run.odometry_behind_scans) +
       ",\"odometry_velocity\":" + (s.odometry_velocity ? "true" : "false");
  j += ",\"first_utime\":" + std::to_string(run.first_utime) +
       ",\"last_utime\":" + std::to_string(run.last_utime);
  j += fmt::format(",\"wall_s\":{:.3f}", run.wall_s);
  j += std::string(",\"interrupted\":") + (run.interrupted ? "true" : "false") +
       ",\"input_error\":" + quoted(s.input_error) + ",\"out\":" + quoted(run.out_path) + "}";
  return j;
}

}  // namespace traverse::carmen
