// Decoding bounded and plausibility checked, through the typed subscription every process uses:
// a message that claims more than it holds is dropped before anything is allocated for it, one
// that cannot be right is rejected and counted, and neither costs memory.
#include "message_checks.hpp"

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <climits>
#include <cstring>
#include <vector>

#include "bus.hpp"
#include "traverse/process_status_t.hpp"
#include "type_registry.hpp"

namespace traverse {
namespace {

template <class T>
std::vector<uint8_t> encode(const T& msg) {
  std::vector<uint8_t> buf(msg.getEncodedSize());
  msg.encode(buf.data(), 0, static_cast<int>(buf.size()));
  return buf;
}

planar_scan_t make_scan(int64_t utime, int n) {
  planar_scan_t s{};
  s.utime = s.utime_first = s.utime_last = utime;
  s.frame = "laser";
  s.angle_first = -1.5f;
  s.angle_step = 0.01f;
  s.range_min = 0.1f;
  s.range_max = 30.0f;
  s.n_ranges = n;
  s.ranges.assign(n, 2.0f);
  return s;
}

void set_be32(std::vector<uint8_t>& b, std::size_t at, int32_t v) {
  for (int i = 0; i < 4; ++i)
    b[at + i] = static_cast<uint8_t>(static_cast<uint32_t>(v) >> (24 - 8 * i));
}

// A scan of no ranges whose n_ranges then claims `claimed`.
std::vector<uint8_t> scan_claiming(int32_t claimed) {
  std::vector<uint8_t> b = encode(make_scan(1000, 0));
  // fingerprint 8, utime 8, seq 8, frame 4+6, utime_first 8, utime_last 8, 4 floats 16.
  set_be32(b, 8 + 8 + 8 + 4 + 6 + 8 + 8 + 16, claimed);
  return b;
}

long peak_rss_kb() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return ru.ru_maxrss;
}

void drain(Bus& bus) {
  while (bus.lcm().handleTimeout(0) > 0) {
  }
}

TEST(MessageLayout, EveryTypeHasALayoutAndItsMessagesWalkExactly) {
  ASSERT_GE(all_types().size(), 10u);
  for (const TypeInfo& t : all_types()) {
    ASSERT_NE(t.layout, nullptr) << t.name;
    EXPECT_GT(t.layout->min_bytes, 0) << t.name;
  }
  const auto scan = encode(make_scan(5, 300));
  EXPECT_TRUE(
      walk_message(*find_type(scan.data(), scan.size())->layout, scan.data(), scan.size()).ok());
  process_status_t st{};
  st.process = "p";
  st.n_channels = 2;
  st.channels.resize(2);
  st.channels[0].channel = "A";
  st.channels[1].channel = "B";
  st.n_counters = 1;
  st.counter_names = {"x"};
  st.counter_values = {1.0};
  const auto bytes = encode(st);
  ASSERT_NE(find_type(bytes.data(), bytes.size()), nullptr);
  // One byte more, one byte less: not the message any more.
  auto longer = bytes;
  longer.push_back(0);
  EXPECT_EQ(find_type(longer.data(), longer.size()), nullptr);
  EXPECT_EQ(find_type(bytes.data(), bytes.size() - 1), nullptr);
}

TEST(MessageLayout, NegativeAndZeroLengthsAreMalformed) {
  auto b = scan_claiming(-5);
  EXPECT_EQ(find_type(b.data(), b.size()), nullptr);
  // The frame string's length (with its NUL) set to 0: the decoder would throw length_error.
  auto s = encode(make_scan(1, 3));
  set_be32(s, 24, 0);
  planar_scan_t msg;
  EXPECT_EQ(decode_checked(s.data(), static_cast<int>(s.size()), {}, msg).verdict,
            MessageVerdict::kMalformed);
}

TEST(MessageChecks, ScansClaimingMoreThanTheyHoldCostNoMemory) {
  Bus bus("memq://");
  int handled = 0;
  bus.subscribe<planar_scan_t>("SCAN", [&](const planar_scan_t&) { ++handled; });
  const long before_kb = peak_rss_kb();
  // Fifty 78-byte scans claiming 100 M ranges (400 MB each to the generated decoder), and one
  // claiming INT32_MAX (bad_alloc).
  const auto claim = scan_claiming(100'000'000);
  ASSERT_EQ(claim.size(), 78u);
  for (int i = 0; i < 50; ++i) {
    bus.lcm().publish("SCAN", claim.data(), static_cast<unsigned>(claim.size()));
    drain(bus);
  }
  const auto huge = scan_claiming(INT32_MAX);
  bus.lcm().publish("SCAN", huge.data(), static_cast<unsigned>(huge.size()));
  drain(bus);
  EXPECT_LT(peak_rss_kb() - before_kb, 50'000) << "decoding allocated what the bytes claimed";
  EXPECT_EQ(handled, 0);
  EXPECT_EQ(bus.stats().at("SCAN").decode_failures, 51);
  auto good = make_scan(2000, 180);
  bus.publish("SCAN", good);
  drain(bus);
  EXPECT_EQ(handled, 1);  // the channel still works
}

TEST(MessageChecks, StatusClaimingMillionsOfChannelsIsDroppedCheaply) {
  process_status_t st{};
  st.process = "liar";
  st.host = "h";
  st.state = "running";
  auto b = encode(st);
  // n_channels follows utime, seq, 3 strings (4+5, 4+2, 4+8), pid, uptime, cpu, rss.
  const std::size_t at = 8 + 8 + 8 + 9 + 6 + 4 + 8 + 8 + 8 + 12;
  set_be32(b, at, 5'000'000);
  process_status_t out;
  const long before_kb = peak_rss_kb();
  for (int i = 0; i < 20; ++i) {
    EXPECT_EQ(decode_checked(b.data(), static_cast<int>(b.size()), {}, out).verdict,
              MessageVerdict::kMalformed);
  }
  EXPECT_LT(peak_rss_kb() - before_kb, 50'000);
}

TEST(MessageChecks, BeamCapRejectsLargerScansAndKeepsTheChannel) {
  InputConfig input;
  input.max_scan_beams = 1000;
  Bus bus("memq://", input);
  std::vector<int> sizes;
  bus.subscribe<planar_scan_t>("SCAN",
                               [&](const planar_scan_t& s) { sizes.push_back(s.n_ranges); });
  auto a = make_scan(1, 1000), b = make_scan(2, 1001), c = make_scan(3, 10);
  a.angle_step = b.angle_step = 0.001f;
  bus.publish("SCAN", a);
  bus.publish("SCAN", b);
  bus.publish("SCAN", c);
  drain(bus);
  EXPECT_EQ(sizes, (std::vector<int>{1000, 10}));
  EXPECT_EQ(bus.stats().at("SCAN").rejected, 1);
  EXPECT_EQ(bus.stats().at("SCAN").decode_failures, 0);
  EXPECT_EQ(InputConfig{}.max_scan_beams, 100'000);
}

TEST(MessageChecks, ZeroAngleStepIsRejectedAndCounted) {
  Bus bus("memq://");
  int handled = 0;
  bus.subscribe<planar_scan_t>("SCAN", [&](const planar_scan_t&) { ++handled; });
  for (int i = 0; i < 5; ++i) {
    auto s = make_scan(100 + i, 180);
    s.angle_step = 0.0f;
    bus.publish("SCAN", s);
  }
  drain(bus);
  EXPECT_EQ(handled, 0);
  EXPECT_EQ(bus.stats().at("SCAN").rejected, 5);
  EXPECT_EQ(bus.stats().at("SCAN").received, 0);
}

TEST(MessageChecks, WhatCannotBeRight) {
  auto s = make_scan(1, 10);
  EXPECT_FALSE(implausible(s));
  s.angle_step = 0.0f;
  EXPECT_TRUE(implausible(s));
  s = make_scan(1, 1000);
  s.angle_step = 0.01f;  // 10 rad over 1000 beams: more than a turn
  EXPECT_TRUE(implausible(s));
  s = make_scan(1, 10);
  s.range_max = 0.05f;
  EXPECT_TRUE(implausible(s));
  s = make_scan(1, 10);
  s.angle_first = NAN;
  EXPECT_TRUE(implausible(s));
  imu_t imu{};
  EXPECT_FALSE(implausible(imu));
  imu.angular_velocity[2] = INFINITY;
  EXPECT_TRUE(implausible(imu));
  pose2d_t p{};
  p.theta = NAN;
  EXPECT_TRUE(implausible(p));
}

}  // namespace
}  // namespace traverse
