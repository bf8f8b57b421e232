// End to end: traverse-record on a private udpm port keeps a burst that LCM's default queue of
// 30 messages per subscription (which Debian's lcm-logger keeps) would cut, leaves out the
// channels it is told to, says what it wrote, and leaves a readable log when killed.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <sstream>
#include <string>
#include <thread>

#include "bus.hpp"
#include "json.hpp"
#include "lcm_log.hpp"
#include "traverse/process_status_t.hpp"

namespace traverse {
namespace {

namespace fs = std::filesystem;

const std::string kRecord = std::string(TRAVERSE_BIN_DIR) + "/traverse-record";

std::string url_on(int port) {
  return "udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0&recv_buf_size=8388608";
}

fs::path temp_path(const std::string& what) {
  return fs::temp_directory_path() / ("traverse_record_" + what + "_" + std::to_string(::getpid()));
}

std::string read_file(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

int run(const std::string& command) {
  const int status = std::system((command + " > /dev/null 2>&1").c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// Starts the recorder on `url` writing `log` (stdout to `out`), with `extra` arguments.
pid_t start_recorder(const std::string& url, const fs::path& log, const fs::path& out,
                     const std::vector<std::string>& extra) {
  const pid_t pid = fork();
  if (pid == 0) {
    std::freopen(out.c_str(), "w", stdout);
    std::freopen("/dev/null", "w", stderr);
    std::vector<std::string> args = {kRecord,  "--lcm-url",   url,
                                     "--name", "record_test", log.string()};
    args.insert(args.end(), extra.begin(), extra.end());
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    execv(kRecord.c_str(), argv.data());
    _exit(127);
  }
  return pid;
}

// Waits for the recorder's status (STATUS_RECORD_TEST) satisfying `done`, up to `seconds`.
template <class F>
bool wait_status(Bus& bus, F done, int seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(seconds);
  bool ok = false;
  auto handle = bus.subscribe_raw("STATUS_RECORD_TEST",
                                  [&](const std::string&, const uint8_t* data, int size, int64_t) {
                                    process_status_t st;
                                    if (st.decode(data, 0, size) > 0 && done(st)) ok = true;
                                  });
  while (!ok && std::chrono::steady_clock::now() < end) bus.handle(50);
  bus.unsubscribe(handle);
  return ok;
}

double counter(const process_status_t& st, const std::string& name) {
  for (std::size_t i = 0; i < st.counter_names.size(); ++i) {
    if (st.counter_names[i] == name) return st.counter_values[i];
  }
  return -1;
}

// A recorder on a port of its own writing a fresh temporary log, and a bus on the same URL that
// heard its first status (`up`).
struct Running {
  std::string url;
  fs::path log, out;
  std::unique_ptr<Bus> bus;
  pid_t pid = -1;
  bool up = false;

  Running(int port, const std::string& what, const std::vector<std::string>& extra)
      : url(url_on(port)), log(temp_path(what + ".lcmlog")), out(temp_path(what + ".out")) {
    fs::remove(log);
    bus = std::make_unique<Bus>(url);
    if (!bus->good()) return;
    pid = start_recorder(url, log, out, extra);
    up = pid > 0 && wait_status(
                        *bus, [](const process_status_t&) { return true; }, 10);
  }
  // Stops it with `signal`; true if it then exited with 0.
  bool stop(int signal) {
    kill(pid, signal);
    int wstatus = 0;
    waitpid(pid, &wstatus, 0);
    return WIFEXITED(wstatus) && WEXITSTATUS(wstatus) == 0;
  }
  ~Running() {
    fs::remove(log);
    fs::remove(out);
  }
};

TEST(RecordProgram, BadArgumentsLoseNothing) {
  EXPECT_EQ(run(kRecord + " --help"), 0);
  EXPECT_EQ(run(kRecord), 2);  // no log named
  const fs::path log = temp_path("existing");
  std::ofstream(log) << "what the user had";
  const std::string url = url_on(31481);
  EXPECT_EQ(run(kRecord + " --lcm-url '" + url + "' " + log.string()), 2);
  EXPECT_EQ(run(kRecord + " --lcm-url '" + url + "' --force --without '(' " + log.string()), 2);
  EXPECT_EQ(read_file(log), "what the user had");
  fs::remove(log);
}

TEST(RecordProgram, KeepsABurstAndLeavesOutWhatItIsTold) {
  Running rec(31482, "burst", {"--without", "SKIP_.*"});
  const bool up = rec.up;
  const std::string& url = rec.url;

  // 400 small messages back to back, every fourth on a channel left out: more than LCM's default
  // queue of 30 holds while the recorder waits for a core.
  constexpr int kBurst = 400;
  lcm::LCM sender(url);
  for (int i = 0; up && i < kBurst; ++i) {
    uint8_t payload[8];
    std::memcpy(payload, &i, sizeof i);
    std::memset(payload + 4, 0xAB, 4);
    sender.publish(i % 4 == 3 ? "SKIP_ME" : "BURST", payload, sizeof payload);
  }
  const bool written = up && wait_status(
                                 *rec.bus,
                                 [](const process_status_t& st) {
                                   return counter(st, "events_written") >= 300 + 1 &&
                                          counter(st, "events_left_out") >= 100;
                                 },
                                 10);
  const bool clean_exit = rec.stop(SIGINT);
  ASSERT_TRUE(up) << "no status from traverse-record";
  EXPECT_TRUE(written) << "the recorder's status never counted the burst";
  EXPECT_TRUE(clean_exit);

  LogReader reader(rec.log.string());
  int burst = 0, skipped = 0, statuses = 0, events = 0;
  bool in_order = true;
  int64_t last_utime = 0;
  while (auto ev = reader.next()) {
    ++events;
    if (ev->channel == "BURST") {
      int i = -1;
      std::memcpy(&i, ev->data.data(), sizeof i);
      in_order = in_order && i == burst + burst / 3;  // 0, 1, 2, 4, 5, 6, 8, ...
      ++burst;
    }
    if (ev->channel == "SKIP_ME") ++skipped;
    if (ev->channel == "STATUS_RECORD_TEST") ++statuses;
    in_order = in_order && ev->utime >= last_utime;
    last_utime = ev->utime;
  }
  EXPECT_TRUE(reader.damage().empty());
  EXPECT_EQ(burst, 300);
  EXPECT_TRUE(in_order);
  EXPECT_EQ(skipped, 0);
  EXPECT_GE(statuses, 1);  // its own status too, as every process's

  const Json j = Json::parse(read_file(rec.out));
  EXPECT_EQ(j["events_written"], events) << j.dump();
  EXPECT_EQ(j["events_left_out"], 100) << j.dump();
  EXPECT_EQ(j["receive_queue_dropped"], 0) << j.dump();
  EXPECT_EQ(j["write_errors"], 0) << j.dump();
}

TEST(RecordProgram, KilledItLeavesALogThatReadsUpToItsLastFlush) {
  Running rec(31483, "killed", {});
  const bool up = rec.up;
  const std::string& url = rec.url;
  lcm::LCM sender(url);
  for (int i = 0; up && i < 50; ++i) {
    uint8_t payload[4];
    std::memcpy(payload, &i, sizeof i);
    sender.publish("BEFORE_KILL", payload, sizeof payload);
  }
  // Counted in a status, then at least one flush period (100 ms) later.
  const bool written =
      up && wait_status(
                *rec.bus,
                [](const process_status_t& st) { return counter(st, "events_written") >= 50; }, 10);
  std::this_thread::sleep_for(std::chrono::milliseconds(400));
  rec.stop(SIGKILL);
  ASSERT_TRUE(up) << "no status from traverse-record";
  ASSERT_TRUE(written);

  LogReader reader(rec.log.string());
  int before = 0;
  while (auto ev = reader.next()) before += ev->channel == "BEFORE_KILL";
  EXPECT_EQ(before, 50);
  EXPECT_TRUE(reader.damage().empty());
}

}  // namespace
}  // namespace traverse
