// The densifier and mapper nodes together over memq:// (graph_test.cpp, late_join_graph_test.cpp):
// frontend poses 1 cm off the key poses, profiles, and what the two nodes publish.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "bus.hpp"
#include "channels.hpp"
#include "densifier_node.hpp"
#include "mapper_node.hpp"
#include "test_profile.hpp"

namespace traverse {
namespace {

constexpr int64_t kT0 = 1'700'000'000'000'000;
constexpr int64_t kPoseDt = 20'000;  // [us] 50 Hz frontend
constexpr int kKeyEvery = 15;

// Parameter: the mapper on its own worker thread (live) or inline (replay).
class GraphTest : public ::testing::TestWithParam<bool> {
 protected:
  void SetUp() override {
    mapper::MapperConfig mc;
    mc.footprint = {-0.1, 0.1, -0.1, 0.1, 0.02, 0.5};
    out_dir_ = std::filesystem::temp_directory_path() /
               ("traverse_graph_test_" + std::to_string(::getpid()) + (GetParam() ? "_w" : "_i"));
    mc.output_dir = out_dir_.string();
    mc.preview.resend_max_bytes = resend_max_bytes_;
    configure(mc);
    Eigen::Isometry3d T_base_laser = Eigen::Isometry3d::Identity();
    T_base_laser.linear() =
        Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
    T_base_laser.translation() = Eigen::Vector3d(0.4, 0, 1.0);
    densifier_ = std::make_unique<densifier::DensifierNode>(bus_, densifier::DensifierConfig{});
    mapper_ = std::make_unique<mapper::MapperNode>(
        bus_, mc, T_base_laser,
        [this](const std::string& name, double v) { mapper_counters_[name] = v; }, GetParam());
    bus_.subscribe<dense_segments_t>(channels::kDenseSegments, [this](const dense_segments_t& m) {
      messages_.push_back(m);
      segments_.insert(segments_.end(), m.segments.begin(), m.segments.end());
    });
    // One bus for producer and listener: its order check would see the producer's own last
    // time, so the test checks the order itself.
    bus_.subscribe<pose2d_t>(
        channels::kPoseDense, [this](const pose2d_t& m) { dense_.push_back(m); }, true);
  }
  // A test's own mapper settings.
  virtual void configure(mapper::MapperConfig&) {}
  void handle_all() {
    while (bus_.lcm().handleTimeout(0) > 0) {
    }
  }
  void send_keys(const std::vector<int>& indices, double y, int optimisation = 1) {
    key_poses_t msg{};
    msg.optimisation = optimisation;
    msg.utime = kT0 + indices.back() * kKeyEvery * kPoseDt;
    msg.parts = 1;
    for (int k : indices) {
      key_pose_t p{};
      p.utime = kT0 + k * kKeyEvery * kPoseDt;
      p.id = k;
      p.x = 0.5e-6 * static_cast<double>(p.utime - kT0);
      p.y = y;
      msg.poses.push_back(p);
    }
    msg.n_poses = static_cast<int32_t>(msg.poses.size());
    bus_.publish(channels::kKeyPoses, msg);
  }
  void send_profile(int64_t t0) {
    planar_scan_t s = test_profile(t0, std::vector<float>(360, 2.0f));
    bus_.publish(channels::kScanProfile, s);
  }

  // Frontend pose i, 1 cm north of the truth.
  void send_frontend_pose(int i) {
    pose2d_t p{};
    p.utime = kT0 + i * kPoseDt;
    p.parent_frame = "map";
    p.child_frame = "base";
    p.x = 0.5e-6 * static_cast<double>(p.utime - kT0);
    p.y = 0.01;
    bus_.publish(channels::kPoseFrontend, p);
  }

  // Frontend poses first..n_poses, key poses (the truth) every kKeyEvery.
  void drive(int n_poses, bool profiles, int first = 0) {
    for (int i = first; i <= n_poses; ++i) {
      send_frontend_pose(i);
      const int64_t utime = kT0 + i * kPoseDt;
      if (i % kKeyEvery == 0) send_keys({i / kKeyEvery}, 0.0);
      if (profiles && i % 3 == 0 && i + 2 <= n_poses) send_profile(utime);
      handle_all();
      mapper_->flush();
    }
  }

  void TearDown() override { std::filesystem::remove_all(out_dir_); }

  Bus bus_{"memq://"};
  int64_t resend_max_bytes_ = mapper::PreviewConfig{}.resend_max_bytes;
  std::filesystem::path out_dir_;
  std::unique_ptr<densifier::DensifierNode> densifier_;
  std::unique_ptr<mapper::MapperNode> mapper_;
  std::vector<dense_segments_t> messages_;
  std::vector<dense_segment_t> segments_;
  std::vector<pose2d_t> dense_;
  std::map<std::string, double> mapper_counters_;
};

}  // namespace
}  // namespace traverse
