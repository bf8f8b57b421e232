// Typed publish/subscribe over LCM with the checks every process needs, so that every consumer
// gets them: a message whose bytes do not hold what it claims is counted as a decode failure and
// dropped before anything is allocated for it (message_layout.hpp); one that decodes but cannot be
// right (message_checks.hpp) or exceeds a limit (a scan's beam cap, input_config.hpp) is counted
// as rejected and dropped; one whose utime goes backwards is counted and dropped, and one stamped
// far from its neighbours is held back and then either delivered or dropped as an outlier, never
// blocking the channel (stamp_order.hpp); skipped sequence numbers are counted; a handler that
// throws is reported and counted, and the process keeps running.
//
// Memory: a message reaches a handler only when its bytes hold everything it claims, so decoding
// it costs at most a small multiple of its size; the receive queue holds at most
// input.max_queue_bytes (1 GiB by default).
//
// On a network bus (udpm://) a receive thread reads the socket all the time and queues what
// arrives in memory; handle() dispatches the queued messages, in order, on the calling thread,
// where every handler runs. A process busy for seconds (a loop closure, an optimisation) so loses
// nothing to its socket's receive buffer: every process's socket gets every channel of the group,
// and net.core.rmem_max (8 MB here) holds about two seconds of a whole graph's traffic. Messages
// beyond input.max_queue_bytes queued are dropped and counted. On memq:// (in process) there
// is no socket: handle() dispatches as LCM delivers, on the calling thread.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <lcm/lcm-cpp.hpp>
#include <list>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "input_config.hpp"
#include "message_checks.hpp"
#include "publisher.hpp"
#include "stamp_order.hpp"

namespace traverse {

// Default URL: loopback multicast, never leaves the host (ttl=0), with a receive buffer large
// enough for bursts of 43 KB scans. --lcm-url overrides it; LCM_DEFAULT_URL does not (see
// process.hpp).
inline constexpr const char* kDefaultLcmUrl =
    "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=8388608";

class Bus : public Publisher {
 public:
  // Messages LCM may hold for one subscription before this bus's reader takes them (its default
  // is 30, and it drops the rest uncounted); the reader only copies them into the counted queue,
  // so this is seldom reached. Every subscription on lcm() directly should set it too.
  static constexpr int kLcmQueueMessages = 100000;

  explicit Bus(const std::string& url, const InputConfig& input = {});
  bool good() const { return lcm_.good(); }
  const std::string& url() const { return url_; }
  const InputConfig& input() const { return input_; }

  // Calls handler(msg) for every message on `channel` that decodes as T, passes the checks above
  // and is in order by its utime (any order if `accept_out_of_order`).
  template <class T>
  void subscribe(const std::string& channel, std::function<void(const T&)> handler,
                 bool accept_out_of_order = false) {
    auto order = std::make_shared<StampOrder>(max_stamp_jump_us());
    auto held = std::make_shared<std::optional<T>>();
    add_subscription(
        channel, true,
        [this, channel, order, held, accept_out_of_order, handler = std::move(handler)](
            const std::string&, const uint8_t* data, int size, int64_t) {
          T msg;
          const Inspection r = decode_checked(data, size, limits_, msg);
          if (r.verdict == MessageVerdict::kMalformed) return Outcome::kDecodeFailure;
          if (r.verdict != MessageVerdict::kGood) {
            reject(channel, r.problem);
            return Outcome::kRejected;
          }
          int64_t seq = -1;
          if constexpr (requires { msg.seq; }) seq = msg.seq;
          count_sequence(channel, seq);
          const StampOrder::Step step =
              accept_out_of_order ? StampOrder::Step{.deliver = true} : order->next(msg.utime);
          count_order(channel, step);
          if (step.release_held) {
            const T earlier = std::move(**held);
            held->reset();
            delivered(channel, earlier.utime);
            handler(earlier);
          }
          if (step.hold) *held = std::move(msg);
          if (!step.deliver) return step.out_of_order ? Outcome::kOutOfOrder : Outcome::kHandled;
          delivered(channel, msg.utime);
          handler(msg);
          return Outcome::kHandled;
        });
    stats_[channel];  // list the channel in status even before the first message
  }

  // Raw bytes of every message on channels matching `channel_regex`, with the time the bus
  // received each [us]; `handler(channel, data, size, recv_utime)`. Not counted per channel.
  // The handle ends the subscription with unsubscribe().
  using RawHandler = std::function<void(const std::string& channel, const uint8_t* data, int size,
                                        int64_t recv_utime)>;
  using Handle = const void*;
  Handle subscribe_raw(const std::string& channel_regex, RawHandler handler);
  // No message reaches the handler afterwards (also none already received).
  void unsubscribe(Handle handle);

  // Waits up to timeout_ms for messages and dispatches them. Returns false on an LCM error.
  bool handle(int timeout_ms);

  // Receive queue of a network bus: largest size reached [bytes] and messages dropped because it
  // was full (both 0 on memq://).
  int64_t queue_max_bytes() const;
  int64_t queue_dropped() const;

  lcm::LCM& lcm() { return lcm_; }
  ~Bus() override;

 protected:
  void send(const std::string& channel, const uint8_t* data, std::size_t size,
            int64_t utime) override;

 private:
  enum class Outcome { kHandled, kDecodeFailure, kRejected, kOutOfOrder };
  using Dispatch = std::function<Outcome(const std::string& channel, const uint8_t*, int, int64_t)>;
  struct Subscription {
    Bus* bus = nullptr;
    bool counted = true;  // typed: decode failures and handler errors go into the channel's stats
    std::atomic<bool> active{true};  // kept until the bus ends: the receive thread may hold it
    lcm::Subscription* lcm_subscription = nullptr;
    Dispatch dispatch;
    void on_message(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  };
  struct Received {
    Subscription* subscription = nullptr;
    std::string channel;
    std::vector<uint8_t> data;
    int64_t recv_utime = 0;
  };

  Subscription* add_subscription(const std::string& channel, bool counted, Dispatch dispatch);
  // Runs a subscription's handler on one message (on the thread that calls handle()).
  void deliver(Subscription& sub, const std::string& channel, const uint8_t* data, int size,
               int64_t recv_utime);
  void read_loop();  // the receive thread of a network bus
  // Counters of the typed subscriptions.
  void count_sequence(const std::string& channel, int64_t seq);
  void count_order(const std::string& channel, const StampOrder::Step& step);
  void delivered(const std::string& channel, int64_t utime);
  void reject(const std::string& channel, const std::string& why);
  int64_t max_stamp_jump_us() const;

  std::string url_;
  InputConfig input_;
  std::vector<ArrayLimit> limits_;
  lcm::LCM lcm_;
  std::list<std::unique_ptr<Subscription>> subscriptions_;
  const bool threaded_;  // network bus: a receive thread queues messages
  std::thread reader_;   // started by the first handle()
  mutable std::mutex mutex_;
  std::condition_variable arrived_;
  std::deque<Received> queue_;
  int64_t queued_bytes_ = 0, queue_max_bytes_ = 0, queue_dropped_ = 0;
  bool read_failed_ = false;
  std::atomic<bool> stop_reading_{false};
};

}  // namespace traverse
