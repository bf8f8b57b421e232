// Reads LCM log files event by event, and says exactly where and how a damaged file is damaged.
//
// The format (LCM's eventlog): each event is a big-endian header -- sync word 0xEDA1DA01,
// int64 event number, int64 timestamp [us], int32 channel length, int32 data length -- followed
// by the channel name and the data. lcm::LogFile stops silently at damage; this reader reports
// the byte offset, then looks for the next sync word so that everything readable is still read.
//
// A record is taken only when it ends where the next one starts (or at the end of the file): a
// corrupt length field would otherwise read the start of the next record as this one's data and
// report the damage at the next sync word instead of where it is. When a record's end is not at a
// sync word, the bytes there decide: a header with the next event number (only its sync word
// damaged) puts the damage there; anything else means this record's length is wrong.
#pragma once

#include <cstdint>
#include <cstdio>
#include <lcm/lcm-cpp.hpp>
#include <optional>
#include <string>
#include <vector>

namespace traverse {

struct LogEvent {
  int64_t event_number = 0;
  int64_t utime = 0;  // [us] event timestamp (receive time, or message time)
  std::string channel;
  std::vector<uint8_t> data;
  uint64_t offset = 0;  // [bytes] where the event's header starts in the file
};

struct LogDamage {
  uint64_t offset = 0;         // [bytes] where the damaged record starts
  std::string what;            // e.g. "truncated record", "bad sync word"
  uint64_t skipped_bytes = 0;  // [bytes] skipped until the next readable event (or the end)
};

class LogReader {
 public:
  explicit LogReader(const std::string& path);  // throws std::runtime_error if it cannot open
  // Reads an open file (e.g. fmemopen), which the reader closes.
  explicit LogReader(std::FILE* file);
  ~LogReader();
  LogReader(const LogReader&) = delete;
  LogReader& operator=(const LogReader&) = delete;

  // Next intact event, or nullopt at the end of the file. Damage met on the way is recorded.
  std::optional<LogEvent> next();

  const std::vector<LogDamage>& damage() const { return damage_; }
  uint64_t file_size() const { return file_size_; }

 private:
  // Reads an event at the current position; nullopt and records damage if it is not intact.
  std::optional<LogEvent> read_at(uint64_t offset, std::string& problem);
  // Whether a record ending at `end` ends where the next record starts (see the top).
  bool ends_at_record(uint64_t end, int64_t event_number);
  // A header at `offset` whose fields are sane, its sync word aside.
  bool header_after(uint64_t offset, int64_t event_number);
  bool resync(uint64_t from);  // moves to the next sync word after `from`; false at end

  std::vector<LogDamage> damage_;
  std::FILE* file_ = nullptr;
  uint64_t file_size_ = 0;
  uint64_t pos_ = 0;
};

// Writes an LCM log file event by event, numbering the events from 0 (lcm::LogFile writes them):
// the one writer of the run log's recorder, a process's --record and the offline run's copy.
class LogWriter {
 public:
  explicit LogWriter(const std::string& path) : file_(path, "w") {}
  bool good() { return file_.good(); }
  // One event stamped `utime` [us]; false if it could not be written.
  bool write(const std::string& channel, const uint8_t* data, std::size_t size, int64_t utime);
  // Hands what was written to the operating system; false if that failed.
  bool flush() { return std::fflush(file_.getFilePtr()) == 0; }
  int64_t events() const { return events_; }

 private:
  lcm::LogFile file_;
  int64_t events_ = 0;
};

}  // namespace traverse
