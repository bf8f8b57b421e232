// Reads CARMEN robot logs (the text format of the Radish data sets), plain or gzip-compressed.
//
// A CARMEN log has one message per line, the first token naming its type. Laser scans come as
//   FLASER n r1..rn x y theta odom_x odom_y odom_theta ipc_timestamp host logger_timestamp
//   ROBOTLASER1 laser_type start_angle fov resolution max_range accuracy remission_mode
//               n r1..rn m e1..em laser_x laser_y laser_theta robot_x robot_y robot_theta
//               tv rv forward_safety side_safety turn_axis ipc_timestamp host logger_timestamp
// (angles in radians, lengths in metres, timestamps in seconds). FLASER does not state its beam
// geometry; which reading is right was decided by map sharpness on the Radish logs (see
// tests/carmen/beam_geometry_test.cpp): FlaserGeometry::kStandard, i.e. first beam at -90 deg and
// the step the scanner's resolution (1, 0.5 deg): 180 and 360 beams stop one step short of +90
// deg, 181 and 361 beams reach it.
//
// The reader never trusts the text: a line that does not parse (every field present, every number
// finite) is skipped and its number kept; a damaged gzip stream ends the input and is reported.
// Nothing here prints.
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

// One laser scan with the pose the log gives for it.
struct Scan {
  std::string type;   // "FLASER" or "ROBOTLASER1"
  int64_t line = 0;   // line number in the log, from 1
  int64_t utime = 0;  // [us] ipc timestamp of the scan (one per scan in CARMEN)
  // [s] Resolution of the timestamp as printed: the place value of its last digit (1e-6 for
  // "12.345678", 1e4 for "1.13486e+09", a log printed with 6 significant digits).
  double utime_quantum_s = 0.0;
  // The logger timestamp (the line's last field) and its resolution, when it parses.
  std::optional<int64_t> logger_utime;
  double logger_quantum_s = 0.0;
  BeamAngles beams;
  std::vector<float> ranges;          // [m]
  std::optional<double> range_max_m;  // [m] stated by the message (ROBOTLASER1), if any
  // Pose of the laser in the log's world frame (for the corrected logs: the reference
  // trajectory). [m], [m], [rad]
  double x_m = 0.0, y_m = 0.0, theta_rad = 0.0;
};

struct Malformed {
  std::string reason;
};
struct OtherMessage {
  std::string type;  // a well-formed type token this reader does not use, e.g. "ODOM"
};
struct Ignorable {};  // blank line or '#' comment

using ParsedLine = std::variant<Scan, OtherMessage, Malformed, Ignorable>;

// Parses one line (without its newline). Never throws on any input.
ParsedLine parse_line(std::string_view text, int64_t line_number, FlaserGeometry geometry);

// What reading a whole log found.
struct Summary {
  int64_t lines = 0;
  int64_t scans = 0;
  std::map<std::string, int64_t> scans_by_type;    // FLASER, ROBOTLASER1
  std::map<std::string, int64_t> skipped_by_type;  // ODOM, PARAM, ...
  int64_t comment_or_blank_lines = 0;
  int64_t malformed_count = 0;
  std::vector<int64_t> malformed_lines;  // line numbers, the first `kListed`
  std::string first_malformed_reason;
  // Scans stamped no later than the scan before them (real logs have a few, e.g. four in intel,
  // while the poses show file order is motion order): kept in file order, stamped 1 us after the
  // previous scan so time never goes backwards on a channel.
  int64_t backwards_count = 0;
  std::vector<int64_t> backwards_lines;  // the first `kListed`
  int64_t max_backstep_us = 0;           // [us] largest correction made
  // Scans whose ipc timestamp is coarser than TimestampPolicy::max_quantum_s (csail: printed with
  // 6 significant digits, 1e4 s steps): restamped from the logger timestamp when that is fine
  // enough, else spaced at the nominal period after the previous scan.
  int64_t quantised_count = 0;
  double max_quantum_s = 0.0;  // [s] coarsest timestamp resolution seen (ipc)
  int64_t restamped_logger = 0;
  int64_t restamped_nominal = 0;
  std::string input_error;  // empty when the whole file was read
  static constexpr std::size_t kListed = 100;
};

// What to do with timestamps printed too coarsely to order or space scans.
struct TimestampPolicy {
  double max_quantum_s = 1.0;     // [s] coarser timestamps are quantised
  double nominal_period_s = 3.0;  // [s] spacing of quantised scans when no finer clock exists
};

// Resolution [s] of a printed number: the place value of its last mantissa digit, times the
// exponent ("1.5e3" -> 100, "0.25" -> 0.01, "7" -> 1).
double printed_quantum(std::string_view token);

// Reads a CARMEN log line by line; gzip is detected from the content, not the name.
class Reader {
 public:
  explicit Reader(const std::string& path, FlaserGeometry geometry = FlaserGeometry::kStandard,
                  TimestampPolicy timestamps = {});
  ~Reader();
  Reader(const Reader&) = delete;
  Reader& operator=(const Reader&) = delete;

  bool good() const { return good_; }  // false if the file could not be opened
  // Next scan in file order, or nullopt at the end of the input (or at damage).
  std::optional<Scan> next();
  const Summary& summary() const { return summary_; }

 private:
  bool read_line(std::string& line);  // false at end of input

  struct GzFile;
  std::unique_ptr<GzFile> file_;
  FlaserGeometry geometry_;
  TimestampPolicy timestamps_;
  bool good_ = false;
  bool eof_ = false;
  bool line_too_long_ = false;  // the line just read was cut at kMaxLineBytes
  std::string buffer_;
  std::size_t buffer_pos_ = 0;
  Summary summary_;
  std::optional<int64_t> last_utime_;
};

// Longest line accepted [bytes]; longer ones are malformed (and not held in memory whole).
inline constexpr std::size_t kMaxLineBytes = 1 << 20;
// Most beams accepted in one scan.
inline constexpr int kMaxBeams = 100000;

}  // namespace traverse::carmen
