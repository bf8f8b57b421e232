// traverse-record: writes every message of the LCM bus into a log file (as lcm-logger, without
// its losses: recorder.hpp), until SIGINT or SIGTERM; then prints a JSON line: events and bytes
// written, messages left out by channel, messages its receive queue dropped, write errors.
// Exits 0 after a clean recording, 1 if LCM failed, the file could not be opened or a write
// failed, 2 for a bad command line (an existing file without --force, a --without that is no
// regular expression) or config.
//
//   traverse-record run.lcmlog [--without 'SCAN_PROFILE|IMU'] [--force] [--lcm-url URL]
#include <spdlog/spdlog.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <regex>
#include <stdexcept>
#include <string>

#include "json.hpp"
#include "process.hpp"
#include "recorder.hpp"

int main(int argc, char** argv) {
  using Clock = std::chrono::steady_clock;
  traverse::Process proc("record",
                         "Writes every message of the LCM bus into an LCM log file, stamped with "
                         "the time it was received, until SIGINT/SIGTERM.");
  traverse::record::RecordConfig cfg;
  std::string path, without;
  bool force = false;
  proc.cli().add_option("log", path, "the LCM log to write")->required();
  proc.cli()
      .add_option("--without", without,
                  "channels left out: a regular expression the whole channel name matches")
      ->check([](const std::string& s) -> std::string {
        try {
          std::regex r(s, std::regex::ECMAScript);
          return {};
        } catch (const std::regex_error& e) {
          return "not a regular expression: " + std::string(e.what());
        }
      });
  proc.cli().add_flag("--force", force, "replace the log if it exists");
  if (auto rc = proc.start(argc, argv, cfg)) return *rc;
  if (!force && std::filesystem::exists(path)) {
    spdlog::error("traverse-record: {} exists (--force replaces it)", path);
    return traverse::kConfigErrorExitCode;
  }

  std::unique_ptr<traverse::record::Recorder> recorder;
  try {
    recorder = std::make_unique<traverse::record::Recorder>(proc.bus(), path, without);
  } catch (const std::exception& e) {
    spdlog::error("traverse-record: {}", e.what());
    return 1;
  }
  auto counters = [&] {
    proc.counter("events_written") = static_cast<double>(recorder->events());
    proc.counter("written_bytes") = static_cast<double>(recorder->bytes());
    proc.counter("events_left_out") = static_cast<double>(recorder->skipped());
    proc.counter("write_errors") = static_cast<double>(recorder->write_errors());
  };
  auto flushed = Clock::now();
  int rc = proc.spin([&] {
    if (Clock::now() - flushed >= std::chrono::milliseconds(100)) {  // as lcm-logger
      recorder->flush();
      flushed = Clock::now();
    }
    counters();
  });
  // What the bus received before the stop and has not handed over yet.
  for (int i = 0; i < 3; ++i) proc.bus().handle(i == 0 ? 0 : 50);
  recorder->flush();
  counters();

  traverse::Json j;
  j["log"] = path;
  j["events_written"] = recorder->events();
  j["written_bytes"] = recorder->bytes();
  j["events_left_out"] = recorder->skipped();
  j["receive_queue_dropped"] = proc.bus().queue_dropped();
  j["write_errors"] = recorder->write_errors();
  std::puts(traverse::json_line(j).c_str());
  std::fflush(stdout);
  if (recorder->write_errors() > 0) {
    spdlog::error("traverse-record: {} events could not be written to {}", recorder->write_errors(),
                  path);
    rc = 1;
  }
  return rc;
}
