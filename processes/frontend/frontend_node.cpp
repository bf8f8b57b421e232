#include "frontend_node.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include "odometry_message.hpp"
#include "scan_message.hpp"
#include "state_file.hpp"
#include "traverse/pose2d_t.hpp"

namespace traverse::frontend {
namespace {

const std::string kStateMagic = "TRVFEW01";  // frontend.state: the recent window, version 1

}  // namespace

FrontendNode::FrontendNode(Bus& bus, const FrontendConfig& config, CounterSink counters,
                           const std::string& state_dir)
    : bus_(bus),
      config_(config),
      kind_(config.kind),
      counters_(std::move(counters)),
      handover_(config.handover),
      state_dir_(state_dir) {
  if (!state_dir_.empty()) {
    std::filesystem::create_directories(state_dir_);
    std::string error;
    const auto payload = read_snapshot(state_dir_ + "/frontend.state", kStateMagic, &error);
    if (!error.empty()) throw std::runtime_error(error);
    if (payload && !handover_.restore(*payload)) {
      throw std::runtime_error(state_dir_ + "/frontend.state is inconsistent");
    }
    if (payload) {
      if (auto started = handover_.start(config_)) {
        frontend_ = std::move(started->frontend);
        C_ = started->C;
        resumed_scans_ = started->scans;
        saved_ = handover_;
        checks_left_ = config_.handover.check_scans;
      }
    }
  }
  if (!frontend_) frontend_ = make_frontend(config_);
  bus_.subscribe<planar_scan_t>(config_.scan_channel,
                                [this](const planar_scan_t& m) { on_scan(m); });
  bus_.subscribe<imu_t>(config_.imu_channel, [this](const imu_t& m) { on_imu(m); });
  bus_.subscribe<odometry_t>(config_.odometry_channel,
                             [this](const odometry_t& m) { on_odometry(m); });
  bus_.subscribe<frontend_control_t>(config_.handover.control_channel,
                                     [this](const frontend_control_t& m) { on_control(m); });
}

void FrontendNode::on_scan(const planar_scan_t& msg) {
  pending_.push_back(to_planar_scan(msg));
  flush();
}

void FrontendNode::on_imu(const imu_t& msg) {
  const Eigen::Vector3d angular_velocity(msg.angular_velocity[0], msg.angular_velocity[1],
                                         msg.angular_velocity[2]);
  if (frontend_->add_imu(msg.utime, angular_velocity)) {
    last_imu_utime_ = msg.utime;
    handover_.add_imu(msg.utime, angular_velocity);
  }
  flush();
}

void FrontendNode::on_odometry(const odometry_t& msg) {
  const OdometrySample o = to_odometry_sample(msg);
  if (frontend_->add_odometry(o)) {
    last_odometry_utime_ = msg.utime;
    handover_.add_odometry(o);
  }
  flush();
}

void FrontendNode::on_control(const frontend_control_t& msg) {
  // Repeats of a request carry its id: each is carried out once.
  if (msg.request_id <= last_request_id_) return;
  last_request_id_ = msg.request_id;
  FrontendConfig c = config_;
  c.kind = msg.kind;
  if (validate(c)) {
    ++control_rejected_;
    return;
  }
  if (msg.kind != kind_) hand_over(msg.kind);
}

void FrontendNode::hand_over(const std::string& kind) {
  // What the outgoing frontend still holds (a lagging scan) is published first.
  if (const auto held = frontend_->finish()) publish(*held);
  FrontendConfig c = config_;
  c.kind = kind;
  if (auto started = handover_.start(c)) {
    frontend_ = std::move(started->frontend);
    C_ = started->C;
    last_misfit_m_ = started->misfit_m;
    last_misfit_rad_ = started->misfit_rad;
  } else {  // nothing tracked yet: it starts where the first one would have
    frontend_ = make_frontend(c);
    C_ = Pose2();
  }
  kind_ = kind;
  ++swaps_;
}

void FrontendNode::flush(bool all) {
  const auto covered = [](const std::optional<int64_t>& last, int64_t utime) {
    return !last || *last >= utime;
  };
  while (!pending_.empty() && resume_failure_.empty()) {
    const Scan& scan = pending_.front();
    const bool ready = all ||
                       (covered(last_imu_utime_, scan.utime_last) &&
                        covered(last_odometry_utime_, scan.utime_last)) ||
                       pending_.back().utime_last - scan.utime_last >= config_.deskew.imu_wait_us;
    if (!ready) break;
    handover_.add_scan(scan);
    const FrontendResult result = frontend_->process(scan);
    if (result.has_pose() && checks_left_ > 0 && result.utime == scan.utime_last &&
        !check_resumed(scan, C_ * result.T_map_base)) {
      return;
    }
    pending_.pop_front();
    if (result.has_pose()) publish(result);
  }
  if (!all || !resume_failure_.empty()) return;
  // The end of the stream: the scan the lag still holds (sparse_lag) gets its pose.
  if (const auto result = frontend_->finish()) publish(*result);
}

bool FrontendNode::check_resumed(const Scan& scan, const Pose2& T_map_base) {
  const double fit = saved_->fit(scan, T_map_base, config_);
  worst_fit_ = std::min(worst_fit_, fit);
  if (fit < config_.handover.min_fit) {
    char text[256];
    std::snprintf(text, sizeof(text),
                  "the resumed session's scan at %.3f s does not fit the saved map at the saved "
                  "pose: %.0f %% of its points within %.2f m of the saved scans, at least "
                  "%.0f %% needed (moved since the session stopped, or another place?)",
                  static_cast<double>(scan.utime_last) * 1e-6, 100.0 * fit,
                  config_.handover.fit_distance_m, 100.0 * config_.handover.min_fit);
    resume_failure_ = text;
    return false;
  }
  if (--checks_left_ == 0) saved_.reset();
  return true;
}

void FrontendNode::publish(const FrontendResult& result) {
  const Pose2 T = C_ * result.T_map_base;
  const Eigen::Matrix3d covariance = rotate_covariance(result.covariance, C_.rotation());
  pose2d_t msg{};
  msg.utime = result.utime;
  msg.parent_frame = "map";
  msg.child_frame = "base";
  msg.x = T.x();
  msg.y = T.y();
  msg.theta = T.theta();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) msg.covariance[3 * r + c] = covariance(r, c);
  }
  msg.flags = (result.status == ScanStatus::kPredicted ? pose2d_t::FLAG_PREDICTED : 0) |
              (result.late ? pose2d_t::FLAG_LATE : 0);
  bus_.publish(config_.pose_channel, msg);
  if (!result.late) handover_.add_published(result.utime, T);
  const auto period_us = static_cast<int64_t>(config_.handover.save_period_s * 1e6);
  if (!state_dir_.empty() && period_us > 0 &&
      (last_saved_utime_ == INT64_MIN || result.utime - last_saved_utime_ >= period_us)) {
    save_in_background();
    last_saved_utime_ = result.utime;
  }
}

FrontendNode::~FrontendNode() {
  if (writing_.valid()) writing_.wait();
}

void FrontendNode::save_in_background() {
  if (handover_.empty() || !resume_failure_.empty()) return;
  if (writing_.valid() && writing_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) {
    ++saves_skipped_;
    return;
  }
  const auto t0 = std::chrono::steady_clock::now();
  std::string bytes = handover_.serialise();
  state_bytes_ = static_cast<double>(bytes.size());
  writing_ = std::async(std::launch::async,
                        [path = state_dir_ + "/frontend.state", bytes = std::move(bytes)] {
                          return write_snapshot(path, kStateMagic, bytes, false);
                        });
  const double took_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ++saves_;
  save_total_s_ += took_s;
  save_max_s_ = std::max(save_max_s_, took_s);
}

void FrontendNode::save_state(bool durable) {
  if (writing_.valid()) writing_.wait();  // the last periodic save is not renamed in after this
  if (state_dir_.empty() || handover_.empty() || !resume_failure_.empty()) return;
  const std::string bytes = handover_.serialise();
  state_bytes_ = static_cast<double>(bytes.size());
  write_snapshot(state_dir_ + "/frontend.state", kStateMagic, bytes, durable);
}

void FrontendNode::report_counters() {
  if (!counters_) return;
  frontend_->report(counters_);
  counters_("scans_waiting_for_imu", static_cast<double>(pending_.size()));
  counters_("map_bytes", static_cast<double>(frontend_->map_bytes()));
  counters_("frontend_kind_icp", kind_ == "icp" ? 1.0 : 0.0);
  counters_("frontend_swaps", static_cast<double>(swaps_));
  counters_("frontend_request_id", static_cast<double>(last_request_id_));
  counters_("frontend_control_rejected", static_cast<double>(control_rejected_));
  counters_("handover_misfit_m", last_misfit_m_);
  counters_("handover_misfit_rad", last_misfit_rad_);
  if (!state_dir_.empty()) {
    counters_("state_saves", static_cast<double>(saves_));
    counters_("state_saves_skipped", static_cast<double>(saves_skipped_));
    counters_("state_save_total_s", save_total_s_);
    counters_("state_save_max_s", save_max_s_);
    counters_("state_bytes", state_bytes_);
  }
  if (resumed_scans_) {
    counters_("resumed_scans", static_cast<double>(*resumed_scans_));
    counters_("resume_worst_fit", worst_fit_);
  }
}

}  // namespace traverse::frontend
