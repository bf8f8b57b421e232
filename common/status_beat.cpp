#include "status_beat.hpp"

#include <pthread.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <vector>

namespace traverse {

StatusBeat::StatusBeat(lcm::LCM& lcm, std::string channel,
                       std::function<void(process_status_t&)> refresh)
    : lcm_(lcm), channel_(std::move(channel)), refresh_(std::move(refresh)) {}

StatusBeat::~StatusBeat() { stop(); }

void StatusBeat::publish(const process_status_t& st) {
  std::vector<uint8_t> buf(st.getEncodedSize());
  st.encode(buf.data(), 0, static_cast<int>(buf.size()));
  lcm_.publish(channel_, buf.data(), static_cast<unsigned>(buf.size()));
}

int64_t StatusBeat::send(process_status_t st) {
  std::lock_guard lock(mutex_);
  st.seq = seq_++;
  publish(st);
  last_ = std::move(st);
  have_last_ = true;
  main_sent_utime_ = last_.utime;
  return last_.seq;
}

void StatusBeat::start() {
  if (thread_.joinable()) return;
  stopping_ = false;
  thread_ = std::thread([this] { run(); });
}

void StatusBeat::stop() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void StatusBeat::run() {
  // Signals go to the process's main thread, never to this one.
  sigset_t all;
  sigfillset(&all);
  pthread_sigmask(SIG_BLOCK, &all, nullptr);
  std::unique_lock lock(mutex_);
  while (!wake_.wait_for(lock, std::chrono::milliseconds(250), [this] { return stopping_; })) {
    if (!have_last_) continue;
    process_status_t st = last_;
    refresh_(st);
    const int64_t busy_us = st.utime - main_sent_utime_;
    if (busy_us < 1'500'000 || st.utime - beat_sent_utime_ < 1'000'000) continue;
    char state[64];
    std::snprintf(state, sizeof state, "busy: %.1f s in one step", 1e-6 * busy_us);
    st.state = state;
    st.counter_names.push_back("busy_s");
    st.counter_values.push_back(1e-6 * static_cast<double>(busy_us));
    st.n_counters = static_cast<int32_t>(st.counter_names.size());
    st.seq = seq_++;
    publish(st);
    beat_sent_utime_ = st.utime;
  }
}

}  // namespace traverse
