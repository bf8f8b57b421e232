#include "resend.hpp"

#include <algorithm>

#include "channels.hpp"
#include "traverse/resend_request_t.hpp"

namespace traverse {

void request_resend(Publisher& bus, const std::string& requester,
                    const std::vector<std::string>& wanted) {
  resend_request_t m{};
  m.requester = requester;
  for (const std::string& c : wanted) {
    if (!c.empty()) m.channels.push_back(c);
  }
  m.n_channels = static_cast<int32_t>(m.channels.size());
  if (m.n_channels > 0) bus.publish(channels::kResendRequest, m);
}

void answer_resend_requests(Bus& bus, const std::string& channel,
                            std::function<void(const std::string& requester)> answer) {
  if (channel.empty()) return;
  // Requesters are independent processes: their times need not be in order.
  bus.subscribe<resend_request_t>(
      channels::kResendRequest,
      [channel, answer = std::move(answer)](const resend_request_t& m) {
        if (std::find(m.channels.begin(), m.channels.end(), channel) != m.channels.end()) {
          answer(m.requester);
        }
      },
      true);
}

}  // namespace traverse
