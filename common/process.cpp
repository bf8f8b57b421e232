#include "process.hpp"

#include <signal.h>
#include <spdlog/spdlog.h>
#include <sys/resource.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <lcm/lcm-cpp.hpp>

#include "channels.hpp"
#include "lcm_log.hpp"
#include "traverse/process_status_t.hpp"
#include "version.hpp"

namespace traverse {
namespace {

std::atomic<bool> g_stop{false};

void on_stop_signal(int) { g_stop = true; }

double cpu_seconds() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return ru.ru_utime.tv_sec + ru.ru_stime.tv_sec +
         1e-6 * (ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}

int64_t resident_bytes() {
  std::ifstream statm("/proc/self/statm");
  int64_t size_pages = 0, resident_pages = 0;
  statm >> size_pages >> resident_pages;
  return resident_pages * sysconf(_SC_PAGESIZE);
}

// The deployment's name for this machine when a launcher started the process (TRAVERSE_HOST),
// otherwise the system's host name.
std::string host_name() {
  if (const char* deployed = std::getenv("TRAVERSE_HOST"); deployed && *deployed) return deployed;
  char buf[256] = {};
  gethostname(buf, sizeof(buf) - 1);
  return buf;
}

}  // namespace

LcmUrlChoice choose_lcm_url(const std::string& cli_url, const char* env_url) {
  LcmUrlChoice c;
  if (!cli_url.empty()) {
    c.url = cli_url;
  } else if (env_url && *env_url) {
    c.url = env_url;
    c.note = "LCM URL " + c.url + " from LCM_DEFAULT_URL (not the built-in " + kDefaultLcmUrl +
             "; --lcm-url overrides both)";
  } else {
    c.url = kDefaultLcmUrl;
  }
  // LCM's udpm sends with ttl 0 (this host only) unless the URL says otherwise.
  const auto at = c.url.find("ttl=");
  if (c.url.rfind("udpm://", 0) == 0 && at != std::string::npos) {
    const std::string ttl = c.url.substr(at + 4, c.url.find('&', at) - at - 4);
    if (ttl != "0") {
      if (!c.note.empty()) c.note += "; ";
      c.note += "ttl=" + ttl + ": messages leave this host";
    }
  }
  return c;
}

int64_t now_utime() {
  using namespace std::chrono;
  return duration_cast<microseconds>(system_clock::now().time_since_epoch()).count();
}

bool stop_requested() { return g_stop; }

void install_stop_signals() {
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

Process::Process(std::string name, std::string description)
    : name_(std::move(name)), app_(std::move(description), "traverse-" + name_) {
  app_.add_option("--config", config_path_, "YAML config file (defaults apply to absent keys)");
  app_.add_option("--lcm-url", lcm_url_,
                  std::string("LCM provider URL (default: LCM_DEFAULT_URL if set, else ") +
                      kDefaultLcmUrl + ")");
  app_.add_option("--name", name_, "instance name; status goes to STATUS_<NAME>")
      ->capture_default_str();
  add_version_flag(app_);
}

void Process::offer_replay() {
  auto* replay = app_.add_option("--replay", replay_path_,
                                 "offline: read this LCM log as input instead of a live bus, as "
                                 "fast as the process runs (in-process bus, no loss)");
  replay->check(CLI::ExistingFile);
  app_.add_option("--record", record_path_,
                  "with --replay: write every input and output message to this LCM log")
      ->needs(replay);
}

// Writes every message of the in-process bus to the --record log, stamped with the time of the
// input event being handled.
struct Process::Recorder {
  std::unique_ptr<LogWriter> log;
  int64_t utime = 0;  // [us] time of the input event being handled

  void on_message(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    log->write(channel, static_cast<const uint8_t*>(rbuf->data), rbuf->data_size, utime);
  }
};

Process::~Process() {
  if (bus_ && replaying()) drain();  // what the node published last (finish, "stopped" status)
}

std::optional<int> Process::parse(int argc, char** argv) {
  try {
    app_.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app_.exit(e);  // prints help (rc 0) or the error
    return rc == 0 ? 0 : kConfigErrorExitCode;
  }
  install_stop_signals();
  start_utime_ = now_utime();
  return std::nullopt;
}

void Process::report_config_error(const ConfigError& e) const {
  spdlog::error("traverse-{}: config error: {}", name_, e.what());
}

std::optional<int> Process::connect() {
  if (replaying()) {
    lcm_url_ = "memq://";
  } else {
    const LcmUrlChoice choice = choose_lcm_url(lcm_url_, std::getenv("LCM_DEFAULT_URL"));
    lcm_url_ = choice.url;
    if (!choice.note.empty()) spdlog::warn("traverse-{}: {}", name_, choice.note);
  }
  bus_ = std::make_unique<Bus>(lcm_url_, input_);
  if (!bus_->good()) {
    spdlog::error("traverse-{}: cannot start LCM with URL '{}'", name_, lcm_url_);
    return 1;
  }
  beat_ = std::make_unique<StatusBeat>(bus_->lcm(), channels::status_channel(name_),
                                       [start = start_utime_](process_status_t& st) {
                                         st.utime = now_utime();
                                         st.uptime_s = 1e-6 * static_cast<double>(st.utime - start);
                                         st.cpu_s = cpu_seconds();
                                         st.rss_bytes = resident_bytes();
                                       });
  if (!record_path_.empty()) {
    recorder_ = std::make_unique<Recorder>();
    recorder_->log = std::make_unique<LogWriter>(record_path_);
    if (!recorder_->log->good()) {
      spdlog::error("traverse-{}: cannot write --record {}", name_, record_path_);
      return 1;
    }
    bus_->lcm()
        .subscribe(".*", &Recorder::on_message, recorder_.get())
        ->setQueueCapacity(Bus::kLcmQueueMessages);
  }
  return std::nullopt;
}

void Process::drain() {
  while (bus_->lcm().handleTimeout(0) > 0) {
  }
}

int Process::replay(const std::function<void()>& tick, const std::function<bool()>& until) {
  std::unique_ptr<LogReader> reader;
  try {
    reader = std::make_unique<LogReader>(replay_path_);
  } catch (const std::exception& e) {
    spdlog::error("traverse-{}: --replay: {}", name_, e.what());
    return 1;
  }
  publish_status("running");
  drain();
  long events = 0;
  while (!g_stop && !(until && until())) {
    std::optional<LogEvent> ev = reader->next();
    if (!ev) break;
    ++events;
    counters_["replay_events"] = static_cast<double>(events);
    if (recorder_) recorder_->utime = ev->utime;
    if (bus_->lcm().publish(ev->channel, ev->data.data(),
                            static_cast<unsigned int>(ev->data.size())) != 0) {
      spdlog::error("traverse-{}: --replay: cannot publish event {} ({} bytes on {})", name_,
                    ev->event_number, ev->data.size(), ev->channel);
      return 1;
    }
    drain();
    if (tick) tick();
    maybe_publish_status();
    drain();
  }
  for (const LogDamage& d : reader->damage()) {
    spdlog::warn("traverse-{}: --replay {}: {} at byte {} ({} bytes skipped)", name_, replay_path_,
                 d.what, d.offset, d.skipped_bytes);
  }
  spdlog::info("traverse-{}: replayed {} events of {}", name_, events, replay_path_);
  // In the status, so that a run's verdict sees what the input lost (and an empty input).
  counters_["replay_events"] = static_cast<double>(events);
  counters_["replay_damaged_records"] = static_cast<double>(reader->damage().size());
  publish_status("stopping");
  drain();
  return 0;
}

int Process::spin(const std::function<void()>& tick, const std::function<bool()>& until) {
  if (replaying()) return replay(tick, until);
  publish_status("running");
  beat_->start();
  int rc = 0;
  while (!g_stop && !(until && until())) {
    if (!bus_->handle(100)) {
      if (g_stop) break;  // interrupted by the stop signal
      spdlog::error("traverse-{}: LCM failed while handling messages", name_);
      rc = 1;
      break;
    }
    if (tick) tick();
    maybe_publish_status();
  }
  beat_->stop();
  publish_status("stopping");
  return rc;
}

void Process::maybe_publish_status() {
  if (now_utime() - last_status_utime_ >= 1'000'000) publish_status("running");
}

void Process::publish_status(const std::string& state) {
  if (!bus_ || !beat_) return;
  process_status_t st;
  st.utime = now_utime();
  last_status_utime_ = st.utime;
  st.process = name_;
  st.host = host_name();
  st.pid = getpid();
  st.uptime_s = 1e-6 * (st.utime - start_utime_);
  st.cpu_s = cpu_seconds();
  st.rss_bytes = resident_bytes();
  st.state = state;
  for (const auto& [channel, s] : bus_->stats()) {
    channel_stats_t c;
    c.channel = channel;
    c.received = s.received;
    c.published = s.published;
    c.decode_failures = s.decode_failures;
    c.out_of_order = s.out_of_order;
    c.missed = s.missed;
    c.handler_errors = s.handler_errors;
    c.last_utime = s.last_utime;
    st.channels.push_back(c);
  }
  st.n_channels = static_cast<int32_t>(st.channels.size());
  for (const auto& [k, v] : counters_) {
    st.counter_names.push_back(k);
    st.counter_values.push_back(v);
  }
  // What channel_stats_t has no field for: "<CHANNEL>/rejected" and so on, when not zero.
  for (const auto& [channel, s] : bus_->stats()) {
    for (const auto& [what, n] :
         {std::pair{"rejected", s.rejected}, std::pair{"stamp_outliers", s.stamp_outliers},
          std::pair{"time_jumps", s.time_jumps}}) {
      if (n == 0) continue;
      st.counter_names.push_back(channel + "/" + what);
      st.counter_values.push_back(static_cast<double>(n));
    }
  }
  // The bus's receive queue (network bus): how far handling fell behind, and what it dropped.
  st.counter_names.push_back("receive_queue_max_bytes");
  st.counter_values.push_back(static_cast<double>(bus_->queue_max_bytes()));
  st.counter_names.push_back("receive_queue_dropped");
  st.counter_values.push_back(static_cast<double>(bus_->queue_dropped()));
  st.n_counters = static_cast<int32_t>(st.counter_names.size());
  const int64_t utime = st.utime;
  const int64_t seq = beat_->send(std::move(st));
  bus_->note_published(channels::status_channel(name_), utime, seq);
}

}  // namespace traverse
