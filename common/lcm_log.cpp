#include "lcm_log.hpp"

#include <stdexcept>

namespace traverse {
namespace {

constexpr uint32_t kSyncWord = 0xEDA1DA01;
constexpr std::size_t kHeaderBytes = 4 + 8 + 8 + 4 + 4;
constexpr int32_t kMaxChannelBytes = 256;     // LCM allows 63; leave room, reject garbage
constexpr int32_t kMaxDataBytes = 256 << 20;  // 256 MiB: anything larger is a broken header

uint64_t read_be(const uint8_t* p, int n) {
  uint64_t v = 0;
  for (int i = 0; i < n; ++i) v = (v << 8) | p[i];
  return v;
}

}  // namespace

LogReader::LogReader(const std::string& path) : LogReader(std::fopen(path.c_str(), "rb")) {
  if (!file_) throw std::runtime_error("cannot open LCM log: " + path);
}

LogReader::LogReader(std::FILE* file) : file_(file) {
  if (!file_) return;
  std::fseek(file_, 0, SEEK_END);
  file_size_ = static_cast<uint64_t>(std::ftell(file_));
  std::fseek(file_, 0, SEEK_SET);
}

LogReader::~LogReader() {
  if (file_) std::fclose(file_);
}

std::optional<LogEvent> LogReader::read_at(uint64_t offset, std::string& problem) {
  std::fseek(file_, static_cast<long>(offset), SEEK_SET);
  uint8_t h[kHeaderBytes];
  const std::size_t got = std::fread(h, 1, kHeaderBytes, file_);
  if (got < 4 || read_be(h, 4) != kSyncWord) {
    problem = got < 4 ? "truncated record header" : "bad sync word";
    return std::nullopt;
  }
  if (got < kHeaderBytes) {
    problem = "truncated record header";
    return std::nullopt;
  }
  LogEvent ev;
  ev.offset = offset;
  ev.event_number = static_cast<int64_t>(read_be(h + 4, 8));
  ev.utime = static_cast<int64_t>(read_be(h + 12, 8));
  const auto channel_len = static_cast<int32_t>(read_be(h + 20, 4));
  const auto data_len = static_cast<int32_t>(read_be(h + 24, 4));
  if (channel_len <= 0 || channel_len > kMaxChannelBytes || data_len < 0 ||
      data_len > kMaxDataBytes) {
    problem = "corrupt record header (channel length " + std::to_string(channel_len) +
              ", data length " + std::to_string(data_len) + ")";
    return std::nullopt;
  }
  const uint64_t end = offset + kHeaderBytes + channel_len + data_len;
  if (end > file_size_) {
    problem = "truncated record (needs " + std::to_string(channel_len + data_len) +
              " bytes after its header, file has " +
              std::to_string(file_size_ - offset - kHeaderBytes) + ")";
    return std::nullopt;
  }
  ev.channel.resize(channel_len);
  ev.data.resize(data_len);
  if (std::fread(ev.channel.data(), 1, channel_len, file_) !=
          static_cast<std::size_t>(channel_len) ||
      std::fread(ev.data.data(), 1, data_len, file_) != static_cast<std::size_t>(data_len)) {
    problem = "read error";
    return std::nullopt;
  }
  if (!ends_at_record(end, ev.event_number)) {
    problem = "corrupt record length (data length " + std::to_string(data_len) +
              " does not end where a record starts)";
    return std::nullopt;
  }
  return ev;
}

bool LogReader::ends_at_record(uint64_t end, int64_t event_number) {
  if (end == file_size_) return true;
  uint8_t sync[4];
  std::fseek(file_, static_cast<long>(end), SEEK_SET);
  if (end + 4 <= file_size_ && std::fread(sync, 1, 4, file_) == 4 &&
      read_be(sync, 4) == kSyncWord) {
    return true;
  }
  return header_after(end, event_number);
}

bool LogReader::header_after(uint64_t offset, int64_t event_number) {
  uint8_t h[kHeaderBytes];
  std::fseek(file_, static_cast<long>(offset), SEEK_SET);
  if (offset + kHeaderBytes > file_size_ || std::fread(h, 1, kHeaderBytes, file_) != kHeaderBytes) {
    return false;
  }
  const auto channel_len = static_cast<int32_t>(read_be(h + 20, 4));
  const auto data_len = static_cast<int32_t>(read_be(h + 24, 4));
  return static_cast<int64_t>(read_be(h + 4, 8)) == event_number + 1 && channel_len > 0 &&
         channel_len <= kMaxChannelBytes && data_len >= 0 && data_len <= kMaxDataBytes;
}

bool LogReader::resync(uint64_t from) {
  std::fseek(file_, static_cast<long>(from), SEEK_SET);
  uint32_t window = 0;
  uint64_t pos = from;
  int c;
  while ((c = std::fgetc(file_)) != EOF) {
    window = (window << 8) | static_cast<uint32_t>(c);
    ++pos;
    if (pos - from >= 4 && window == kSyncWord) {
      pos_ = pos - 4;
      return true;
    }
  }
  pos_ = file_size_;
  return false;
}

std::optional<LogEvent> LogReader::next() {
  while (pos_ < file_size_) {
    std::string problem;
    if (auto ev = read_at(pos_, problem)) {
      pos_ += kHeaderBytes + ev->channel.size() + ev->data.size();
      return ev;
    }
    const uint64_t damaged_at = pos_;
    const bool found = resync(damaged_at + 1);
    // A record running past the end with records after it: its length is wrong, not the file cut.
    if (found && problem.rfind("truncated record (", 0) == 0) {
      problem = "corrupt record length (runs past the end of the file)";
    }
    damage_.push_back({damaged_at, problem, pos_ - damaged_at});
  }
  return std::nullopt;
}

bool LogWriter::write(const std::string& channel, const uint8_t* data, std::size_t size,
                      int64_t utime) {
  lcm::LogEvent ev;
  ev.eventnum = events_;
  ev.timestamp = utime;
  ev.channel = channel;
  ev.datalen = static_cast<int32_t>(size);
  ev.data = const_cast<uint8_t*>(data);
  if (file_.writeEvent(&ev) != 0) return false;
  ++events_;
  return true;
}

}  // namespace traverse
