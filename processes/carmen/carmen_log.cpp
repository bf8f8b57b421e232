#include "carmen_log.hpp"

#include <zlib.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <numbers>

namespace traverse::carmen {
namespace {

constexpr double kPi = std::numbers::pi;
// Timestamps beyond this are not seconds since any epoch a robot log could have [s].
constexpr double kMaxTimestampS = 1e11;

std::vector<std::string_view> split(std::string_view s) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t' || s[i] == '\r')) ++i;
    const std::size_t start = i;
    while (i < s.size() && s[i] != ' ' && s[i] != '\t' && s[i] != '\r') ++i;
    if (i > start) out.push_back(s.substr(start, i - start));
  }
  return out;
}

// A finite number, the whole token; nullopt otherwise.
std::optional<double> to_number(std::string_view tok) {
  double v = 0.0;
  const auto [end, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), v);
  if (ec != std::errc() || end != tok.data() + tok.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

std::optional<int> to_count(std::string_view tok) {
  int v = 0;
  const auto [end, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), v);
  if (ec != std::errc() || end != tok.data() + tok.size() || v < 0 || v > kMaxBeams) {
    return std::nullopt;
  }
  return v;
}

bool looks_like_type(std::string_view tok) {
  if (tok.empty() || tok.size() > 32) return false;
  for (char c : tok) {
    if (!((c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_')) return false;
  }
  return tok[0] >= 'A' && tok[0] <= 'Z';
}

// Reads tokens [first, first + n) as ranges [m]; false if any is not a finite non-negative number.
bool read_ranges(const std::vector<std::string_view>& t, std::size_t first, int n,
                 std::vector<float>& ranges) {
  ranges.resize(n);
  for (int i = 0; i < n; ++i) {
    const auto r = to_number(t[first + i]);
    if (!r || *r < 0.0) return false;
    ranges[i] = static_cast<float>(*r);
  }
  return true;
}

// Reads x y theta at `first`; false unless all three are finite.
bool read_pose(const std::vector<std::string_view>& t, std::size_t first, Scan& scan) {
  const auto x = to_number(t[first]), y = to_number(t[first + 1]), th = to_number(t[first + 2]);
  if (!x || !y || !th) return false;
  scan.x_m = *x;
  scan.y_m = *y;
  scan.theta_rad = *th;
  return true;
}

bool read_timestamp(std::string_view tok, Scan& scan) {
  const auto ts = to_number(tok);
  if (!ts || std::abs(*ts) > kMaxTimestampS) return false;
  scan.utime = std::llround(*ts * 1e6);
  scan.utime_quantum_s = printed_quantum(tok);
  return true;
}

// The logger timestamp is optional information: a bad one is ignored, not a malformed line.
void read_logger_timestamp(std::string_view tok, Scan& scan) {
  const auto ts = to_number(tok);
  if (!ts || std::abs(*ts) > kMaxTimestampS) return;
  scan.logger_utime = std::llround(*ts * 1e6);
  scan.logger_quantum_s = printed_quantum(tok);
}

ParsedLine parse_flaser(const std::vector<std::string_view>& t, int64_t line,
                        FlaserGeometry geometry) {
  const auto n = t.size() > 1 ? to_count(t[1]) : std::nullopt;
  if (!n || *n == 0) return Malformed{"FLASER: beam count is not a positive integer"};
  // n ranges, pose, odometry, timestamp, host, logger timestamp. Requiring the two trailing
  // fields means a line cut short inside the timestamp cannot pass as complete.
  const std::size_t needed = 2 + *n + 6 + 3;
  if (t.size() != needed) {
    return Malformed{"FLASER: " + std::to_string(t.size()) + " fields for " + std::to_string(*n) +
                     " beams"};
  }
  Scan scan;
  scan.type = "FLASER";
  scan.line = line;
  scan.beams = flaser_beam_angles(*n, geometry);
  if (!read_ranges(t, 2, *n, scan.ranges)) return Malformed{"FLASER: bad range"};
  if (!read_pose(t, 2 + *n, scan)) return Malformed{"FLASER: bad pose"};
  if (!read_timestamp(t[2 + *n + 6], scan)) return Malformed{"FLASER: bad timestamp"};
  read_logger_timestamp(t[2 + *n + 8], scan);
  return scan;
}

ParsedLine parse_robotlaser1(const std::vector<std::string_view>& t, int64_t line) {
  // laser_type start_angle fov resolution max_range accuracy remission_mode n
  if (t.size() < 9) return Malformed{"ROBOTLASER1: too few fields"};
  const auto start = to_number(t[2]), fov = to_number(t[3]), res = to_number(t[4]),
             max_range = to_number(t[5]);
  const auto n = to_count(t[8]);
  if (!start || !fov || !res || !max_range || !n || *n == 0) {
    return Malformed{"ROBOTLASER1: bad header"};
  }
  const std::size_t at_m = 9 + *n;
  const auto m = t.size() > at_m ? to_count(t[at_m]) : std::nullopt;
  if (!m) return Malformed{"ROBOTLASER1: bad remission count"};
  const std::size_t at_pose = at_m + 1 + *m;  // laser pose, robot pose, 5 motion fields, time
  if (t.size() != at_pose + 14) {
    return Malformed{"ROBOTLASER1: wrong number of fields"};
  }
  Scan scan;
  scan.type = "ROBOTLASER1";
  scan.line = line;
  scan.beams = {*start, *res};
  scan.range_max_m = *max_range;
  if (!read_ranges(t, 9, *n, scan.ranges)) return Malformed{"ROBOTLASER1: bad range"};
  if (!read_pose(t, at_pose, scan)) return Malformed{"ROBOTLASER1: bad laser pose"};
  if (!read_timestamp(t[at_pose + 11], scan)) return Malformed{"ROBOTLASER1: bad timestamp"};
  read_logger_timestamp(t[at_pose + 13], scan);
  return scan;
}

}  // namespace

double printed_quantum(std::string_view token) {
  std::size_t e = token.find_first_of("eE");
  int exponent = 0;
  if (e != std::string_view::npos) {
    std::string_view x = token.substr(e + 1);
    if (!x.empty() && x[0] == '+') x.remove_prefix(1);
    std::from_chars(x.data(), x.data() + x.size(), exponent);
  } else {
    e = token.size();
  }
  const std::string_view mantissa = token.substr(0, e);
  const std::size_t dot = mantissa.find('.');
  const int decimals = dot == std::string_view::npos ? 0 : static_cast<int>(e - dot - 1);
  return std::pow(10.0, exponent - decimals);
}

BeamAngles flaser_beam_angles(int n_beams, FlaserGeometry geometry) {
  const double n = std::max(n_beams, 2);
  switch (geometry) {
    case FlaserGeometry::kClosed:
      return {-kPi / 2, kPi / (n - 1)};
    case FlaserGeometry::kCentered:
      return {-kPi / 2 + kPi / (2 * n), kPi / n};
    case FlaserGeometry::kReversed:
      return {kPi / 2, -kPi / n};
    case FlaserGeometry::kStandard:
      return n_beams % 2 == 0 ? BeamAngles{-kPi / 2, kPi / n} : BeamAngles{-kPi / 2, kPi / (n - 1)};
    case FlaserGeometry::kHalfOpen:
      break;
  }
  return {-kPi / 2, kPi / n};
}

std::optional<FlaserGeometry> parse_flaser_geometry(std::string_view name) {
  if (name == "standard") return FlaserGeometry::kStandard;
  if (name == "half_open") return FlaserGeometry::kHalfOpen;
  if (name == "closed") return FlaserGeometry::kClosed;
  if (name == "centered") return FlaserGeometry::kCentered;
  if (name == "reversed") return FlaserGeometry::kReversed;
  return std::nullopt;
}

ParsedLine parse_line(std::string_view text, int64_t line_number, FlaserGeometry geometry) {
  const auto t = split(text);
  if (t.empty() || t[0][0] == '#') return Ignorable{};
  if (t[0] == "FLASER") return parse_flaser(t, line_number, geometry);
  if (t[0] == "ROBOTLASER1") return parse_robotlaser1(t, line_number);
  if (!looks_like_type(t[0])) return Malformed{"not a CARMEN message type"};
  return OtherMessage{std::string(t[0])};
}

struct Reader::GzFile {
  gzFile f = nullptr;
  ~GzFile() {
    if (f) gzclose(f);
  }
};

Reader::Reader(const std::string& path, FlaserGeometry geometry, TimestampPolicy timestamps)
    : file_(std::make_unique<GzFile>()), geometry_(geometry), timestamps_(timestamps) {
  file_->f = gzopen(path.c_str(), "rb");  // reads plain files transparently
  good_ = file_->f != nullptr;
  if (!good_) summary_.input_error = "cannot open " + path;
}

Reader::~Reader() = default;

bool Reader::read_line(std::string& line) {
  line.clear();
  line_too_long_ = false;
  while (true) {
    const std::size_t nl = buffer_.find('\n', buffer_pos_);
    const std::size_t end = nl == std::string::npos ? buffer_.size() : nl;
    if (!line_too_long_) line.append(buffer_, buffer_pos_, end - buffer_pos_);
    if (line.size() > kMaxLineBytes) {  // keep counting the line, not holding it
      line_too_long_ = true;
      line.clear();
    }
    buffer_pos_ = end;
    if (nl != std::string::npos) {
      buffer_pos_ = nl + 1;
      return true;
    }
    if (eof_) return !line.empty() || line_too_long_;
    buffer_.resize(1 << 16);
    buffer_pos_ = 0;
    const int got = gzread(file_->f, buffer_.data(), static_cast<unsigned>(buffer_.size()));
    if (got <= 0) {
      int code = Z_OK;
      const char* msg = gzerror(file_->f, &code);
      if (got < 0 || code != Z_OK) {
        summary_.input_error = std::string("compressed input damaged after line ") +
                               std::to_string(summary_.lines) + ": " + (msg ? msg : "?");
      }
      eof_ = true;
      buffer_.clear();
      // A partial last line of a damaged stream is not trusted.
      if (code != Z_OK) line.clear();
      if (line.empty() && !line_too_long_) return false;
      continue;
    }
    buffer_.resize(got);
  }
}

std::optional<Scan> Reader::next() {
  if (!good_) return std::nullopt;
  std::string text;
  while (read_line(text)) {
    const int64_t number = ++summary_.lines;
    ParsedLine parsed = line_too_long_ ? ParsedLine(Malformed{"line longer than 1 MiB"})
                                       : parse_line(text, number, geometry_);
    if (auto* scan = std::get_if<Scan>(&parsed)) {
      summary_.max_quantum_s = std::max(summary_.max_quantum_s, scan->utime_quantum_s);
      if (scan->utime_quantum_s > timestamps_.max_quantum_s) {
        // Too coarse to order or space scans (csail: 404 of 406 scans share two values). The
        // logger's clock, if printed finely, else the nominal period after the previous scan.
        ++summary_.quantised_count;
        if (scan->logger_utime && scan->logger_quantum_s <= timestamps_.max_quantum_s) {
          scan->utime = *scan->logger_utime;
          ++summary_.restamped_logger;
        } else if (last_utime_) {
          scan->utime = *last_utime_ + std::llround(timestamps_.nominal_period_s * 1e6);
          ++summary_.restamped_nominal;
        }
      }
      if (last_utime_ && scan->utime <= *last_utime_) {
        summary_.max_backstep_us = std::max(summary_.max_backstep_us, *last_utime_ - scan->utime);
        if (summary_.backwards_lines.size() < Summary::kListed) {
          summary_.backwards_lines.push_back(number);
        }
        ++summary_.backwards_count;
        scan->utime = *last_utime_ + 1;
      }
      last_utime_ = scan->utime;
      ++summary_.scans;
      ++summary_.scans_by_type[scan->type];
      return std::move(*scan);
    }
    if (auto* other = std::get_if<OtherMessage>(&parsed)) {
      ++summary_.skipped_by_type[other->type];
    } else if (auto* bad = std::get_if<Malformed>(&parsed)) {
      if (summary_.malformed_count++ == 0) summary_.first_malformed_reason = bad->reason;
      if (summary_.malformed_lines.size() < Summary::kListed) {
        summary_.malformed_lines.push_back(number);
      }
    } else {
      ++summary_.comment_or_blank_lines;
    }
  }
  return std::nullopt;
}

}  // namespace traverse::carmen
