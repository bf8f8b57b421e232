#include "status_report.hpp"

#include "traverse/process_status_t.hpp"

namespace traverse {
namespace {

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

}  // namespace

StatusReport report_of(const process_status_t& st) {
  StatusReport r;
  r.process = st.process;
  r.host = st.host;
  r.pid = st.pid;
  r.seq = st.seq;
  r.utime = st.utime;
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
  for (std::size_t i = 0; i < st.counter_names.size() && i < st.counter_values.size(); ++i) {
    const std::string& name = st.counter_names[i];
    const auto value = static_cast<int64_t>(st.counter_values[i]);
    if (ends_with(name, "/rejected")) r.rejected += value;
    if (ends_with(name, "/stamp_outliers")) r.stamp_outliers += value;
    if (name == "receive_queue_dropped") r.queue_dropped = value;
    if (name == "replay_events") r.replay_events = value;
    if (name == "replay_damaged_records") r.replay_damaged_records = value;
  }
  return r;
}

}  // namespace traverse
