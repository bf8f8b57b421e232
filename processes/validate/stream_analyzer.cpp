#include "stream_analyzer.hpp"

#include <algorithm>

namespace traverse::validate {

void Range::add(int64_t v) {
  min = empty ? v : std::min(min, v);
  max = empty ? v : std::max(max, v);
  empty = false;
}

void StreamAnalyzer::TypeStream::add(const MessageFacts& f, bool event_went_back) {
  ++decoded;
  if (f.utime) {
    const StampOrder::Step step = order.next(*f.utime);
    (void)step;  // counted by the StampOrder itself
    if (last_utime && *f.utime < *last_utime) {
      ++utime_backwards;
      if (!event_went_back) ++utime_only_backwards;
      max_backstep_us = std::max(max_backstep_us.value_or(0), *last_utime - *f.utime);
    }
    if (!first_utime) first_utime = f.utime;
    last_utime = f.utime;
  }
  if (f.seq) {
    // Like the bus: a number not above the last one means the producer restarted its count.
    if (last_seq && *f.seq > *last_seq + 1) seq_gaps += *f.seq - *last_seq - 1;
    if (last_seq && *f.seq <= *last_seq) ++seq_restarts;
    last_seq = f.seq;
  }
  if (f.points) points.add(*f.points);
  if (f.sweep_us) sweep_us.add(*f.sweep_us);
  if (!f.frame.empty() && frames.size() < kMaxFrames) frames.insert(f.frame);
}

void StreamAnalyzer::add(const std::string& channel, int64_t event_utime, const void* data,
                         std::size_t size) {
  ++events_;
  Channel& c = channels_[channel];
  const bool event_went_back = c.count > 0 && event_utime < c.last_event;
  if (c.count == 0) {
    c.first_event = event_utime;
  } else if (event_went_back) {
    ++c.event_backwards;
    c.max_backstep_us = std::max(c.max_backstep_us.value_or(0), c.last_event - event_utime);
  } else {
    const int64_t gap = event_utime - c.last_event;
    c.max_gap_us = std::max(c.max_gap_us.value_or(0), gap);
  }
  c.last_event = event_utime;
  ++c.count;

  const TypeInfo* type = type_of_fingerprint(data, size);
  if (!type) {
    ++c.unknown_fingerprint;
    return;
  }
  Inspection r;
  if (size <= static_cast<std::size_t>(INT32_MAX)) {
    // The bytes are walked before anything is decoded (message_layout.hpp): a message claiming
    // more than it holds costs nothing.
    r = type->inspect(data, static_cast<int>(size), limits_);
  }
  if (r.verdict == MessageVerdict::kMalformed) {
    ++c.undecodable;
    return;
  }
  if (r.verdict != MessageVerdict::kGood) {
    ++c.rejected;
    if (c.first_rejection.empty()) c.first_rejection = r.problem;
  }
  TypeStream& t = c.types.try_emplace(type->name, max_stamp_jump_us_).first->second;
  if (r.verdict == MessageVerdict::kOverLimit) {
    ++t.decoded;  // holds what it claims, but was not decoded: no facts
  } else {
    t.add(r.facts, event_went_back);
  }
}

std::map<std::string, ChannelSummary> StreamAnalyzer::summary() const {
  std::map<std::string, ChannelSummary> out;
  for (const auto& [name, c] : channels_) {
    ChannelSummary& s = out[name];
    s.count = c.count;
    s.first_event_utime = c.first_event;
    s.last_event_utime = c.last_event;
    const int64_t span_us = c.last_event - c.first_event;
    if (c.count >= 2 && span_us > 0) s.rate_hz = (c.count - 1) / (1e-6 * span_us);
    if (c.max_gap_us) s.max_gap_s = 1e-6 * *c.max_gap_us;
    s.event_backwards = c.event_backwards;
    s.backwards = c.event_backwards;
    if (c.max_backstep_us) s.max_backstep_s = 1e-6 * static_cast<double>(*c.max_backstep_us);
    s.unknown_fingerprint = c.unknown_fingerprint;
    s.undecodable = c.undecodable;
    s.rejected = c.rejected;
    s.first_rejection = c.first_rejection;

    // The channel's type is the one most of its messages decode as (first by name on a tie).
    const TypeStream* main = nullptr;
    for (const auto& [type_name, t] : c.types) {
      if (!main || t.decoded > main->decoded) {
        main = &t;
        s.type = type_name;
      }
    }
    for (const auto& [type_name, t] : c.types) {
      if (&t != main) s.other_types[type_name] = t.decoded;
    }
    s.decode_failures = c.count - (main ? main->decoded : 0);
    if (!main) continue;
    s.utime_backwards = main->utime_backwards;
    s.backwards += main->utime_only_backwards;
    if (main->max_backstep_us) {
      s.max_backstep_s = std::max(s.max_backstep_s.value_or(0.0),
                                  1e-6 * static_cast<double>(*main->max_backstep_us));
    }
    // A message still held at the end jumped far from its predecessor with none after it.
    StampOrder order = main->order;
    order.finish();
    s.stamp_outliers = order.outliers();
    s.time_jumps = order.jumps();
    s.seq_gaps = main->seq_gaps;
    s.seq_restarts = main->seq_restarts;
    s.points = main->points;
    s.sweep_us = main->sweep_us;
    s.frames = main->frames;
    if (main->decoded >= 2 && main->first_utime && main->last_utime) {
      s.period_s = 1e-6 * (*main->last_utime - *main->first_utime) / (main->decoded - 1);
    }
  }
  return out;
}

}  // namespace traverse::validate
