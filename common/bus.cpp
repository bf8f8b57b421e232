#include "bus.hpp"

#include <pthread.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <csignal>

namespace traverse {

Bus::Bus(const std::string& url, const InputConfig& input)
    : url_(url),
      input_(input),
      limits_(array_limits(input)),
      lcm_(url),
      threaded_(url.rfind("memq://", 0) != 0) {}

int64_t Bus::max_stamp_jump_us() const {
  return static_cast<int64_t>(std::min(1e6 * input_.max_stamp_jump_s, 9e18));
}

Bus::~Bus() {
  stop_reading_ = true;
  if (reader_.joinable()) reader_.join();
}

Bus::Subscription* Bus::add_subscription(const std::string& channel, bool counted,
                                         Dispatch dispatch) {
  auto sub = std::make_unique<Subscription>();
  sub->bus = this;
  sub->counted = counted;
  sub->dispatch = std::move(dispatch);
  sub->lcm_subscription = lcm_.subscribe(channel, &Subscription::on_message, sub.get());
  // LCM keeps at most 30 messages per subscription between its socket and this bus's reader by
  // default and drops the rest uncounted: a burst of small messages (a log replayed fast, a
  // frontend's IMU while the reader waits for a core) lost most of itself there. The bus's own
  // queue, bounded by `input.max_queue_bytes` and counted, is the one limit.
  sub->lcm_subscription->setQueueCapacity(kLcmQueueMessages);
  subscriptions_.push_back(std::move(sub));
  return subscriptions_.back().get();
}

void Bus::unsubscribe(Handle handle) {
  for (auto& sub : subscriptions_) {
    if (sub.get() != handle || !sub->active) continue;
    sub->active = false;
    lcm_.unsubscribe(sub->lcm_subscription);
    std::lock_guard lock(mutex_);
    std::erase_if(queue_, [&](const Received& r) {
      if (r.subscription != sub.get()) return false;
      queued_bytes_ -= static_cast<int64_t>(r.data.size());
      return true;
    });
  }
}

Bus::Handle Bus::subscribe_raw(const std::string& channel_regex, RawHandler handler) {
  return add_subscription(
      channel_regex, false,
      [handler = std::move(handler)](const std::string& channel, const uint8_t* data, int size,
                                     int64_t recv_utime) {
        handler(channel, data, size, recv_utime);
        return Outcome::kHandled;
      });
}

void Bus::read_loop() {
  // Signals (stop, export requests) go to the process's main thread, never to this one.
  sigset_t all;
  sigfillset(&all);
  pthread_sigmask(SIG_BLOCK, &all, nullptr);
  while (!stop_reading_) {
    if (lcm_.handleTimeout(100) < 0) {
      std::lock_guard lock(mutex_);
      read_failed_ = true;
      arrived_.notify_all();
      return;
    }
  }
}

bool Bus::handle(int timeout_ms) {
  if (!threaded_) return lcm_.handleTimeout(timeout_ms) >= 0;
  if (!reader_.joinable()) reader_ = std::thread([this] { read_loop(); });
  std::deque<Received> batch;
  {
    std::unique_lock lock(mutex_);
    arrived_.wait_for(lock, std::chrono::milliseconds(std::max(0, timeout_ms)),
                      [this] { return !queue_.empty() || read_failed_; });
    if (queue_.empty() && read_failed_) return false;
    batch.swap(queue_);
    queued_bytes_ = 0;
  }
  for (Received& r : batch) {
    deliver(*r.subscription, r.channel, r.data.data(), static_cast<int>(r.data.size()),
            r.recv_utime);
  }
  return true;
}

int64_t Bus::queue_max_bytes() const {
  std::lock_guard lock(mutex_);
  return queue_max_bytes_;
}

int64_t Bus::queue_dropped() const {
  std::lock_guard lock(mutex_);
  return queue_dropped_;
}

void Bus::send(const std::string& channel, const uint8_t* data, std::size_t size, int64_t) {
  lcm_.publish(channel, data, static_cast<unsigned int>(size));
}

void Bus::count_sequence(const std::string& channel, int64_t seq) {
  if (seq < 0) return;
  ChannelStats& s = stats_[channel];
  // A sequence number below the last one means the producer restarted: start counting afresh.
  if (s.last_seq >= 0 && seq > s.last_seq + 1) s.missed += seq - s.last_seq - 1;
  s.last_seq = seq;
}

void Bus::count_order(const std::string& channel, const StampOrder::Step& step) {
  ChannelStats& s = stats_[channel];
  if (step.out_of_order) ++s.out_of_order;
  if (step.release_held) ++s.time_jumps;
  if (step.dropped_held) {
    ++s.stamp_outliers;
    if (s.stamp_outliers <= 3) {
      spdlog::warn("{}: a message stamped far from its neighbours was dropped", channel);
    }
  }
}

void Bus::delivered(const std::string& channel, int64_t utime) {
  ChannelStats& s = stats_[channel];
  s.last_utime = utime;
  ++s.received;
}

void Bus::reject(const std::string& channel, const std::string& why) {
  ChannelStats& s = stats_[channel];
  ++s.rejected;
  if (s.rejected <= 3) spdlog::warn("{}: message rejected: {}", channel, why);
}

void Bus::Subscription::on_message(const lcm::ReceiveBuffer* rbuf, const std::string& ch) {
  const auto* data = static_cast<const uint8_t*>(rbuf->data);
  const int size = static_cast<int>(rbuf->data_size);
  if (!active) return;
  if (!bus->threaded_) {
    bus->deliver(*this, ch, data, size, rbuf->recv_utime);
    return;
  }
  // The receive thread: queue a copy for handle().
  std::lock_guard lock(bus->mutex_);
  if (bus->queued_bytes_ + size > bus->input_.max_queue_bytes) {
    ++bus->queue_dropped_;
  } else {
    bus->queue_.push_back({this, ch, std::vector<uint8_t>(data, data + size), rbuf->recv_utime});
    bus->queued_bytes_ += size;
    bus->queue_max_bytes_ = std::max(bus->queue_max_bytes_, bus->queued_bytes_);
  }
  bus->arrived_.notify_one();
}

void Bus::deliver(Subscription& sub, const std::string& ch, const uint8_t* data, int size,
                  int64_t recv_utime) {
  if (!sub.active) return;
  try {
    if (sub.dispatch(ch, data, size, recv_utime) == Outcome::kDecodeFailure) {
      ChannelStats& s = stats_[ch];
      ++s.decode_failures;
      if (s.decode_failures <= 3) {
        spdlog::warn("{}: message of {} bytes does not decode, dropped", ch, size);
      }
    }
  } catch (const std::exception& e) {
    if (!sub.counted) {
      spdlog::error("{}: handler failed: {}", ch, e.what());
      return;
    }
    ChannelStats& s = stats_[ch];
    ++s.handler_errors;
    if (s.handler_errors <= 10) spdlog::error("{}: handler failed: {}", ch, e.what());
  }
}

}  // namespace traverse
