// Checks the message streams of an LCM log or a live bus, channel by channel, from raw events
// (channel, event time, bytes) -- the checks a rosbag validator makes, for LCM.
//
// A message's type is told by its LCM fingerprint (its first 8 bytes) through the type registry,
// so a new message type needs no change here. A channel's type is the type most of its messages
// decode as; a message that does not decode completely as that type (unknown fingerprint, another
// type's fingerprint, or bytes that do not decode) is a decode failure. Per channel it counts
// messages, the mean rate and largest gap of the event times, timestamps going backwards (event
// time, and the message's own utime where the type has one), skipped sequence numbers, and the
// facts the registry extracts (points per scan, sweep time, frames). A message whose bytes do not
// hold what it claims is never decoded (message_layout.hpp); one that decodes but cannot be right
// or exceeds a limit is counted as rejected, as a subscriber would reject it (message_checks.hpp);
// stamps far from their neighbours are counted as a subscriber would drop them (stamp_order.hpp).
//
// Memory is bounded by the number of channels and types, never by the number of messages, so a
// log of any size streams through.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "input_config.hpp"
#include "stamp_order.hpp"
#include "type_registry.hpp"

namespace traverse::validate {

// Min/max of an integer quantity seen in a stream.
struct Range {
  int64_t min = 0;
  int64_t max = 0;
  bool empty = true;
  void add(int64_t v);
};

// The summary of one channel.
struct ChannelSummary {
  std::string type;                 // e.g. "traverse.planar_scan_t"; "" if nothing decodes
  int64_t count = 0;                // [messages] events on the channel, decodable or not
  int64_t first_event_utime = 0;    // [us]
  int64_t last_event_utime = 0;     // [us]
  std::optional<double> rate_hz;    // [Hz] (count - 1) / event time span; none below 2 messages
  std::optional<double> max_gap_s;  // [s] largest forward step of the event time
  int64_t event_backwards = 0;      // [messages] event time earlier than the previous event's
  int64_t utime_backwards = 0;      // [messages] message utime earlier than the previous one's
  int64_t backwards = 0;            // [messages] either of the two (a message counts once)
  std::optional<double> max_backstep_s;  // [s] largest step back of either time
  int64_t seq_gaps = 0;                  // [messages] sequence numbers skipped
  int64_t seq_restarts = 0;              // [messages] sequence number not above the previous one
  int64_t decode_failures = 0;           // [messages] did not decode as the channel's type
  int64_t unknown_fingerprint = 0;       // [messages] of those: fingerprint of no known type
  int64_t undecodable = 0;  // [messages] of those: known fingerprint, bytes do not decode
  std::map<std::string, int64_t> other_types;  // of those: [messages] decoding as another type
  int64_t rejected = 0;         // [messages] cannot be right or beyond a limit (message_checks.hpp)
  std::string first_rejection;  // why the first of those was rejected
  int64_t stamp_outliers = 0;   // [messages] utime far from both neighbours (stamp_order.hpp)
  int64_t time_jumps = 0;       // [messages] utime jumped far and the stream went on from there
  Range points;                 // [points] per message, types with n_ranges
  Range sweep_us;               // [us] utime_last - utime_first, types with both
  std::optional<double> period_s;  // [s] mean step of the message utime
  std::set<std::string> frames;    // frames named by the messages (at most kMaxFrames)

  bool clean() const {
    return decode_failures == 0 && backwards == 0 && rejected == 0 && stamp_outliers == 0;
  }
};

inline constexpr std::size_t kMaxFrames = 8;

class StreamAnalyzer {
 public:
  // Limits and the stamp jump as every process applies them (input_config.hpp).
  explicit StreamAnalyzer(const InputConfig& input = {})
      : limits_(array_limits(input)),
        max_stamp_jump_us_(static_cast<int64_t>(1e6 * input.max_stamp_jump_s)) {}

  // Feeds one event. `event_utime` [us] is the log's event time or the receive time.
  void add(const std::string& channel, int64_t event_utime, const void* data, std::size_t size);

  std::map<std::string, ChannelSummary> summary() const;
  int64_t events() const { return events_; }

 private:
  // What the messages of one type on one channel said about themselves.
  struct TypeStream {
    explicit TypeStream(int64_t max_jump_us) : order(max_jump_us) {}
    int64_t decoded = 0;
    StampOrder order;  // what a subscriber would deliver, hold back or drop
    std::optional<int64_t> first_utime, last_utime, last_seq;
    int64_t utime_backwards = 0;
    int64_t utime_only_backwards = 0;  // utime went back, the event time did not
    std::optional<int64_t> max_backstep_us;
    int64_t seq_gaps = 0;
    int64_t seq_restarts = 0;
    Range points, sweep_us;
    std::set<std::string> frames;
    void add(const MessageFacts& f, bool event_went_back);
  };
  struct Channel {
    int64_t count = 0;
    int64_t first_event = 0, last_event = 0;
    int64_t event_backwards = 0;
    std::optional<int64_t> max_gap_us, max_backstep_us;
    int64_t undecodable = 0;  // fingerprint known but bytes do not decode
    int64_t unknown_fingerprint = 0;
    int64_t rejected = 0;
    std::string first_rejection;
    std::map<std::string, TypeStream> types;  // by type name
  };

  std::vector<ArrayLimit> limits_;
  int64_t max_stamp_jump_us_;
  std::map<std::string, Channel> channels_;
  int64_t events_ = 0;
};

}  // namespace traverse::validate
