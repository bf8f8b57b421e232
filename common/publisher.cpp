#include "publisher.hpp"

#include <lcm/lcm-cpp.hpp>

#include <stdexcept>

namespace traverse {

LogFilePublisher::LogFilePublisher(const std::string& path)
    : log_(std::make_unique<lcm::LogFile>(path, "w")) {
  if (!log_->good()) throw std::runtime_error("cannot write LCM log: " + path);
}

LogFilePublisher::~LogFilePublisher() = default;

void LogFilePublisher::send(const std::string& channel, const uint8_t* data, std::size_t size,
                            int64_t utime) {
  lcm::LogEvent ev;
  ev.eventnum = event_number_++;
  ev.timestamp = utime;
  ev.channel = channel;
  ev.datalen = static_cast<int32_t>(size);
  ev.data = const_cast<uint8_t*>(data);
  if (log_->writeEvent(&ev) != 0) throw std::runtime_error("write to LCM log failed");
}

}  // namespace traverse
