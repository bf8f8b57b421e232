#include "recorder.hpp"

#include <cstdio>
#include <stdexcept>

namespace traverse::record {

Recorder::Recorder(Bus& bus, const std::string& path, const std::string& without) : bus_(bus) {
  if (!without.empty()) {
    try {
      without_ = std::regex(without, std::regex::ECMAScript);
    } catch (const std::regex_error& e) {
      throw std::runtime_error("'" + without + "' is not a regular expression: " + e.what());
    }
    has_without_ = true;
  }
  log_ = std::make_unique<LogWriter>(path);
  if (!log_->good()) throw std::runtime_error("cannot write " + path);
  handle_ = bus_.subscribe_raw(
      ".*", [this](const std::string& channel, const uint8_t* data, int size, int64_t recv_utime) {
        on_message(channel, data, size, recv_utime);
      });
}

Recorder::~Recorder() {
  bus_.unsubscribe(handle_);
  flush();
}

bool Recorder::wanted(const std::string& channel) {
  auto [it, added] = wanted_.try_emplace(channel, true);
  if (added) {
    it->second = !(has_without_ && std::regex_match(channel, without_));
  }
  return it->second;
}

void Recorder::on_message(const std::string& channel, const uint8_t* data, int size,
                          int64_t recv_utime) {
  if (channel == "LCM_SELF_TEST") return;  // udpm's start-up probe, not part of the run
  if (!wanted(channel)) {
    ++skipped_;
    return;
  }
  if (!log_->write(channel, data, static_cast<std::size_t>(size), recv_utime)) {
    ++write_errors_;
    return;
  }
  bytes_ += size;
}

void Recorder::flush() {
  if (log_ && !log_->flush()) ++write_errors_;
}

}  // namespace traverse::record
