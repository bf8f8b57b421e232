// Files a process keeps its state in, so that after a crash (SIGKILL, an out-of-memory kill) or
// between two sessions it resumes where it was instead of starting again.
//
// Two kinds, both checked on reading so that a file torn by the crash is never taken for state:
//   - a snapshot, rewritten whole: written to `path.tmp`, then renamed over `path` (rename is
//     atomic on POSIX file systems), so `path` always holds either the previous snapshot or the
//     new one, complete. That holds whenever the process dies; to hold through a power cut or a
//     kernel crash too, the file must reach the disk before the rename (`durable`: fdatasync),
//     which on a busy disk costs tens of milliseconds a snapshot. Layout: 8-byte magic, payload
//     size (uint64), payload, FNV-1a 64 hash of the payload.
//   - a record log, appended to: one record per item that never changes once written (a key
//     scan, a profile), so that a snapshot need not rewrite them. Each record: payload size
//     (uint32), payload, FNV-1a 64 hash; reading stops at the first torn or damaged record. The
//     snapshot says how many records it covers; records beyond that (appended after it) are cut
//     off when the state is resumed.
// Values are written in the machine's byte order: the files are for the machine that wrote them.
#pragma once

#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "se2.hpp"

namespace traverse {

// Serialises plain values into a byte string.
class StateWriter {
 public:
  template <class T>
  void put(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto* p = reinterpret_cast<const char*>(&value);
    bytes_.append(p, sizeof(T));
  }
  void put(const std::string& s) {
    put<uint64_t>(s.size());
    bytes_.append(s);
  }
  void put(const Pose2& T) {
    put(T.x());
    put(T.y());
    put(T.theta());
  }
  template <class T>
  void put_vector(const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    put<uint64_t>(v.size());
    bytes_.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }
  const std::string& bytes() const { return bytes_; }

 private:
  std::string bytes_;
};

// Reads what a StateWriter wrote; every get fails (returns false, and ok() turns false) past the
// end instead of reading beyond it.
class StateReader {
 public:
  explicit StateReader(const std::string& bytes) : bytes_(bytes) {}
  template <class T>
  bool get(T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    if (!take(sizeof(T))) return false;
    std::memcpy(&value, bytes_.data() + at_ - sizeof(T), sizeof(T));
    return true;
  }
  bool get(std::string& s);
  bool get(Pose2& T);
  template <class T>
  bool get_vector(std::vector<T>& v, uint64_t max_size) {
    uint64_t n = 0;
    if (!get(n) || n > max_size || !take(n * sizeof(T))) return ok_ = false;
    v.resize(n);
    std::memcpy(v.data(), bytes_.data() + at_ - n * sizeof(T), n * sizeof(T));
    return true;
  }
  bool ok() const { return ok_; }
  bool at_end() const { return at_ == bytes_.size(); }

 private:
  bool take(std::size_t n);
  const std::string& bytes_;
  std::size_t at_ = 0;
  bool ok_ = true;
};

uint64_t fnv1a64(const char* data, std::size_t size);

// Writes a snapshot atomically (see the header); false, with `error` set, when it could not.
bool write_snapshot(const std::string& path, const std::string& magic, const std::string& payload,
                    bool durable = false, std::string* error = nullptr);
// The payload of a snapshot; nullopt when the file is missing. A file with another magic, or
// torn or damaged, gives nullopt with `error` saying so.
std::optional<std::string> read_snapshot(const std::string& path, const std::string& magic,
                                         std::string* error = nullptr);

// An append-only record log (see the header).
class RecordLog {
 public:
  RecordLog() = default;
  ~RecordLog();
  RecordLog(const RecordLog&) = delete;
  RecordLog& operator=(const RecordLog&) = delete;

  // Opens `path` for appending after its first `keep` intact records (the file is cut there);
  // false with `error` set when it has fewer, or cannot be opened.
  bool open(const std::string& path, std::size_t keep, std::string* error = nullptr);
  // Opens `path` for appending at byte `length` (the end of its intact records, as read() says;
  // what follows, a record torn by a crash, is cut off).
  bool open_at(const std::string& path, std::size_t length, std::string* error = nullptr);
  bool append(const std::string& payload);
  // Flushes what was appended to the disk (before a snapshot that counts it is renamed in).
  bool sync();
  bool is_open() const { return fd_ >= 0; }

  // The intact records of `path` from the start, at most `max` of them (a missing file: none);
  // `length`: set to the bytes they take.
  static std::vector<std::string> read(const std::string& path, std::size_t max,
                                       std::size_t* length = nullptr);
  // Replaces `path` atomically by a log of `records` (written aside, flushed, renamed over it):
  // a log compacted while the process may die.
  static bool write(const std::string& path, const std::vector<std::string>& records,
                    std::string* error = nullptr);

 private:
  int fd_ = -1;
};

}  // namespace traverse
