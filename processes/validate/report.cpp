#include "report.hpp"

#include <cstdio>

namespace traverse::validate {
namespace {

std::string format(const char* fmt, auto... args) {
  char buf[512];
  std::snprintf(buf, sizeof(buf), fmt, args...);
  return buf;
}

std::string number_or_dash(const std::optional<double>& v, const char* fmt) {
  return v ? format(fmt, *v) : "-";
}

// A figure as the summaries print it: nine significant digits, null when absent or not finite.
Json figure(std::optional<double> v) { return json_significant(v, 9); }

std::string short_type(const std::string& type) {
  const auto dot = type.rfind('.');
  return type.empty() ? "?" : type.substr(dot == std::string::npos ? 0 : dot + 1);
}

}  // namespace

std::vector<std::string> channel_problems(const ChannelSummaries& channels) {
  std::vector<std::string> out;
  for (const auto& [name, c] : channels) {
    if (c.decode_failures > 0) {
      out.push_back(name + ": " + std::to_string(c.decode_failures) + " of " +
                    std::to_string(c.count) + " messages do not decode as " +
                    (c.type.empty() ? std::string("any known type") : c.type));
    }
    if (c.backwards > 0) {
      out.push_back(name + ": timestamps go backwards at " + std::to_string(c.backwards) +
                    " messages (event time " + std::to_string(c.event_backwards) +
                    ", message utime " + std::to_string(c.utime_backwards) + ", up to " +
                    format("%.6f", c.max_backstep_s.value_or(0.0)) + " s)");
    }
    if (c.rejected > 0) {
      out.push_back(name + ": " + std::to_string(c.rejected) + " messages cannot be right (" +
                    c.first_rejection + ")");
    }
    if (c.stamp_outliers > 0) {
      out.push_back(name + ": " + std::to_string(c.stamp_outliers) +
                    " messages stamped far from their neighbours");
    }
  }
  return out;
}

std::vector<std::string> process_problems(const ProcessSummaries& processes, const Thresholds& t) {
  std::vector<std::string> out;
  const auto over = [&out](const std::string& name, int64_t n, int64_t max, const char* what) {
    if (n > max) {
      out.push_back(name + ": " + std::to_string(n) + " " + what + " (at most " +
                    std::to_string(max) + " allowed)");
    }
  };
  for (const auto& [name, p] : processes) {
    if (t.timing && p.state == "silent") {
      out.push_back(name + ": silent for " + format("%.1f", p.silent_s) + " s");
    }
    if (t.timing && p.max_status_gap_s && *p.max_status_gap_s > t.max_status_gap_s) {
      out.push_back(name + ": no status for " + format("%.1f", *p.max_status_gap_s) +
                    " s at one point (at most " + format("%.1f", t.max_status_gap_s) + " s)");
    }
    over(name, p.last.missed, t.max_missed, "messages missed (sequence numbers skipped)");
    over(name, p.last.out_of_order, t.max_out_of_order, "messages dropped as out of order");
    over(name, p.last.queue_dropped, t.max_queue_dropped, "messages dropped by its receive queue");
    over(name, p.last.rejected + p.last.stamp_outliers, t.max_rejected,
         "messages rejected as implausible, beyond a limit or stamped far from their neighbours");
    if (p.last.replay_events == 0) out.push_back(name + ": its input log had no readable event");
    if (p.last.replay_damaged_records > 0) {
      out.push_back(name + ": its input log has " + std::to_string(p.last.replay_damaged_records) +
                    " damaged records");
    }
    if (p.last.decode_failures > 0) {
      out.push_back(name + ": reports " + std::to_string(p.last.decode_failures) +
                    " decode failures");
    }
    if (p.last.handler_errors > 0) {
      out.push_back(name + ": reports " + std::to_string(p.last.handler_errors) +
                    " handler errors");
    }
  }
  return out;
}

Json channels_json(const ChannelSummaries& channels) {
  Json out = Json::object();
  for (const auto& [name, c] : channels) {
    Json j;
    j["type"] = c.type.empty() ? Json() : Json(c.type);
    j["count"] = c.count;
    j["rate_hz"] = figure(c.rate_hz);
    j["max_gap_s"] = figure(c.max_gap_s);
    j["backwards"] = c.backwards;
    j["event_backwards"] = c.event_backwards;
    j["utime_backwards"] = c.utime_backwards;
    j["max_backstep_s"] = figure(c.max_backstep_s);
    j["seq_gaps"] = c.seq_gaps;
    j["seq_restarts"] = c.seq_restarts;
    j["decode_failures"] = c.decode_failures;
    j["unknown_fingerprint"] = c.unknown_fingerprint;
    j["undecodable"] = c.undecodable;
    j["other_types"] = Json::object();
    for (const auto& [type, n] : c.other_types) j["other_types"][type] = n;
    j["rejected"] = c.rejected;
    j["stamp_outliers"] = c.stamp_outliers;
    j["time_jumps"] = c.time_jumps;
    const auto range = [](const Range& r, int64_t v) { return r.empty ? Json() : Json(v); };
    j["points_per_scan_min"] = range(c.points, c.points.min);
    j["points_per_scan_max"] = range(c.points, c.points.max);
    const auto seconds = [](const Range& r, int64_t v) {
      return r.empty ? Json() : figure(1e-6 * static_cast<double>(v));
    };
    j["sweep_s_min"] = seconds(c.sweep_us, c.sweep_us.min);
    j["sweep_s_max"] = seconds(c.sweep_us, c.sweep_us.max);
    j["period_s"] = figure(c.period_s);
    j["frames"] = c.frames;
    j["first_utime"] = c.first_event_utime;
    j["last_utime"] = c.last_event_utime;
    out[name] = std::move(j);
  }
  return out;
}

Json processes_json(const ProcessSummaries& processes) {
  Json out = Json::object();
  for (const auto& [name, p] : processes) {
    Json j;
    j["channel"] = p.channel;
    j["state"] = p.state;
    j["last_state"] = p.last.state;
    j["host"] = p.last.host;
    j["pid"] = p.last.pid;
    j["statuses"] = p.statuses;
    j["silent_s"] = figure(p.silent_s);
    j["max_status_gap_s"] = figure(p.max_status_gap_s);
    j["status_seq_gaps"] = p.status_seq_gaps;
    j["restarts"] = p.restarts;
    j["uptime_s"] = figure(p.last.uptime_s);
    j["cpu_s"] = figure(p.last.cpu_s);
    j["rss_bytes"] = p.last.rss_bytes;
    j["peak_rss_bytes"] = p.peak_rss_bytes;
    j["received"] = p.last.received;
    j["published"] = p.last.published;
    j["decode_failures"] = p.last.decode_failures;
    j["out_of_order"] = p.last.out_of_order;
    j["missed"] = p.last.missed;
    j["handler_errors"] = p.last.handler_errors;
    j["rejected"] = p.last.rejected;
    j["stamp_outliers"] = p.last.stamp_outliers;
    j["queue_dropped"] = p.last.queue_dropped;
    out[name] = std::move(j);
  }
  return out;
}

std::string channel_table(const ChannelSummaries& channels) {
  std::string out =
      format("%-24s %-18s %9s %10s %11s %9s %8s %11s %13s\n", "channel", "type", "count",
             "rate [Hz]", "max gap [s]", "backwards", "seq gaps", "decode fail", "points/scan");
  for (const auto& [name, c] : channels) {
    const std::string points = c.points.empty
                                   ? "-"
                                   : format("%lld..%lld", static_cast<long long>(c.points.min),
                                            static_cast<long long>(c.points.max));
    out += format("%-24s %-18s %9lld %10s %11s %9lld %8lld %11lld %13s\n", name.c_str(),
                  short_type(c.type).c_str(), static_cast<long long>(c.count),
                  number_or_dash(c.rate_hz, "%.3f").c_str(),
                  number_or_dash(c.max_gap_s, "%.3f").c_str(), static_cast<long long>(c.backwards),
                  static_cast<long long>(c.seq_gaps), static_cast<long long>(c.decode_failures),
                  points.c_str());
    std::string details;
    if (c.period_s) details += format("  period %.4f s", *c.period_s);
    if (!c.sweep_us.empty) {
      details += format("  sweep %.4f..%.4f s", 1e-6 * static_cast<double>(c.sweep_us.min),
                        1e-6 * static_cast<double>(c.sweep_us.max));
    }
    if (!c.frames.empty()) {
      details += "  frames";
      for (const auto& f : c.frames) details += " " + f;
    }
    if (c.max_backstep_s) details += format("  steps back up to %.6f s", *c.max_backstep_s);
    if (c.unknown_fingerprint > 0) {
      details += format("  %lld of unknown type", static_cast<long long>(c.unknown_fingerprint));
    }
    if (c.undecodable > 0) {
      details += format("  %lld undecodable", static_cast<long long>(c.undecodable));
    }
    for (const auto& [type, n] : c.other_types) {
      details += format("  %lld as %s", static_cast<long long>(n), type.c_str());
    }
    if (c.seq_restarts > 0) {
      details += format("  %lld seq restarts", static_cast<long long>(c.seq_restarts));
    }
    if (!details.empty()) out += "   " + details + "\n";
  }
  return out;
}

std::string process_table(const ProcessSummaries& processes) {
  std::string out =
      format("%-20s %-10s %9s %11s %14s %9s %10s %11s %9s\n", "process", "state", "statuses",
             "silent [s]", "max gap [s]", "cpu [s]", "rss [MB]", "decode fail", "handler err");
  for (const auto& [name, p] : processes) {
    out += format("%-20s %-10s %9lld %11.1f %14s %9.2f %10.1f %11lld %9lld\n", name.c_str(),
                  p.state.c_str(), static_cast<long long>(p.statuses), p.silent_s,
                  number_or_dash(p.max_status_gap_s, "%.2f").c_str(), p.last.cpu_s,
                  1e-6 * static_cast<double>(p.last.rss_bytes),
                  static_cast<long long>(p.last.decode_failures),
                  static_cast<long long>(p.last.handler_errors));
  }
  return out;
}

}  // namespace traverse::validate
