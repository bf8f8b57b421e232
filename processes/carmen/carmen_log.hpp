// Reads the lines of CARMEN robot logs (the text format of the Radish data sets), plain or
// gzip-compressed.
//
// A CARMEN log has one message per line, the first token naming its type. Used here:
//   FLASER n r1..rn x y theta odom_x odom_y odom_theta ipc_timestamp host logger_timestamp
//   ROBOTLASER1 laser_type start_angle fov resolution max_range accuracy remission_mode
//               n r1..rn m e1..em laser_x laser_y laser_theta robot_x robot_y robot_theta
//               tv rv forward_safety side_safety turn_axis ipc_timestamp host logger_timestamp
//   ODOM x y theta tv rv accel ipc_timestamp host logger_timestamp
// (angles in radians, lengths in metres, velocities in m/s and rad/s, timestamps in seconds).
// FLASER does not state its beam geometry; which reading is right was decided by map sharpness on
// the Radish logs (see tests/carmen/beam_geometry_test.cpp): FlaserGeometry::kStandard, i.e. first
// beam at -90 deg and the step the scanner's resolution (1, 0.5 deg): 180 and 360 beams stop one
// step short of +90 deg, 181 and 361 beams reach it.
//
// The reader never trusts the text: a line that does not parse (every field present, every number
// finite) is skipped and its number kept; a damaged gzip stream ends the input and is reported.
// Timestamps are kept as written (log_reader.hpp decides what time each message is published
// at). Nothing here prints.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace traverse::carmen {

// How the n beams of a FLASER line spread over the 180 degrees in front of the robot.
enum class FlaserGeometry {
  kStandard,  // kHalfOpen for an even n (180, 360), kClosed for an odd n (181, 361)
  kHalfOpen,  // step pi/n, first beam at -90 deg, last at +90 deg - step
  kClosed,    // step pi/(n-1), first at -90 deg, last at +90 deg (both ends)
  kCentered,  // step pi/n, beams at the centres of n equal sectors (-90 deg + step/2 ...)
  kReversed,  // kHalfOpen mirrored (first beam on the left): a wrong reading, for comparison
};

struct BeamAngles {
  double angle_first = 0.0;  // [rad] first beam in the laser frame (x forward, y left)
  double angle_step = 0.0;   // [rad] counter-clockwise positive
};

BeamAngles flaser_beam_angles(int n_beams, FlaserGeometry geometry);
std::optional<FlaserGeometry> parse_flaser_geometry(std::string_view name);

// The two clocks of a CARMEN message, as written.
struct Stamp {
  int64_t ipc_utime = 0;  // [us] the ipc timestamp (the message's time)
  // [s] Resolution of the ipc timestamp as printed: the place value of its last digit (1e-6 for
  // "12.345678", 1e4 for "1.13486e+09", a log printed with 6 significant digits).
  double ipc_quantum_s = 0.0;
  std::optional<int64_t> logger_utime;  // [us] the logger timestamp (last field), if it parses
  double logger_quantum_s = 0.0;        // [s] its resolution as printed
};

// One laser scan with the poses the log gives for it.
struct Scan {
  std::string type;  // "FLASER" or "ROBOTLASER1"
  int64_t line = 0;  // line number in the log, from 1
  Stamp stamp;       // as written
  // [us] Time the scan is published at: stamp.ipc_utime as read by the line parser; the
  // log_reader.hpp Reader sets it by the log's time plan (never going backwards).
  int64_t utime = 0;
  BeamAngles beams;
  std::vector<float> ranges;          // [m]
  std::optional<double> range_max_m;  // [m] stated by the message (ROBOTLASER1), if any
  // [m] The log's no-return code (a reading at or above it is no return), when the Reader found
  // one in the data or the config names one.
  std::optional<double> no_return_code_m;
  // Pose of the laser in the log's world frame (for the corrected logs: the reference
  // trajectory; for raw logs: odometry). [m], [m], [rad]
  double x_m = 0.0, y_m = 0.0, theta_rad = 0.0;
  // The odometry the line carries: FLASER's odom_x odom_y odom_theta, ROBOTLASER1's robot pose.
  // [m], [m], [rad]
  double odom_x_m = 0.0, odom_y_m = 0.0, odom_theta_rad = 0.0;
  // ROBOTLASER1's translational [m/s] and rotational [rad/s] velocity; FLASER has none.
  std::optional<double> tv_mps, rv_radps;
};

// One ODOM line: the wheel odometry's pose and velocity.
struct Odometry {
  int64_t line = 0;                              // line number in the log, from 1
  Stamp stamp;                                   // as written
  double x_m = 0.0, y_m = 0.0, theta_rad = 0.0;  // [m], [m], [rad] in the odometry's own frame
  double tv_mps = 0.0;                           // [m/s] forward velocity
  double rv_radps = 0.0;                         // [rad/s] turn rate, counter-clockwise
};

struct Malformed {
  std::string reason;
};
struct OtherMessage {
  std::string type;  // a well-formed type token this reader does not use, e.g. "PARAM"
};
struct Ignorable {};  // blank line or '#' comment

using ParsedLine = std::variant<Scan, Odometry, OtherMessage, Malformed, Ignorable>;

// Parses one line (without its newline). Never throws on any input.
ParsedLine parse_line(std::string_view text, int64_t line_number, FlaserGeometry geometry);

// Resolution [s] of a printed number: the place value of its last mantissa digit, times the
// exponent ("1.5e3" -> 100, "0.25" -> 0.01, "7" -> 1).
double printed_quantum(std::string_view token);

// What reading the lines of a log found.
struct LineCounts {
  int64_t lines = 0;
  int64_t scans = 0;
  std::map<std::string, int64_t> scans_by_type;    // FLASER, ROBOTLASER1
  int64_t odometry = 0;                            // ODOM lines
  std::map<std::string, int64_t> skipped_by_type;  // PARAM, NEFF, ...
  int64_t comment_or_blank_lines = 0;
  int64_t malformed_count = 0;
  std::vector<int64_t> malformed_lines;  // line numbers, the first `kListed`
  std::string first_malformed_reason;
  std::string input_error;  // empty when the whole file was read
  static constexpr std::size_t kListed = 100;
};

// Reads a CARMEN log line by line and yields its scans and odometry in file order; gzip is
// detected from the content, not the name.
class LineReader {
 public:
  explicit LineReader(const std::string& path, FlaserGeometry geometry = FlaserGeometry::kStandard);
  ~LineReader();
  LineReader(const LineReader&) = delete;
  LineReader& operator=(const LineReader&) = delete;

  bool good() const { return good_; }  // false if the file could not be opened
  // Next scan or odometry line, or nullopt at the end of the input (or at damage).
  std::optional<std::variant<Scan, Odometry>> next();
  const LineCounts& counts() const { return counts_; }

 private:
  bool read_line(std::string& line);  // false at end of input

  struct GzFile;
  std::unique_ptr<GzFile> file_;
  FlaserGeometry geometry_;
  bool good_ = false;
  bool eof_ = false;
  bool line_too_long_ = false;  // the line just read was cut at kMaxLineBytes
  std::string buffer_;
  std::size_t buffer_pos_ = 0;
  LineCounts counts_;
};

// Longest line accepted [bytes]; longer ones are malformed (and not held in memory whole).
inline constexpr std::size_t kMaxLineBytes = 1 << 20;
// Most beams a line may claim (the published scan is capped lower, CarmenConfig::max_beams).
inline constexpr int kMaxBeams = 100000;

}  // namespace traverse::carmen
