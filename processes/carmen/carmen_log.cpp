#include "carmen_log.hpp"

#include <zlib.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <numbers>

#include "seconds_text.hpp"

namespace traverse::carmen {
namespace {

constexpr double kPi = std::numbers::pi;

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

struct Xyt {
  double x = 0.0, y = 0.0, theta = 0.0;  // [m], [m], [rad]
};

// Reads x y theta at `first`; nullopt unless all three are finite.
std::optional<Xyt> read_pose(const std::vector<std::string_view>& t, std::size_t first) {
  const auto x = to_number(t[first]), y = to_number(t[first + 1]), th = to_number(t[first + 2]);
  if (!x || !y || !th) return std::nullopt;
  return Xyt{*x, *y, *th};
}

// The ipc timestamp at `ipc` and the logger timestamp at `logger`. A bad ipc timestamp makes the
// line malformed; the logger timestamp is optional information, a bad one is left out.
bool read_stamp(const std::vector<std::string_view>& t, std::size_t ipc, std::size_t logger,
                Stamp& stamp) {
  const auto ipc_utime = seconds_text_to_utime(t[ipc]);
  if (!ipc_utime) return false;
  stamp.ipc_utime = *ipc_utime;
  stamp.ipc_quantum_s = printed_quantum(t[ipc]);
  stamp.logger_utime = seconds_text_to_utime(t[logger]);
  if (stamp.logger_utime) stamp.logger_quantum_s = printed_quantum(t[logger]);
  return true;
}

void set_poses(const Xyt& laser, const Xyt& odometry, Scan& scan) {
  scan.x_m = laser.x;
  scan.y_m = laser.y;
  scan.theta_rad = laser.theta;
  scan.odom_x_m = odometry.x;
  scan.odom_y_m = odometry.y;
  scan.odom_theta_rad = odometry.theta;
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
  const auto pose = read_pose(t, 2 + *n), odom = read_pose(t, 2 + *n + 3);
  if (!pose || !odom) return Malformed{"FLASER: bad pose"};
  if (!read_stamp(t, 2 + *n + 6, 2 + *n + 8, scan.stamp)) {
    return Malformed{"FLASER: bad timestamp"};
  }
  scan.utime = scan.stamp.ipc_utime;
  set_poses(*pose, *odom, scan);
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
  const auto pose = read_pose(t, at_pose), robot = read_pose(t, at_pose + 3);
  if (!pose) return Malformed{"ROBOTLASER1: bad laser pose"};
  if (!robot) return Malformed{"ROBOTLASER1: bad robot pose"};
  const auto tv = to_number(t[at_pose + 6]), rv = to_number(t[at_pose + 7]);
  if (!tv || !rv) return Malformed{"ROBOTLASER1: bad velocity"};
  if (!read_stamp(t, at_pose + 11, at_pose + 13, scan.stamp)) {
    return Malformed{"ROBOTLASER1: bad timestamp"};
  }
  scan.utime = scan.stamp.ipc_utime;
  set_poses(*pose, *robot, scan);
  scan.tv_mps = *tv;
  scan.rv_radps = *rv;
  return scan;
}

// ODOM x y theta tv rv accel ipc_timestamp host logger_timestamp
ParsedLine parse_odom(const std::vector<std::string_view>& t, int64_t line) {
  if (t.size() != 10) {
    return Malformed{"ODOM: " + std::to_string(t.size()) + " fields, expected 10"};
  }
  Odometry odom;
  odom.line = line;
  const auto pose = read_pose(t, 1);
  const auto tv = to_number(t[4]), rv = to_number(t[5]), accel = to_number(t[6]);
  if (!pose) return Malformed{"ODOM: bad pose"};
  if (!tv || !rv || !accel) return Malformed{"ODOM: bad velocity"};
  if (!read_stamp(t, 7, 9, odom.stamp)) return Malformed{"ODOM: bad timestamp"};
  odom.x_m = pose->x;
  odom.y_m = pose->y;
  odom.theta_rad = pose->theta;
  odom.tv_mps = *tv;
  odom.rv_radps = *rv;
  return odom;
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
  if (t[0] == "ODOM") return parse_odom(t, line_number);
  if (!looks_like_type(t[0])) return Malformed{"not a CARMEN message type"};
  return OtherMessage{std::string(t[0])};
}

struct LineReader::GzFile {
  gzFile f = nullptr;
  ~GzFile() {
    if (f) gzclose(f);
  }
};

LineReader::LineReader(const std::string& path, FlaserGeometry geometry)
    : file_(std::make_unique<GzFile>()), geometry_(geometry) {
  file_->f = gzopen(path.c_str(), "rb");  // reads plain files transparently
  good_ = file_->f != nullptr;
  if (!good_) counts_.input_error = "cannot open " + path;
}

LineReader::~LineReader() = default;

bool LineReader::read_line(std::string& line) {
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
        counts_.input_error = std::string("compressed input damaged after line ") +
                              std::to_string(counts_.lines) + ": " + (msg ? msg : "?");
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

std::optional<std::variant<Scan, Odometry>> LineReader::next() {
  if (!good_) return std::nullopt;
  std::string text;
  while (read_line(text)) {
    const int64_t number = ++counts_.lines;
    ParsedLine parsed = line_too_long_ ? ParsedLine(Malformed{"line longer than 1 MiB"})
                                       : parse_line(text, number, geometry_);
    if (auto* scan = std::get_if<Scan>(&parsed)) {
      ++counts_.scans;
      ++counts_.scans_by_type[scan->type];
      return std::move(*scan);
    }
    if (auto* odom = std::get_if<Odometry>(&parsed)) {
      ++counts_.odometry;
      return *odom;
    }
    if (auto* other = std::get_if<OtherMessage>(&parsed)) {
      ++counts_.skipped_by_type[other->type];
    } else if (auto* bad = std::get_if<Malformed>(&parsed)) {
      if (counts_.malformed_count++ == 0) counts_.first_malformed_reason = bad->reason;
      if (counts_.malformed_lines.size() < LineCounts::kListed) {
        counts_.malformed_lines.push_back(number);
      }
    } else {
      ++counts_.comment_or_blank_lines;
    }
  }
  return std::nullopt;
}

}  // namespace traverse::carmen
