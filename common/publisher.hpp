// Where a process's messages go: a live LCM bus, or an LCM log file (drivers' --out). Both encode
// the same way and stamp each message with a per-channel sequence number so loss is noticed.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "channel_stats.hpp"

namespace lcm {
class LogFile;
}

namespace traverse {

class Publisher {
 public:
  virtual ~Publisher() = default;

  // Encodes and sends `msg`; if the type has a `seq` field it is set to this channel's next number.
  template <class T>
  void publish(const std::string& channel, T& msg) {
    ChannelStats& s = stats_[channel];
    if constexpr (requires { msg.seq; }) msg.seq = ++s.last_seq;
    std::vector<uint8_t> buf(msg.getEncodedSize());
    msg.encode(buf.data(), 0, static_cast<int>(buf.size()));
    send(channel, buf.data(), buf.size(), msg.utime);
    ++s.published;
    s.last_utime = msg.utime;
  }

  const ChannelStatsMap& stats() const { return stats_; }

  // Counts a message this process sent on `channel` by other means (its status, StatusBeat).
  void note_published(const std::string& channel, int64_t utime, int64_t seq) {
    ChannelStats& s = stats_[channel];
    ++s.published;
    s.last_utime = utime;
    s.last_seq = seq;
  }

 protected:
  // `utime` is the message's own time: a log file uses it as the event time.
  virtual void send(const std::string& channel, const uint8_t* data, std::size_t size,
                    int64_t utime) = 0;
  ChannelStatsMap stats_;
};

// Writes messages as events of an LCM log file, event time = message utime, so that a log
// produced from the same input is byte-identical.
class LogFilePublisher : public Publisher {
 public:
  explicit LogFilePublisher(const std::string& path);  // throws std::runtime_error
  ~LogFilePublisher() override;

 protected:
  void send(const std::string& channel, const uint8_t* data, std::size_t size,
            int64_t utime) override;

 private:
  std::unique_ptr<lcm::LogFile> log_;
  int64_t event_number_ = 0;
};

}  // namespace traverse
