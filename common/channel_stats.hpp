// Per-channel traffic counters that every process keeps and reports in its status.
#pragma once

#include <cstdint>
#include <map>
#include <string>

namespace traverse {

struct ChannelStats {
  int64_t received = 0;  // decoded and handed to the process
  int64_t published = 0;
  int64_t decode_failures = 0;  // bytes that did not decode as the subscribed type
  int64_t out_of_order = 0;     // utime earlier than the previous message (dropped)
  int64_t missed = 0;           // sequence numbers skipped
  int64_t handler_errors = 0;   // the process failed while handling the message
  int64_t rejected = 0;         // decoded but cannot be right, or beyond a limit (dropped)
  int64_t stamp_outliers = 0;   // utime far from both neighbours (dropped)
  int64_t time_jumps = 0;       // the stream's utime jumped far and went on from there
  int64_t last_utime = 0;       // [us]
  int64_t last_seq = -1;        // last sequence number seen or sent, -1 if none
};

using ChannelStatsMap = std::map<std::string, ChannelStats>;

}  // namespace traverse
