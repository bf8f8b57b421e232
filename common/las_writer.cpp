#include "las_writer.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <ctime>
#include <limits>

namespace traverse {

namespace {

constexpr uint16_t kHeaderSize = 375;          // LAS 1.4 public header block
constexpr uint16_t kVlrHeaderSize = 54;        // variable length record header
constexpr uint16_t kExtraDescriptor = 192;     // one Extra Bytes descriptor
constexpr int kFormat7Length = 36;             // point data record format 7 without extra bytes
constexpr double kGpsEpochUnix = 315964800.0;  // 1980-01-06T00:00:00Z in Unix seconds
constexpr double kGpsMinusUtc = 18.0;          // [s] leap seconds since 2017-01-01

// Little-endian field writer into a byte buffer.
struct Bytes {
  std::vector<char> b;
  template <class T>
  void put(T v) {
    char raw[sizeof(T)];
    std::memcpy(raw, &v, sizeof(T));
    b.insert(b.end(), raw, raw + sizeof(T));
  }
  void text(const std::string& s, std::size_t width) {  // zero-padded, truncated to width - 1
    std::string t = s.substr(0, width - 1);
    t.resize(width, '\0');
    b.insert(b.end(), t.begin(), t.end());
  }
  void zeros(std::size_t n) { b.insert(b.end(), n, '\0'); }
};

int extra_size(LasExtraField::Type t) {
  switch (t) {
    case LasExtraField::Type::kU8:
      return 1;
    case LasExtraField::Type::kU16:
      return 2;
    case LasExtraField::Type::kF32:
      return 4;
  }
  return 0;
}

void vlr_header(Bytes& out, const char* user, uint16_t record_id, std::size_t length,
                const char* description) {
  out.put<uint16_t>(0);
  out.text(user, 16);
  out.put<uint16_t>(record_id);
  out.put<uint16_t>(static_cast<uint16_t>(length));
  out.text(description, 32);
}

}  // namespace

double unix_to_adjusted_gps(double unix_time_s) {
  return unix_time_s - kGpsEpochUnix + kGpsMinusUtc - 1e9;
}

LasWriter::LasWriter(std::string path, std::string frame_wkt, std::vector<LasExtraField> extra,
                     std::string software, double scale_m)
    : path_(std::move(path)),
      wkt_(std::move(frame_wkt)),
      software_(std::move(software)),
      extra_(std::move(extra)),
      scale_(scale_m) {
  record_length_ = kFormat7Length;
  for (const auto& f : extra_) record_length_ += extra_size(f.type);
  min_.fill(std::numeric_limits<double>::infinity());
  max_.fill(-std::numeric_limits<double>::infinity());
  file_ = std::fopen(path_.c_str(), "wb");
  if (!file_) {
    fail("cannot write " + path_);
    return;
  }
  write_header();
}

LasWriter::~LasWriter() { close(); }

bool LasWriter::fail(const std::string& why) {
  if (ok_) error_ = why;
  ok_ = false;
  return false;
}

bool LasWriter::write_header() {
  Bytes h;
  h.text("LASF", 5);
  h.b.pop_back();             // "LASF" without a terminator
  h.put<uint16_t>(0);         // file source id
  h.put<uint16_t>(1u | 16u);  // global encoding: adjusted standard GPS time, CRS as WKT
  h.zeros(16);                // project GUID
  h.put<uint8_t>(1);
  h.put<uint8_t>(4);
  h.text("OTHER", 32);  // system identifier: not an airborne system
  h.text(software_, 32);
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  h.put<uint16_t>(static_cast<uint16_t>(utc.tm_yday + 1));
  h.put<uint16_t>(static_cast<uint16_t>(utc.tm_year + 1900));
  h.put<uint16_t>(kHeaderSize);
  const std::size_t wkt_len = wkt_.size() + 1;
  const std::size_t vlrs_size =
      kVlrHeaderSize + wkt_len +
      (extra_.empty() ? 0 : kVlrHeaderSize + kExtraDescriptor * extra_.size());
  point_offset_ = static_cast<uint32_t>(kHeaderSize + vlrs_size);
  h.put<uint32_t>(point_offset_);
  h.put<uint32_t>(extra_.empty() ? 1 : 2);  // number of VLRs
  h.put<uint8_t>(7);                        // point data record format
  h.put<uint16_t>(static_cast<uint16_t>(record_length_));
  h.put<uint32_t>(0);  // legacy point count: 0 for formats 6-10
  h.zeros(5 * 4);      // legacy points by return
  for (int i = 0; i < 3; ++i) h.put<double>(scale_);
  for (int i = 0; i < 3; ++i) h.put<double>(offset_[i]);
  const bool any = count_ > 0;
  for (int i = 0; i < 3; ++i) {
    h.put<double>(any ? max_[i] : 0.0);
    h.put<double>(any ? min_[i] : 0.0);
  }
  h.put<uint64_t>(0);       // start of waveform data
  h.put<uint64_t>(0);       // start of first EVLR
  h.put<uint32_t>(0);       // number of EVLRs
  h.put<uint64_t>(count_);  // number of point records
  h.put<uint64_t>(count_);  // points by return: every point is a first (single) return
  h.zeros(14 * 8);
  // VLR: the frame as OGC WKT (LASF_Projection, record 2112), null-terminated.
  vlr_header(h, "LASF_Projection", 2112, wkt_len, "OGC WKT: the frame of X, Y, Z");
  h.b.insert(h.b.end(), wkt_.begin(), wkt_.end());
  h.b.push_back('\0');
  if (!extra_.empty()) {
    vlr_header(h, "LASF_Spec", 4, kExtraDescriptor * extra_.size(), "Extra Bytes");
    for (const auto& f : extra_) {
      h.zeros(2);
      h.put<uint8_t>(static_cast<uint8_t>(f.type));
      h.put<uint8_t>(0);  // options: no no_data, min, max, scale or offset
      h.text(f.name, 32);
      h.zeros(4 + 24 * 5);  // unused, no_data/min/max with deprecated fields, scale, offset
      h.text(f.description, 32);
    }
  }
  if (h.b.size() != point_offset_) return fail("LAS header layout error (internal)");
  if (std::fseek(file_, 0, SEEK_SET) != 0 ||
      std::fwrite(h.b.data(), 1, h.b.size(), file_) != h.b.size()) {
    return fail("cannot write the header of " + path_);
  }
  return true;
}

bool LasWriter::add(const LasPoint& p) {
  if (!good()) return false;
  if (p.extra.size() != extra_.size()) return fail("point with the wrong number of extra values");
  if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
    return fail("non-finite point coordinate");
  }
  const double xyz[3] = {p.x, p.y, p.z};
  if (!have_offset_) {
    // Offsets rounded to whole metres, from the first point: the header is rewritten at close.
    for (int i = 0; i < 3; ++i) offset_[i] = std::floor(xyz[i]);
    have_offset_ = true;
  }
  Bytes r;
  r.b.reserve(static_cast<std::size_t>(record_length_));
  for (int i = 0; i < 3; ++i) {
    const double counts = std::round((xyz[i] - offset_[i]) / scale_);
    if (std::abs(counts) > 2147483647.0) return fail("point too far from the first for the scale");
    r.put<int32_t>(static_cast<int32_t>(counts));
    min_[i] = std::min(min_[i], offset_[i] + counts * scale_);
    max_[i] = std::max(max_[i], offset_[i] + counts * scale_);
  }
  r.put<uint16_t>(p.intensity);
  r.put<uint8_t>(0x11);  // return 1 of 1
  r.put<uint8_t>(0);     // classification flags, channel, scan direction, edge
  r.put<uint8_t>(p.classification);
  r.put<uint8_t>(0);   // user data
  r.put<int16_t>(0);   // scan angle
  r.put<uint16_t>(0);  // point source id
  r.put<double>(unix_to_adjusted_gps(p.unix_time_s));
  r.put<uint16_t>(p.red);
  r.put<uint16_t>(p.green);
  r.put<uint16_t>(p.blue);
  for (std::size_t i = 0; i < extra_.size(); ++i) {
    switch (extra_[i].type) {
      case LasExtraField::Type::kU8:
        r.put<uint8_t>(static_cast<uint8_t>(std::clamp(p.extra[i], 0.0, 255.0)));
        break;
      case LasExtraField::Type::kU16:
        r.put<uint16_t>(static_cast<uint16_t>(std::clamp(p.extra[i], 0.0, 65535.0)));
        break;
      case LasExtraField::Type::kF32:
        r.put<float>(static_cast<float>(p.extra[i]));
        break;
    }
  }
  buffer_.insert(buffer_.end(), r.b.begin(), r.b.end());
  ++count_;
  if (buffer_.size() >= (1u << 22)) {
    if (std::fwrite(buffer_.data(), 1, buffer_.size(), file_) != buffer_.size()) {
      return fail("cannot write the points of " + path_);
    }
    buffer_.clear();
  }
  return true;
}

bool LasWriter::close() {
  if (!file_) return ok_;
  if (ok_ && !buffer_.empty() &&
      std::fwrite(buffer_.data(), 1, buffer_.size(), file_) != buffer_.size()) {
    fail("cannot write the points of " + path_);
  }
  buffer_.clear();
  if (ok_) write_header();
  if (std::fclose(file_) != 0) fail("cannot close " + path_);
  file_ = nullptr;
  return ok_;
}

}  // namespace traverse
