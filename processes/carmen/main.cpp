// traverse-carmen: replays a CARMEN log (plain or .gz) as Traverse messages, either into an LCM
// log file (--out, byte-identical for the same input) or live on the bus at the log's own pace
// times --speed. Prints a summary with a JSON line last.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <memory>
#include <sstream>
#include <string>
#include <thread>

#include "carmen_config.hpp"
#include "carmen_node.hpp"
#include "log_reader.hpp"
#include "process.hpp"
#include "publisher.hpp"
#include "summary.hpp"

namespace {

namespace carmen = traverse::carmen;

// --out is known before parsing so that the file mode never needs a working network.
bool writes_log_file(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--out") == 0 || std::strncmp(argv[i], "--out=", 6) == 0) return true;
  }
  return false;
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

void set_survey_counters(traverse::Process& proc, const carmen::Summary& s) {
  proc.counter("timestamps_without_time") = s.time.clock == carmen::Clock::kIpc ? 0.0 : 1.0;
  proc.counter("scans_restamped_logger") = static_cast<double>(s.restamped_logger);
  proc.counter("scans_restamped_nominal") = static_cast<double>(s.restamped_nominal);
  proc.counter("no_return_code_m") = s.no_return ? s.no_return->code_m : 0.0;
  proc.counter("odometry_reanchors") = static_cast<double>(s.odometry_reanchors);
  proc.counter("odometry_out_of_order") = static_cast<double>(s.odometry_out_of_order);
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
  carmen::CarmenConfig cfg;
  const bool to_file = writes_log_file(argc, argv);
  if (auto rc = proc.start(argc, argv, cfg, !to_file)) return *rc;  // validate(cfg) included
  if (log_path.empty()) {
    spdlog::error("traverse-carmen: no CARMEN log given (see --help)");
    return traverse::kConfigErrorExitCode;
  }
  carmen::Reader reader(log_path, *carmen::parse_flaser_geometry(cfg.flaser_geometry),
                        {cfg.max_timestamp_quantum_s, cfg.nominal_scan_period_s},
                        {cfg.no_return_code_m, cfg.no_return_min_fraction});
  if (!reader.good()) {
    spdlog::error("traverse-carmen: cannot read '{}'", log_path);
    return 1;
  }
  const carmen::Summary survey = reader.summary();
  carmen::RunFacts run;
  run.out_path = out_path;
  run.odometry_source = carmen::choose_odometry_source(cfg.odometry_source, survey);
  std::istringstream warnings(carmen::survey_warnings(survey, cfg, run.odometry_source));
  for (std::string line; std::getline(warnings, line);) {
    spdlog::warn("traverse-carmen: {}: {}", log_path, line);
  }
  set_survey_counters(proc, survey);

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
  // Live, each message waits for its time: the log's pace times --speed, from the first message.
  const int64_t wall_start = traverse::now_utime();
  std::optional<int64_t> first_utime;
  bool stopped = false;
  auto pace = [&](int64_t utime) {
    if (!first_utime) first_utime = utime;
    if (to_file || speed <= 0.0 || stopped) return;
    stopped = !wait_until(proc, wall_start + static_cast<int64_t>((utime - *first_utime) / speed));
  };
  carmen::Driver driver(out, cfg, run.odometry_source, survey, pace);
  if (!to_file) proc.publish_status("running");
  while (auto record = reader.next_record()) {
    driver.publish(*record);
    if (const auto* scan = std::get_if<carmen::Scan>(&*record)) {
      if (driver.scans() == 1) run.first_utime = scan->utime;
      run.last_utime = scan->utime;
    }
    proc.counter("scans_published") = static_cast<double>(driver.scans());
    proc.counter("odometry_published") = static_cast<double>(driver.odometry());
    proc.counter("odometry_behind_scans") = static_cast<double>(driver.odometry_behind_scans());
    proc.counter("scans_thinned") = static_cast<double>(driver.scans_thinned());
    if (!to_file) proc.maybe_publish_status();
    if (traverse::stop_requested()) break;
  }
  if (!traverse::stop_requested()) driver.finish();
  run.scans_published = run.poses_published = driver.scans();
  run.odometry_published = driver.odometry();
  run.scans_thinned = driver.scans_thinned();
  run.odometry_behind_scans = driver.odometry_behind_scans();
  run.interrupted = traverse::stop_requested();
  run.wall_s = 1e-6 * static_cast<double>(traverse::now_utime() - wall_start);
  const carmen::Summary& summary = reader.summary();
  proc.counter("malformed_lines") = static_cast<double>(summary.malformed_count);
  if (!to_file) {
    proc.publish_status(run.interrupted ? "stopping: interrupted" : "stopping: end of log");
  }
  file.reset();  // close the log before reporting
  const bool damaged = !summary.input_error.empty();
  if (damaged) spdlog::error("traverse-carmen: {}", summary.input_error);
  std::fputs(carmen::summary_text(summary, run).c_str(), stdout);
  std::printf("%s\n", carmen::summary_json(summary, run, cfg).c_str());  // JSON last
  std::fflush(stdout);
  return damaged ? 1 : 0;
}
