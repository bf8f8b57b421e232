// Typed publish/subscribe over LCM with the checks every process needs: a message that does not
// decode is counted and dropped; one whose utime goes backwards is counted and dropped; skipped
// sequence numbers are counted; a handler that throws is reported and counted, and the process
// keeps running.
#pragma once

#include <lcm/lcm-cpp.hpp>

#include <functional>
#include <list>
#include <memory>
#include <string>

#include "publisher.hpp"

namespace traverse {

// Default URL: loopback multicast, never leaves the host (ttl=0), with a receive buffer large
// enough for bursts of 43 KB scans. Overridden by --lcm-url or LCM_DEFAULT_URL.
inline constexpr const char* kDefaultLcmUrl =
    "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=8388608";

class Bus : public Publisher {
 public:
  explicit Bus(const std::string& url);
  bool good() const { return lcm_.good(); }
  const std::string& url() const { return url_; }

  // Calls handler(msg) for every message on `channel` that decodes as T. Messages whose utime is
  // earlier than the previous one on the channel are dropped unless `accept_out_of_order`.
  template <class T>
  void subscribe(const std::string& channel, std::function<void(const T&)> handler,
                 bool accept_out_of_order = false) {
    auto sub = std::make_unique<Subscription>();
    sub->bus = this;
    sub->dispatch = [this, channel, accept_out_of_order, handler = std::move(handler)](
                        const void* data, int size) {
      T msg;
      if (msg.decode(data, 0, size) != size) return Outcome::kDecodeFailure;
      int64_t seq = -1;
      if constexpr (requires { msg.seq; }) seq = msg.seq;
      if (!admit(channel, msg.utime, seq, accept_out_of_order)) return Outcome::kOutOfOrder;
      handler(msg);
      return Outcome::kHandled;
    };
    lcm_.subscribe(channel, &Subscription::on_message, sub.get());
    stats_[channel];  // list the channel in status even before the first message
    subscriptions_.push_back(std::move(sub));
  }

  // Waits up to timeout_ms for messages and dispatches them. Returns false on an LCM error.
  bool handle(int timeout_ms);

  lcm::LCM& lcm() { return lcm_; }

 protected:
  void send(const std::string& channel, const uint8_t* data, std::size_t size,
            int64_t utime) override;

 private:
  enum class Outcome { kHandled, kDecodeFailure, kOutOfOrder };
  struct Subscription {
    Bus* bus = nullptr;
    std::function<Outcome(const void*, int)> dispatch;
    void on_message(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  };

  // Updates sequence and order counters; false if the message must be dropped.
  bool admit(const std::string& channel, int64_t utime, int64_t seq, bool accept_out_of_order);

  std::string url_;
  lcm::LCM lcm_;
  std::list<std::unique_ptr<Subscription>> subscriptions_;
};

}  // namespace traverse
