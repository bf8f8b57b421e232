#include "monitor_node.hpp"

#include "channels.hpp"
#include "config.hpp"
#include "message_checks.hpp"
#include "process.hpp"
#include "traverse/process_status_t.hpp"

namespace traverse {

std::optional<std::string> validate::validate(const MonitorConfig& c) {
  ConfigCheck check;
  check.positive("status_timeout_s", c.status_timeout_s);
  check.positive("max_status_gap_s", c.max_status_gap_s);
  check.not_negative("max_missed", c.max_missed);
  check.not_negative("max_out_of_order", c.max_out_of_order);
  check.not_negative("max_queue_dropped", c.max_queue_dropped);
  check.not_negative("max_rejected", c.max_rejected);
  check.not_negative("max_seq_gaps", c.max_seq_gaps);
  return check.problem();
}

namespace {

const std::string kStatusPrefix = "STATUS_";

}  // namespace

MonitorNode::MonitorNode(Bus& bus, const MonitorConfig& cfg, std::string self, bool live)
    : bus_(bus),
      cfg_(cfg),
      self_(std::move(self)),
      live_(live),
      tracker_(cfg.status_timeout_s),
      start_utime_(now_utime()) {
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
  // Walked before it is decoded: twenty statuses claiming 5 M channels each silenced the monitor
  // for 23 s when they were decoded first.
  if (decode_checked(data, size, {}, st).verdict == MessageVerdict::kMalformed) {
    ++status_decode_failures_;
    return;
  }
  tracker_.add(channel, recv_utime, report_of(st));
}

validate::Thresholds MonitorNode::thresholds() const {
  validate::Thresholds t;
  t.timing = live_;
  t.max_status_gap_s = cfg_.max_status_gap_s;
  t.max_missed = cfg_.max_missed;
  t.max_out_of_order = cfg_.max_out_of_order;
  t.max_queue_dropped = cfg_.max_queue_dropped;
  t.max_rejected = cfg_.max_rejected;
  t.max_seq_gaps = cfg_.max_seq_gaps;
  return t;
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
  auto self = s.processes.find(self_);
  if (self != s.processes.end() && self->second.state == "silent") {
    self->second.state = self->second.last.state;  // it is running: it is writing this summary
  }
  validate::judge(s, thresholds());
  return s;
}

}  // namespace traverse
