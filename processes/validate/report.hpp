// Turns stream and process summaries into what the tools print: a table for people, one JSON
// object for scripts, and the list of problems that make a log or a run not ok.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "json.hpp"
#include "process_tracker.hpp"
#include "stream_analyzer.hpp"

namespace traverse::validate {

using ChannelSummaries = std::map<std::string, ChannelSummary>;
using ProcessSummaries = std::map<std::string, ProcessSummary>;

// One sentence per problem: decode failures and timestamps going backwards on a channel.
std::vector<std::string> channel_problems(const ChannelSummaries& channels);
// What a run may lose before it fails (MonitorConfig in monitor_node.hpp gives them from the
// config); `timing`: judge status gaps and silence (a live run, not a replay).
struct Thresholds {
  bool timing = true;
  double max_status_gap_s = 3.0;
  int64_t max_missed = 0, max_out_of_order = 0, max_queue_dropped = 0, max_rejected = 0,
          max_seq_gaps = 0;
};

// One sentence per problem: silent or stalled processes, decode failures or handler errors a
// process reports in its status, and losses beyond the thresholds.
std::vector<std::string> process_problems(const ProcessSummaries& processes,
                                          const Thresholds& t = {});

// The JSON of the summaries: an object with one entry per channel, per process. Times in s,
// rates in Hz, memory in bytes, counts in messages; a figure that cannot be known is null.
Json channels_json(const ChannelSummaries& channels);
Json processes_json(const ProcessSummaries& processes);

// Human-readable tables, one line per channel or process (plus detail lines), ending in '\n'.
std::string channel_table(const ChannelSummaries& channels);
std::string process_table(const ProcessSummaries& processes);

}  // namespace traverse::validate
