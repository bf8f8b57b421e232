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
//
// Offline: `--replay IN.lcmlog [--record OUT.lcmlog]` runs the same node on a recorded log instead
// of a live bus, as fast as it computes and without transport loss: each event of IN is published
// on an in-process bus (memq://) and handled, with everything the node publishes in answer,
// before the next event. OUT receives every input and output message in that order, stamped with
// the time of the input event being handled, so the next process of the graph can replay it in
// turn and two replays of the same input give the same output.
//
// The LCM URL: --lcm-url wins; without it LCM_DEFAULT_URL from the environment is used, and the
// process says so at start (and warns when that URL lets messages leave the host, ttl above 0);
// without either, kDefaultLcmUrl (loopback only, ttl=0).
//
// Every config file may hold, beside the process's own keys, an `input:` section: the checks the
// bus makes on every message the process subscribes to (input_config.hpp).
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
#include "status_beat.hpp"

namespace traverse {

// Wall-clock time in microseconds since the epoch.
int64_t now_utime();

// The LCM URL a process uses and, when it is not the built-in default, a sentence saying where
// it came from (and whether it lets messages leave this host).
struct LcmUrlChoice {
  std::string url;
  std::string note;  // empty for the built-in default or an explicit --lcm-url with ttl=0
};
LcmUrlChoice choose_lcm_url(const std::string& cli_url, const char* env_url);

// True once SIGINT or SIGTERM arrived (handlers installed by Process::start or
// install_stop_signals).
bool stop_requested();
void install_stop_signals();

class Process {
 public:
  Process(std::string name, std::string description);
  ~Process();

  // Add program-specific options here before start().
  CLI::App& cli() { return app_; }
  // Adds --replay and --record (see above): for processes of the graph that consume messages.
  void offer_replay();

  // Parses arguments, loads the config file given by --config (if any) into `config`, checks it
  // with the stage's `validate(const Config&)` (found by argument-dependent lookup; see
  // ConfigCheck), and connects to LCM unless `connect` is false. Returns an exit code when the
  // program must stop now (0 after --help, 2 for a bad command line or config, naming the key
  // and the file, 1 when LCM cannot start).
  template <class Config>
  std::optional<int> start(int argc, char** argv, Config& config, bool connect = true) {
    if (auto rc = parse(argc, argv)) return rc;
    try {
      if (!config_path_.empty()) {
        WithInput<Config> both{config, input_};
        load_config(config_path_, both);
        ConfigCheck check;
        check.nested("input", validate_input(input_));
        if (check.problem()) throw ConfigError(config_path_ + ": " + *check.problem());
      }
      if (const std::optional<std::string> problem = config_detail::validate_stage(config)) {
        throw ConfigError((config_path_.empty() ? "default config" : config_path_) + ": " +
                          *problem);
      }
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
  // wake-up (at least every 100 ms). Publishes status once a second and a last one when stopping;
  // live, the status keeps beating while a step takes longer (status_beat.hpp).
  // Returns 0, or 1 if LCM failed.
  int spin(const std::function<void()>& tick = {}, const std::function<bool()>& until = {});

  // True when the input is a recorded log (--replay), not a live bus.
  bool replaying() const { return !replay_path_.empty(); }

  // Publishes the status now (drivers with their own loop call this through maybe_publish_status).
  void publish_status(const std::string& state);
  void maybe_publish_status();

 private:
  // A process's config and the `input:` section every process accepts, read from one file.
  template <class Config>
  struct WithInput {
    Config& config;
    InputConfig& input;
    template <class V>
    void visit(V& v) {
      config.visit(v);
      v("input", input);
    }
  };
  std::optional<int> parse(int argc, char** argv);
  std::optional<int> connect();
  void report_config_error(const ConfigError& e) const;
  int replay(const std::function<void()>& tick, const std::function<bool()>& until);
  void drain();  // handles every queued in-process message (replay only)

  std::string name_;
  CLI::App app_;
  std::string config_path_;
  std::string lcm_url_;
  InputConfig input_;
  std::unique_ptr<Bus> bus_;
  std::unique_ptr<StatusBeat> beat_;  // after bus_: stops before the bus goes
  std::string replay_path_;
  std::string record_path_;
  struct Recorder;
  std::unique_ptr<Recorder> recorder_;
  std::map<std::string, double> counters_;
  int64_t start_utime_ = 0;
  int64_t last_status_utime_ = 0;
};

}  // namespace traverse
