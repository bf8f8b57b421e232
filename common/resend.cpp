#include "resend.hpp"

#include <unistd.h>

#include <algorithm>

#include "channels.hpp"
#include "message_checks.hpp"
#include "traverse/resend_request_t.hpp"

namespace traverse {

void request_resend(Publisher& bus, const std::string& requester,
                    const std::vector<std::string>& wanted, int64_t utime) {
  resend_request_t m{};
  m.utime = utime;
  m.requester = requester + "/" + std::to_string(::getpid());
  for (const std::string& c : wanted) {
    if (!c.empty()) m.channels.push_back(c);
  }
  m.n_channels = static_cast<int32_t>(m.channels.size());
  if (m.n_channels > 0) bus.publish(channels::kResendRequest, m);
}

ResendAnswerer::ResendAnswerer(Bus& bus, std::vector<std::string> channels, Answer answer,
                               ResendPacing pacing)
    : bus_(bus),
      channels_(std::move(channels)),
      answer_(std::move(answer)),
      pacing_(std::move(pacing)) {
  std::erase(channels_, std::string());
  if (channels_.empty()) return;
  subscription_ = bus_.subscribe_raw(
      channels::kResendRequest, [this](const std::string&, const uint8_t* data, int size, int64_t) {
        on_request(data, size);
      });
}

ResendAnswerer::~ResendAnswerer() {
  if (subscription_) bus_.unsubscribe(subscription_);
}

void ResendAnswerer::on_request(const uint8_t* data, int size) {
  resend_request_t m;
  if (decode_checked(data, size, {}, m).verdict != MessageVerdict::kGood) {
    ++counters_.rejected;
    return;
  }
  ResendRequest r{m.requester, m.utime, {}};
  for (const std::string& c : channels_) {
    if (std::find(m.channels.begin(), m.channels.end(), c) != m.channels.end()) {
      r.named.push_back(c);
    }
  }
  if (r.named.empty()) return;  // for other producers
  // Requesters are independent processes: only one requester's own numbers are in order.
  auto [last, first] = last_seq_.try_emplace(m.requester, m.seq);
  if (!first) {
    if (m.seq <= last->second) {
      ++counters_.repeated;
      return;
    }
    last->second = m.seq;
  }
  ++counters_.requests;
  if (pacing_.answering && pacing_.answering(m.requester)) {
    ++counters_.paced;
    return;
  }
  const bool paced = pacing_.min_us > 0 && pacing_.data_time;
  const int64_t now = paced ? pacing_.data_time() : 0;
  const auto key = [&](const std::string& channel) {
    return pacing_.scope == ResendPacing::Scope::kChannel ? channel : m.requester + "\n" + channel;
  };
  if (paced) {
    std::erase_if(r.named, [&](const std::string& channel) {
      const auto last = last_answer_.find(key(channel));
      return last != last_answer_.end() && now - last->second < pacing_.min_us;
    });
    if (r.named.empty()) {
      ++counters_.paced;
      return;
    }
  }
  if (!answer_(r)) return;
  ++counters_.answers;
  if (paced) {
    for (const std::string& channel : r.named) last_answer_[key(channel)] = now;
  }
}

void ResendAnswerer::report(
    const std::function<void(const std::string& name, double value)>& sink) const {
  sink("resend_requests", static_cast<double>(counters_.requests));
  sink("resend_answers", static_cast<double>(counters_.answers));
  sink("resend_requests_paced", static_cast<double>(counters_.paced));
  sink("resend_requests_repeated", static_cast<double>(counters_.repeated));
  sink("resend_requests_rejected", static_cast<double>(counters_.rejected));
}

}  // namespace traverse
