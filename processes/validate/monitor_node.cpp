#include "monitor_node.hpp"

#include <exception>

#include "channels.hpp"
#include "config.hpp"
#include "process.hpp"
#include "traverse/process_status_t.hpp"

namespace traverse {

std::optional<std::string> validate::validate(const MonitorConfig& c) {
  ConfigCheck check;
  check.positive("status_timeout_s", c.status_timeout_s);
  return check.problem();
}

namespace {

const std::string kStatusPrefix = "STATUS_";

validate::ProcessReport to_report(const process_status_t& st) {
  validate::ProcessReport r;
  r.process = st.process;
  r.host = st.host;
  r.pid = st.pid;
  r.seq = st.seq;
  r.state = st.state;
  r.uptime_s = st.uptime_s;
  r.cpu_s = st.cpu_s;
  r.rss_bytes = st.rss_bytes;
  for (const channel_stats_t& c : st.channels) {
    r.received += c.received;
    r.published += c.published;
    r.decode_failures += c.decode_failures;
    r.out_of_order += c.out_of_order;
    r.missed += c.missed;
    r.handler_errors += c.handler_errors;
  }
  return r;
}

}  // namespace

MonitorNode::MonitorNode(Bus& bus, const MonitorConfig& cfg)
    : bus_(bus), tracker_(cfg.status_timeout_s), start_utime_(now_utime()) {
  subscription_ = bus_.subscribe_raw(
      ".*", [this](const std::string& channel, const uint8_t* data, int size, int64_t recv_utime) {
        on_message(channel, data, size, recv_utime);
      });
}

MonitorNode::~MonitorNode() {
  if (subscription_) bus_.unsubscribe(subscription_);
}

void MonitorNode::on_message(const std::string& channel, const uint8_t* data, int size,
                             int64_t recv_utime) {
  if (channel == channels::kLcmSelfTest) return;
  analyzer_.add(channel, recv_utime, data, static_cast<std::size_t>(size));
  if (channel.rfind(kStatusPrefix, 0) != 0) return;
  process_status_t st;
  bool ok = false;
  try {
    ok = st.decode(data, 0, size) == size;
  } catch (const std::exception&) {
    ok = false;  // corrupt array lengths make the generated decoder throw
  }
  if (!ok) {
    ++status_decode_failures_;
    return;
  }
  tracker_.add(channel, recv_utime, to_report(st));
}

validate::RunSummary MonitorNode::summary(int64_t now_utime) const {
  validate::RunSummary s;
  s.lcm_url = bus_.url();
  s.start_utime = start_utime_;
  s.end_utime = now_utime;
  s.events = analyzer_.events();
  s.status_decode_failures = status_decode_failures_;
  s.channels = analyzer_.summary();
  s.processes = tracker_.summary(now_utime);
  validate::judge(s);
  return s;
}

}  // namespace traverse
