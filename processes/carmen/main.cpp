// traverse-carmen: replays a CARMEN log (plain or .gz) as Traverse messages, either into an LCM
// log file (--out, byte-identical for the same input) or live on the bus at the log's own pace
// times --speed. Prints a summary with a JSON line last.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <thread>

#include "carmen_config.hpp"
#include "carmen_log.hpp"
#include "carmen_node.hpp"
#include "json_escape.hpp"
#include "process.hpp"
#include "publisher.hpp"

namespace {

using traverse::carmen::Summary;

// --out is known before parsing so that the file mode never needs a working network.
bool writes_log_file(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--out") == 0 || std::strncmp(argv[i], "--out=", 6) == 0) return true;
  }
  return false;
}

struct RunFacts {
  int64_t scans_published = 0;
  int64_t poses_published = 0;
  int64_t first_utime = 0;
  int64_t last_utime = 0;
  double wall_s = 0.0;
  bool interrupted = false;
};

void print_summary(const Summary& s, const RunFacts& run, const std::string& out_path,
                   double nominal_period_s) {
  std::printf("lines read:        %lld\n", static_cast<long long>(s.lines));
  for (const auto& [type, n] : s.scans_by_type) {
    std::printf("scans (%s): %lld\n", type.c_str(), static_cast<long long>(n));
  }
  std::printf("scans published:   %lld\nreference poses:   %lld\n",
              static_cast<long long>(run.scans_published),
              static_cast<long long>(run.poses_published));
  std::printf("log time span:     %.3f s\n", 1e-6 * (run.last_utime - run.first_utime));
  for (const auto& [type, n] : s.skipped_by_type) {
    std::printf("skipped %-10s %lld lines\n", type.c_str(), static_cast<long long>(n));
  }
  std::printf("malformed lines:   %lld%s%s\n", static_cast<long long>(s.malformed_count),
              s.malformed_count ? ", first: " : "", s.first_malformed_reason.c_str());
  if (s.backwards_count) {
    std::printf(
        "time going back:   %lld scans stamped before the previous one (by up to %.3f s), "
        "restamped 1 us after it\n",
        static_cast<long long>(s.backwards_count), 1e-6 * s.max_backstep_us);
  }
  if (s.quantised_count) {
    std::printf(
        "quantised time:    %lld scans stamped to %.6g s only: %lld restamped from the logger "
        "timestamp, %lld spaced at the nominal period\n",
        static_cast<long long>(s.quantised_count), s.max_quantum_s,
        static_cast<long long>(s.restamped_logger), static_cast<long long>(s.restamped_nominal));
  }
  if (!s.input_error.empty()) std::printf("input error:       %s\n", s.input_error.c_str());

  std::string j = "{\"scans\":" + std::to_string(run.scans_published) +
                  ",\"reference_poses\":" + std::to_string(run.poses_published) +
                  ",\"lines\":" + std::to_string(s.lines) + ",\"scans_by_type\":{";
  bool first = true;
  for (const auto& [type, n] : s.scans_by_type) {
    j += (first ? "\"" : ",\"") + traverse::json_escape(type) + "\":" + std::to_string(n);
    first = false;
  }
  j += "},\"skipped_by_type\":{";
  first = true;
  for (const auto& [type, n] : s.skipped_by_type) {
    j += (first ? "\"" : ",\"") + traverse::json_escape(type) + "\":" + std::to_string(n);
    first = false;
  }
  j += "},\"malformed_count\":" + std::to_string(s.malformed_count) + ",\"malformed_lines\":[";
  for (std::size_t i = 0; i < s.malformed_lines.size(); ++i) {
    if (i) j += ',';
    j += std::to_string(s.malformed_lines[i]);
  }
  j += "],\"malformed_lines_capped\":" +
       std::string(s.malformed_count > static_cast<int64_t>(s.malformed_lines.size()) ? "true"
                                                                                      : "false");
  j += ",\"backwards_timestamps\":" + std::to_string(s.backwards_count) + ",\"backwards_lines\":[";
  for (std::size_t i = 0; i < s.backwards_lines.size(); ++i) {
    if (i) j += ',';
    j += std::to_string(s.backwards_lines[i]);
  }
  j += "],\"max_backstep_us\":" + std::to_string(s.max_backstep_us);
  char quantum[160];
  std::snprintf(quantum, sizeof(quantum),
                ",\"timestamp_quantum_s\":%.6g,\"quantised_timestamps\":%lld,"
                "\"restamped_from_logger\":%lld,\"restamped_nominal\":%lld,"
                "\"nominal_scan_period_s\":%.6g",
                s.max_quantum_s, static_cast<long long>(s.quantised_count),
                static_cast<long long>(s.restamped_logger),
                static_cast<long long>(s.restamped_nominal), nominal_period_s);
  j += quantum;
  j += ",\"first_utime\":" + std::to_string(run.first_utime) +
       ",\"last_utime\":" + std::to_string(run.last_utime);
  char wall[64];
  std::snprintf(wall, sizeof(wall), "%.3f", run.wall_s);
  j += ",\"wall_s\":" + std::string(wall) +
       ",\"interrupted\":" + (run.interrupted ? "true" : "false") + ",\"input_error\":\"" +
       traverse::json_escape(s.input_error) + "\",\"out\":\"" + traverse::json_escape(out_path) +
       "\"}";
  std::printf("%s\n", j.c_str());
  std::fflush(stdout);
}

// Sleeps until wall time `target_utime` [us], publishing status meanwhile; false if stopped.
bool wait_until(traverse::Process& proc, int64_t target_utime) {
  while (!traverse::stop_requested()) {
    const int64_t left = target_utime - traverse::now_utime();
    if (left <= 0) return true;
    std::this_thread::sleep_for(std::chrono::microseconds(std::min<int64_t>(left, 100'000)));
    proc.maybe_publish_status();
  }
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  traverse::Process proc("carmen",
                         "Publishes a CARMEN robot log (plain or .gz) as Traverse "
                         "messages, live or into an LCM log file");
  std::string log_path, out_path;
  double speed = 1.0;
  proc.cli().add_option("LOG", log_path, "CARMEN log file (plain text or gzip)");
  proc.cli().add_option("--out", out_path, "write an LCM log file instead of publishing live");
  proc.cli()
      .add_option("--speed", speed, "live pace: log time x SPEED (0 = as fast as possible)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  traverse::carmen::CarmenConfig cfg;
  const bool to_file = writes_log_file(argc, argv);
  if (auto rc = proc.start(argc, argv, cfg, !to_file)) return *rc;  // validate(cfg) included
  const auto geometry = traverse::carmen::parse_flaser_geometry(cfg.flaser_geometry);
  if (log_path.empty()) {
    spdlog::error("traverse-carmen: no CARMEN log given (see --help)");
    return traverse::kConfigErrorExitCode;
  }
  traverse::carmen::Reader reader(log_path, *geometry,
                                  {cfg.max_timestamp_quantum_s, cfg.nominal_scan_period_s});
  if (!reader.good()) {
    spdlog::error("traverse-carmen: cannot read '{}'", log_path);
    return 1;
  }

  std::unique_ptr<traverse::LogFilePublisher> file;
  if (to_file) {
    try {
      file = std::make_unique<traverse::LogFilePublisher>(out_path);
    } catch (const std::exception& e) {
      spdlog::error("traverse-carmen: {}", e.what());
      return 1;
    }
  }
  traverse::Publisher& out = to_file ? static_cast<traverse::Publisher&>(*file) : proc.bus();

  RunFacts run;
  const int64_t wall_start = traverse::now_utime();
  if (!to_file) proc.publish_status("running");
  while (auto scan = reader.next()) {
    if (run.scans_published == 0) run.first_utime = scan->utime;
    if (!to_file && speed > 0.0 &&
        !wait_until(proc,
                    wall_start + static_cast<int64_t>((scan->utime - run.first_utime) / speed))) {
      break;
    }
    traverse::carmen::publish_scan(out, *scan, cfg);
    run.last_utime = scan->utime;
    ++run.scans_published;
    ++run.poses_published;
    proc.counter("scans_published") = static_cast<double>(run.scans_published);
    proc.counter("malformed_lines") = static_cast<double>(reader.summary().malformed_count);
    if (!to_file) proc.maybe_publish_status();
    if (traverse::stop_requested()) break;
  }
  run.interrupted = traverse::stop_requested();
  run.wall_s = 1e-6 * (traverse::now_utime() - wall_start);
  if (!to_file) {
    proc.publish_status(run.interrupted ? "stopping: interrupted" : "stopping: end of log");
  }
  file.reset();  // close the log before reporting
  const bool damaged = !reader.summary().input_error.empty();
  if (damaged) spdlog::error("traverse-carmen: {}", reader.summary().input_error);
  print_summary(reader.summary(), run, out_path,
                cfg.nominal_scan_period_s);  // JSON last, also when stderr is merged
  return damaged ? 1 : 0;
}
