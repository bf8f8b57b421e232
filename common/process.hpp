// The one main loop every Traverse process runs:
//   parse args -> load config -> connect LCM (exit 1 if not good) -> node subscribes -> spin
// until SIGINT/SIGTERM, publishing process_status_t once a second on STATUS_<NAME>; then the
// caller shuts its node down (flushing what must be written).
//
//   int main(int argc, char** argv) {
//     traverse::Process proc("frontend", "Hector-style scan-to-map matcher");
//     FrontendConfig cfg;
//     if (auto rc = proc.start(argc, argv, cfg)) return *rc;
//     FrontendNode node(proc.bus(), cfg);
//     return proc.spin();
//   }
#pragma once

#include <CLI/CLI.hpp>

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "bus.hpp"
#include "config.hpp"

namespace traverse {

// Wall-clock time in microseconds since the epoch.
int64_t now_utime();

// True once SIGINT or SIGTERM arrived (handlers installed by Process::start or install_stop_signals).
bool stop_requested();
void install_stop_signals();

class Process {
 public:
  Process(std::string name, std::string description);
  ~Process();

  // Add program-specific options here before start().
  CLI::App& cli() { return app_; }

  // Parses arguments, loads the config file given by --config (if any) into `config`, and
  // connects to LCM unless `connect` is false. Returns an exit code when the program must stop
  // now (0 after --help, 2 for a bad command line or config, 1 when LCM cannot start).
  template <class Config>
  std::optional<int> start(int argc, char** argv, Config& config, bool connect = true) {
    if (auto rc = parse(argc, argv)) return rc;
    try {
      if (!config_path_.empty()) load_config(config_path_, config);
    } catch (const ConfigError& e) {
      report_config_error(e);
      return kConfigErrorExitCode;
    }
    return connect ? this->connect() : std::nullopt;
  }

  Bus& bus() { return *bus_; }
  const std::string& name() const { return name_; }
  const std::string& config_path() const { return config_path_; }

  // Process-specific counters reported in the status (unit in the name: _s, _m, _bytes, or count).
  double& counter(const std::string& name) { return counters_[name]; }

  // Handles messages until a stop signal or `until()` returns true; calls tick() after each
  // wake-up (at least every 100 ms). Publishes status once a second and a last one when stopping.
  // Returns 0, or 1 if LCM failed.
  int spin(const std::function<void()>& tick = {}, const std::function<bool()>& until = {});

  // Publishes the status now (drivers with their own loop call this through maybe_publish_status).
  void publish_status(const std::string& state);
  void maybe_publish_status();

 private:
  std::optional<int> parse(int argc, char** argv);
  std::optional<int> connect();
  void report_config_error(const ConfigError& e) const;

  std::string name_;
  CLI::App app_;
  std::string config_path_;
  std::string lcm_url_;
  std::unique_ptr<Bus> bus_;
  std::map<std::string, double> counters_;
  int64_t start_utime_ = 0;
  int64_t last_status_utime_ = 0;
  int64_t status_seq_ = 0;
};

}  // namespace traverse
