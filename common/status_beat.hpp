// Sends a process's status and keeps it beating while the main thread is busy in one step (a
// loop closure, a scan that takes seconds to match): when no status came from the main thread
// for 1.5 s, a thread of its own re-sends the last one once a second with fresh time, CPU and
// memory figures, the state "busy: <seconds> s in one step" and the counter busy_s. So a status
// that stops means the process stopped or hung, never that it was working (a stopped process's
// threads stop too), and the monitor can judge gaps strictly.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <lcm/lcm-cpp.hpp>
#include <mutex>
#include <string>
#include <thread>

#include "traverse/process_status_t.hpp"

namespace traverse {

class StatusBeat {
 public:
  // `refresh` sets utime, uptime_s, cpu_s and rss_bytes of a status to now (any thread).
  StatusBeat(lcm::LCM& lcm, std::string channel, std::function<void(process_status_t&)> refresh);
  ~StatusBeat();
  StatusBeat(const StatusBeat&) = delete;
  StatusBeat& operator=(const StatusBeat&) = delete;

  // Sends `st` now with the next sequence number (main thread); returns that number.
  int64_t send(process_status_t st);
  // Starts or stops the thread that re-sends (a live bus only: LCM's udpm publish is thread-safe).
  void start();
  void stop();

 private:
  void run();
  void publish(const process_status_t& st);  // with mutex_ held

  lcm::LCM& lcm_;
  std::string channel_;
  std::function<void(process_status_t&)> refresh_;
  std::mutex mutex_;
  std::condition_variable wake_;
  process_status_t last_;
  bool have_last_ = false, stopping_ = false;
  int64_t seq_ = 0;
  int64_t main_sent_utime_ = 0;  // [us] last status from the main thread
  int64_t beat_sent_utime_ = 0;  // [us] last status from the beat thread
  std::thread thread_;
};

}  // namespace traverse
