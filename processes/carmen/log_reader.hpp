// Reads a CARMEN log as the driver publishes it: the whole log is surveyed first (its clocks, its
// range values, its odometry), then read again line by line with each message given its time
// (log_time.hpp), each scan its no-return code (no_return.hpp), and each odometry line marked for
// what it is (a measurement in time order, one out of time order, or a corrected log's
// re-anchoring, odometry.hpp). Reading twice costs a second or so on a 45-minute log and lets
// every message be judged by the whole log before anything is published.
#pragma once

#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "carmen_log.hpp"
#include "log_time.hpp"
#include "no_return.hpp"

namespace traverse::carmen {

struct NoReturnPolicy {
  double code_m = 0.0;          // [m] > 0: readings at or above this are no return; 0: found
  double min_fraction = 0.001;  // [0..1] share of beams a value needs to be found as the code
};

// An odometry line as published: its time by the log's plan, and what it is.
struct OdometryReading {
  Odometry odom;
  int64_t utime = 0;  // [us] on the plan's clock (meaningless when !in_time_order)
  // The line repeats the pose of the laser line before it and is stamped before it: a corrected
  // log restarting its odometry from the corrected pose (odometry.hpp), not a measurement.
  bool reanchor = false;
  // Kept in the longest run of strictly increasing stamps (and the plan has a clock): false for a
  // line whose stamp is out of line with its neighbours, or for every line of a log whose stamps
  // carry no time.
  bool in_time_order = false;
};

using Record = std::variant<Scan, OdometryReading>;

// Tells a corrected log's re-anchoring lines: the first ODOM line after a laser line, repeating
// that line's laser pose or odometry exactly and stamped before it (the Radish corrected logs
// stamp them 0 or with garbage; in a raw log the next odometry comes after the scan).
class ReanchorDetector {
 public:
  void on_scan(const Scan& scan);
  bool is_reanchor(const Odometry& odom);

 private:
  bool armed_ = false;
  int64_t scan_ipc_utime_ = 0;
  double laser_[3] = {0, 0, 0}, odometry_[3] = {0, 0, 0};
};

// Everything reading the log found.
struct Summary : LineCounts {
  TimePlan time;
  int64_t quantised_count = 0;    // scans with an ipc stamp printed coarser than max_quantum_s
  double max_quantum_s = 0.0;     // [s] coarsest ipc stamp resolution seen
  int64_t restamped_logger = 0;   // scans timed by the logger's clock (plan kLogger)
  int64_t restamped_nominal = 0;  // scans placed at the nominal spacing (plan kNominal)
  // Scans stamped no later than the scan before them (real logs have a few, e.g. four in intel,
  // while the poses show file order is motion order): kept in file order, put 1 us after the
  // previous scan so time never goes backwards on a channel.
  int64_t backwards_count = 0;
  std::vector<int64_t> backwards_lines;   // the first `kListed`
  int64_t max_backstep_us = 0;            // [us] largest correction made
  std::optional<NoReturnCode> no_return;  // found in the data or configured
  int64_t max_beams_in_scan = 0;
  int64_t odometry_reanchors = 0;     // ODOM lines that re-anchor (not measurements)
  int64_t odometry_out_of_order = 0;  // measurements dropped to keep time increasing
  bool odometry_velocity = false;     // some ODOM line states a non-zero tv or rv
};

class Reader {
 public:
  explicit Reader(const std::string& path, FlaserGeometry geometry = FlaserGeometry::kStandard,
                  TimestampPolicy timestamps = {}, NoReturnPolicy no_return = {});

  bool good() const { return lines_.good(); }  // false if the file could not be opened
  // Next scan or odometry line in file order, or nullopt at the end of the input (or at damage).
  std::optional<Record> next_record();
  // Next scan (odometry lines skipped).
  std::optional<Scan> next();
  // The whole log's line counts and the survey's findings (from the first reading), and the
  // corrections made to scan times so far.
  const Summary& summary();

 private:
  void survey(const std::string& path, const TimestampPolicy& timestamps,
              const NoReturnPolicy& no_return);

  FlaserGeometry geometry_;
  LineReader lines_;
  std::optional<ScanClock> clock_;
  Summary summary_;
  std::vector<bool> odometry_in_order_;  // per ODOM line that is a measurement, in file order
  std::size_t odometry_measurements_ = 0;
  ReanchorDetector reanchors_;
};

}  // namespace traverse::carmen
