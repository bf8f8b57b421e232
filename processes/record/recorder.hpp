// Writes every message a live bus receives into an LCM log file, each stamped with the time it
// was received, as Debian's lcm-logger does, but through the bus (common/bus.hpp): LCM keeps at
// most 30 messages per subscription by default and drops the rest without a count, and
// lcm-logger keeps that default, so on a loaded machine its log silently lacked messages the
// processes themselves had received (a live graph beside a browser drawing the viewer's page:
// 5 to 11 of 2,863 scans). The bus raises LCM's queue, reads the socket on a thread of its own
// into a queue of bounded size, and counts what that queue must drop in the process's status
// (receive_queue_dropped), where the monitor judges it.
#pragma once

#include <cstdint>
#include <memory>
#include <regex>
#include <string>
#include <unordered_map>

#include "bus.hpp"
#include "lcm_log.hpp"

namespace traverse::record {

// traverse-record has no keys of its own; its config file may hold the `input:` section every
// process accepts (the receive queue's size: input.max_queue_bytes).
struct RecordConfig {
  template <class V>
  void visit(V&) {}
};

class Recorder {
 public:
  // Writes to `path` (replaced if it exists). Channels whose whole name matches `without` (a
  // regular expression, ECMAScript; empty: none) are left out, and so is LCM's own start-up probe,
  // LCM_SELF_TEST. Throws std::runtime_error if the file cannot be opened or `without` is no
  // regular expression.
  Recorder(Bus& bus, const std::string& path, const std::string& without);
  ~Recorder();
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  // Hands what was written to the operating system: a recorder killed afterwards leaves a log
  // that reads up to here.
  void flush();

  int64_t events() const { return log_->events(); }  // written
  int64_t bytes() const { return bytes_; }      // of message data written
  int64_t skipped() const { return skipped_; }  // left out by --without
  int64_t write_errors() const { return write_errors_; }

 private:
  void on_message(const std::string& channel, const uint8_t* data, int size, int64_t recv_utime);
  bool wanted(const std::string& channel);

  Bus& bus_;
  Bus::Handle handle_ = nullptr;
  std::unique_ptr<LogWriter> log_;
  std::regex without_;
  bool has_without_ = false;
  std::unordered_map<std::string, bool> wanted_;  // by channel, decided once
  int64_t bytes_ = 0, skipped_ = 0, write_errors_ = 0;
};

}  // namespace traverse::record
