#include "bus.hpp"

#include <gtest/gtest.h>

#include <stdexcept>

#include "traverse/imu_t.hpp"
#include "traverse/pose2d_t.hpp"

namespace traverse {
namespace {

pose2d_t pose_at(int64_t utime) {
  pose2d_t p{};
  p.utime = utime;
  p.parent_frame = "world";
  p.child_frame = "base";
  return p;
}

TEST(Bus, DeliversTypedMessagesAndCounts) {
  Bus bus("memq://");
  ASSERT_TRUE(bus.good());
  std::vector<int64_t> got;
  bus.subscribe<pose2d_t>("POSE", [&](const pose2d_t& p) { got.push_back(p.seq); });
  for (int i = 0; i < 3; ++i) {
    auto p = pose_at(100 + i);
    bus.publish("POSE", p);
  }
  while (bus.lcm().handleTimeout(0) > 0) {
  }
  EXPECT_EQ(got, (std::vector<int64_t>{0, 1, 2}));
  EXPECT_EQ(bus.stats().at("POSE").received, 3);
  EXPECT_EQ(bus.stats().at("POSE").published, 3);
  EXPECT_EQ(bus.stats().at("POSE").missed, 0);
}

TEST(Bus, CountsAndDropsUndecodableBytes) {
  Bus bus("memq://");
  int handled = 0;
  bus.subscribe<pose2d_t>("POSE", [&](const pose2d_t&) { ++handled; });
  // An IMU message on the pose channel: the fingerprint does not match.
  imu_t imu{};
  imu.frame = "imu";
  std::vector<uint8_t> buf(imu.getEncodedSize());
  imu.encode(buf.data(), 0, static_cast<int>(buf.size()));
  bus.lcm().publish("POSE", buf.data(), static_cast<unsigned>(buf.size()));
  const uint8_t junk[3] = {1, 2, 3};
  bus.lcm().publish("POSE", junk, 3);
  auto p = pose_at(5);
  bus.publish("POSE", p);
  while (bus.lcm().handleTimeout(0) > 0) {
  }
  EXPECT_EQ(handled, 1);
  EXPECT_EQ(bus.stats().at("POSE").decode_failures, 2);
}

TEST(Bus, DropsOutOfOrderAndCountsMissedSequenceNumbers) {
  Bus sender("memq://");
  Bus& bus = sender;
  std::vector<int64_t> utimes;
  bus.subscribe<pose2d_t>("POSE", [&](const pose2d_t& p) { utimes.push_back(p.utime); });
  // Hand-made sequence numbers: 0, 1, 5 (3 missed), and a message going back in time.
  std::vector<std::pair<int64_t, int64_t>> seq_utime = {{0, 10}, {1, 20}, {5, 30}, {6, 25}, {7, 40}};
  for (auto [seq, utime] : seq_utime) {
    auto p = pose_at(utime);
    p.seq = seq;
    std::vector<uint8_t> buf(p.getEncodedSize());
    p.encode(buf.data(), 0, static_cast<int>(buf.size()));
    bus.lcm().publish("POSE", buf.data(), static_cast<unsigned>(buf.size()));
  }
  while (bus.lcm().handleTimeout(0) > 0) {
  }
  EXPECT_EQ(utimes, (std::vector<int64_t>{10, 20, 30, 40}));
  EXPECT_EQ(bus.stats().at("POSE").out_of_order, 1);
  EXPECT_EQ(bus.stats().at("POSE").missed, 3);
}

TEST(Bus, HandlerThatThrowsIsCountedAndLaterMessagesStillFlow) {
  Bus bus("memq://");
  int handled = 0;
  bus.subscribe<pose2d_t>("POSE", [&](const pose2d_t& p) {
    if (p.utime == 2) throw std::runtime_error("boom");
    ++handled;
  });
  for (int64_t t : {1, 2, 3}) {
    auto p = pose_at(t);
    bus.publish("POSE", p);
  }
  while (bus.lcm().handleTimeout(0) > 0) {
  }
  EXPECT_EQ(handled, 2);
  EXPECT_EQ(bus.stats().at("POSE").handler_errors, 1);
}

}  // namespace
}  // namespace traverse
