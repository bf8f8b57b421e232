#include "state_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace traverse {
namespace {

// A write of all `size` bytes; false on an error.
bool write_all(int fd, const char* data, std::size_t size) {
  while (size > 0) {
    const ssize_t n = ::write(fd, data, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    data += n;
    size -= static_cast<std::size_t>(n);
  }
  return true;
}

std::string read_file(const std::string& path, bool* exists) {
  std::ifstream in(path, std::ios::binary);
  *exists = static_cast<bool>(in);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void set(std::string* error, const std::string& text) {
  if (error) *error = text;
}

}  // namespace

bool StateReader::take(std::size_t n) {
  if (!ok_ || bytes_.size() - at_ < n) return ok_ = false;
  at_ += n;
  return true;
}

bool StateReader::get(std::string& s) {
  uint64_t n = 0;
  if (!get(n) || !take(n)) return ok_ = false;
  s.assign(bytes_, at_ - n, n);
  return true;
}

bool StateReader::get(Pose2& T) {
  double x = 0, y = 0, theta = 0;
  if (!get(x) || !get(y) || !get(theta)) return false;
  T = Pose2(x, y, theta);
  return true;
}

uint64_t fnv1a64(const char* data, std::size_t size) {
  uint64_t h = 1469598103934665603ULL;
  for (std::size_t i = 0; i < size; ++i) {
    h ^= static_cast<unsigned char>(data[i]);
    h *= 1099511628211ULL;
  }
  return h;
}

bool write_snapshot(const std::string& path, const std::string& magic, const std::string& payload,
                    bool durable, std::string* error) {
  StateWriter head;
  head.put<uint64_t>(payload.size());
  const uint64_t hash = fnv1a64(payload.data(), payload.size());
  const std::string tmp = path + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) {
    set(error, "cannot write " + tmp);
    return false;
  }
  bool ok = write_all(fd, magic.data(), magic.size()) &&
            write_all(fd, head.bytes().data(), head.bytes().size()) &&
            write_all(fd, payload.data(), payload.size()) &&
            write_all(fd, reinterpret_cast<const char*>(&hash), sizeof(hash));
  if (durable) ok = ::fdatasync(fd) == 0 && ok;
  ok = ::close(fd) == 0 && ok;
  if (!ok || std::rename(tmp.c_str(), path.c_str()) != 0) {
    set(error, "cannot write " + path);
    std::remove(tmp.c_str());
    return false;
  }
  return true;
}

std::optional<std::string> read_snapshot(const std::string& path, const std::string& magic,
                                         std::string* error) {
  bool exists = false;
  const std::string bytes = read_file(path, &exists);
  if (!exists) return std::nullopt;
  const std::size_t head = magic.size() + sizeof(uint64_t);
  if (bytes.size() < head + sizeof(uint64_t) || bytes.compare(0, magic.size(), magic) != 0) {
    set(error, path + " is not a state file of this kind");
    return std::nullopt;
  }
  uint64_t size = 0;
  std::memcpy(&size, bytes.data() + magic.size(), sizeof(size));
  if (size != bytes.size() - head - sizeof(uint64_t)) {
    set(error, path + " is truncated or damaged (its size does not match)");
    return std::nullopt;
  }
  uint64_t hash = 0;
  std::memcpy(&hash, bytes.data() + head + size, sizeof(hash));
  if (hash != fnv1a64(bytes.data() + head, size)) {
    set(error, path + " is damaged (its checksum does not match)");
    return std::nullopt;
  }
  return bytes.substr(head, size);
}

RecordLog::~RecordLog() {
  if (fd_ >= 0) ::close(fd_);
}

namespace {
// One record as a log holds it: size, payload, hash.
std::string record_bytes(const std::string& payload) {
  const auto size = static_cast<uint32_t>(payload.size());
  const uint64_t hash = fnv1a64(payload.data(), payload.size());
  std::string record(reinterpret_cast<const char*>(&size), sizeof(size));
  record += payload;
  record.append(reinterpret_cast<const char*>(&hash), sizeof(hash));
  return record;
}
}  // namespace

std::vector<std::string> RecordLog::read(const std::string& path, std::size_t max,
                                         std::size_t* length) {
  bool exists = false;
  const std::string bytes = read_file(path, &exists);
  std::vector<std::string> out;
  std::size_t at = 0;
  while (out.size() < max && bytes.size() - at >= sizeof(uint32_t)) {
    uint32_t size = 0;
    std::memcpy(&size, bytes.data() + at, sizeof(size));
    if (bytes.size() - at - sizeof(size) < static_cast<std::size_t>(size) + sizeof(uint64_t)) break;
    const char* payload = bytes.data() + at + sizeof(size);
    uint64_t hash = 0;
    std::memcpy(&hash, payload + size, sizeof(hash));
    if (hash != fnv1a64(payload, size)) break;
    out.emplace_back(payload, size);
    at += sizeof(size) + size + sizeof(hash);
  }
  if (length) *length = at;
  return out;
}

bool RecordLog::write(const std::string& path, const std::vector<std::string>& records,
                      std::string* error) {
  const std::string tmp = path + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  bool ok = fd >= 0;
  for (std::size_t i = 0; ok && i < records.size(); ++i) {
    const std::string r = record_bytes(records[i]);
    ok = write_all(fd, r.data(), r.size());
  }
  if (fd >= 0) ok = ::fdatasync(fd) == 0 && ::close(fd) == 0 && ok;
  if (!ok || std::rename(tmp.c_str(), path.c_str()) != 0) {
    set(error, "cannot write " + path);
    std::remove(tmp.c_str());
    return false;
  }
  return true;
}

bool RecordLog::open(const std::string& path, std::size_t keep, std::string* error) {
  const std::vector<std::string> kept = read(path, keep);
  if (kept.size() < keep) {
    set(error, path + " holds " + std::to_string(kept.size()) + " intact records, " +
                   std::to_string(keep) + " expected");
    return false;
  }
  std::size_t length = 0;
  for (const std::string& r : kept) length += sizeof(uint32_t) + r.size() + 8;
  return open_at(path, length, error);
}

bool RecordLog::open_at(const std::string& path, std::size_t size, std::string* error) {
  if (fd_ >= 0) ::close(fd_);
  const auto length = static_cast<off_t>(size);
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0 || ::ftruncate(fd_, length) != 0 || ::lseek(fd_, length, SEEK_SET) != length) {
    set(error, "cannot append to " + path);
    return false;
  }
  return true;
}

bool RecordLog::append(const std::string& payload) {
  if (fd_ < 0) return false;
  const std::string record = record_bytes(payload);
  return write_all(fd_, record.data(), record.size());
}

bool RecordLog::sync() { return fd_ >= 0 && ::fdatasync(fd_) == 0; }

}  // namespace traverse
