#include "log_reader.hpp"

#include <algorithm>
#include <cmath>

namespace traverse::carmen {

void ReanchorDetector::on_scan(const Scan& scan) {
  armed_ = true;
  scan_ipc_utime_ = scan.stamp.ipc_utime;
  laser_[0] = scan.x_m;
  laser_[1] = scan.y_m;
  laser_[2] = scan.theta_rad;
  odometry_[0] = scan.odom_x_m;
  odometry_[1] = scan.odom_y_m;
  odometry_[2] = scan.odom_theta_rad;
}

bool ReanchorDetector::is_reanchor(const Odometry& o) {
  if (!armed_) return false;
  armed_ = false;
  const auto same = [&](const double* p) {
    return o.x_m == p[0] && o.y_m == p[1] && o.theta_rad == p[2];
  };
  return o.stamp.ipc_utime < scan_ipc_utime_ && (same(laser_) || same(odometry_));
}

Reader::Reader(const std::string& path, FlaserGeometry geometry, TimestampPolicy timestamps,
               NoReturnPolicy no_return)
    : geometry_(geometry), lines_(path, geometry) {
  if (lines_.good()) survey(path, timestamps, no_return);
  clock_.emplace(summary_.time);
}

void Reader::survey(const std::string& path, const TimestampPolicy& timestamps,
                    const NoReturnPolicy& no_return) {
  LineReader first(path, geometry_);
  ClockStats ipc, logger;
  RangeHistogram ranges;
  ReanchorDetector reanchors;
  std::vector<std::optional<int64_t>> odometry_ipc, odometry_logger;
  while (auto record = first.next()) {
    if (const Scan* scan = std::get_if<Scan>(&*record)) {
      ipc.add(scan->stamp.ipc_utime, scan->stamp.ipc_quantum_s, timestamps.max_quantum_s);
      logger.add(scan->stamp.logger_utime, scan->stamp.logger_quantum_s, timestamps.max_quantum_s);
      for (float r : scan->ranges) ranges.add(r);
      summary_.max_beams_in_scan =
          std::max(summary_.max_beams_in_scan, static_cast<int64_t>(scan->ranges.size()));
      reanchors.on_scan(*scan);
      continue;
    }
    const Odometry& odom = std::get<Odometry>(*record);
    if (reanchors.is_reanchor(odom)) {
      ++summary_.odometry_reanchors;
      continue;
    }
    odometry_ipc.push_back(odom.stamp.ipc_utime);
    odometry_logger.push_back(odom.stamp.logger_utime);
    summary_.odometry_velocity |= odom.tv_mps != 0.0 || odom.rv_radps != 0.0;
  }

  static_cast<LineCounts&>(summary_) = first.counts();
  summary_.time = plan_time(ipc, logger, timestamps);
  summary_.quantised_count = ipc.coarse();
  summary_.max_quantum_s = ipc.max_quantum_s();
  if (summary_.time.clock == Clock::kLogger) summary_.restamped_logger = ipc.scans();
  if (summary_.time.clock == Clock::kNominal) summary_.restamped_nominal = ipc.scans();

  // Odometry in time order on the plan's clock; none when the log's stamps carry no time.
  switch (summary_.time.clock) {
    case Clock::kIpc:
      odometry_in_order_ = longest_increasing(odometry_ipc);
      break;
    case Clock::kLogger:
      odometry_in_order_ = longest_increasing(odometry_logger);
      break;
    case Clock::kNominal:
      odometry_in_order_.assign(odometry_ipc.size(), false);
      break;
  }
  if (summary_.time.clock != Clock::kNominal) {
    for (bool kept : odometry_in_order_) summary_.odometry_out_of_order += kept ? 0 : 1;
  }

  if (no_return.code_m > 0.0) {
    const auto mm = static_cast<std::size_t>(std::llround(no_return.code_m * 1000.0));
    const int64_t beams = ranges.count_mm(mm);
    summary_.no_return = NoReturnCode{
        no_return.code_m, beams,
        ranges.total() > 0 ? static_cast<double>(beams) / static_cast<double>(ranges.total())
                           : 0.0};
  } else {
    summary_.no_return = find_no_return_code(ranges, no_return.min_fraction);
  }
}

std::optional<Record> Reader::next_record() {
  auto record = lines_.next();
  if (!record) return std::nullopt;
  if (Scan* scan = std::get_if<Scan>(&*record)) {
    scan->utime = clock_->next(scan->stamp, scan->line);
    if (summary_.no_return) scan->no_return_code_m = summary_.no_return->code_m;
    reanchors_.on_scan(*scan);
    return Record(std::move(*scan));
  }
  OdometryReading reading{std::get<Odometry>(*record)};
  reading.reanchor = reanchors_.is_reanchor(reading.odom);
  if (!reading.reanchor) {
    const std::size_t i = odometry_measurements_++;
    reading.in_time_order = i < odometry_in_order_.size() && odometry_in_order_[i];
    reading.utime = stamp_on(reading.odom.stamp, summary_.time.clock).value_or(0);
  }
  return Record(reading);
}

std::optional<Scan> Reader::next() {
  while (auto record = next_record()) {
    if (Scan* scan = std::get_if<Scan>(&*record)) return std::move(*scan);
  }
  return std::nullopt;
}

const Summary& Reader::summary() {
  if (!lines_.good()) static_cast<LineCounts&>(summary_) = lines_.counts();  // cannot open
  summary_.backwards_count = clock_->backwards_count();
  summary_.backwards_lines = clock_->backwards_lines();
  summary_.max_backstep_us = clock_->max_backstep_us();
  return summary_;
}

}  // namespace traverse::carmen
