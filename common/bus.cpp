#include "bus.hpp"

#include <spdlog/spdlog.h>

namespace traverse {

Bus::Bus(const std::string& url) : url_(url), lcm_(url) {}

bool Bus::handle(int timeout_ms) { return lcm_.handleTimeout(timeout_ms) >= 0; }

void Bus::send(const std::string& channel, const uint8_t* data, std::size_t size, int64_t) {
  lcm_.publish(channel, data, static_cast<unsigned int>(size));
}

bool Bus::admit(const std::string& channel, int64_t utime, int64_t seq, bool accept_out_of_order) {
  ChannelStats& s = stats_[channel];
  if (seq >= 0) {
    // A sequence number below the last one means the producer restarted: start counting afresh.
    if (s.last_seq >= 0 && seq > s.last_seq + 1) s.missed += seq - s.last_seq - 1;
    s.last_seq = seq;
  }
  if (s.received > 0 && utime < s.last_utime && !accept_out_of_order) {
    ++s.out_of_order;
    return false;
  }
  s.last_utime = utime;
  ++s.received;
  return true;
}

void Bus::Subscription::on_message(const lcm::ReceiveBuffer* rbuf, const std::string& ch) {
  ChannelStats& s = bus->stats_[ch];
  try {
    if (dispatch(rbuf->data, static_cast<int>(rbuf->data_size)) == Outcome::kDecodeFailure) {
      ++s.decode_failures;
      if (s.decode_failures <= 3) {
        spdlog::warn("{}: message of {} bytes does not decode, dropped", ch, rbuf->data_size);
      }
    }
  } catch (const std::exception& e) {
    ++s.handler_errors;
    if (s.handler_errors <= 10) spdlog::error("{}: handler failed: {}", ch, e.what());
  }
}

}  // namespace traverse
