// One stamp far from its neighbours must not block its channel (stamp_order.hpp), through the
// typed subscription every process uses.
#include "stamp_order.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <vector>

#include "bus.hpp"

namespace traverse {
namespace {

constexpr int64_t kMax = std::numeric_limits<int64_t>::max();

planar_scan_t scan_at(int64_t utime) {
  planar_scan_t s{};
  s.utime = s.utime_first = s.utime_last = utime;
  s.frame = "laser";
  s.angle_step = 0.01f;
  s.range_max = 30.0f;
  s.n_ranges = 3;
  s.ranges.assign(3, 1.0f);
  return s;
}

TEST(StampOrder, AStampNearInt64MaxDoesNotBlockTheChannel) {
  // 96 scans at 40 Hz, the 41st stamped near INT64_MAX: before, the next 55 were dropped.
  Bus bus("memq://");
  std::vector<int64_t> got;
  bus.subscribe<planar_scan_t>("SCAN", [&](const planar_scan_t& s) { got.push_back(s.utime); });
  for (int i = 0; i < 96; ++i) {
    auto s = scan_at(i == 40 ? kMax - 7 : 1'000'000 + 25'000 * i);
    bus.publish("SCAN", s);
  }
  while (bus.lcm().handleTimeout(0) > 0) {
  }
  EXPECT_EQ(got.size(), 95u);
  EXPECT_EQ(bus.stats().at("SCAN").stamp_outliers, 1);
  EXPECT_EQ(bus.stats().at("SCAN").out_of_order, 0);
  EXPECT_EQ(bus.stats().at("SCAN").received, 95);
}

TEST(StampOrder, OutlierAheadOrBehindIsDroppedAndCounted) {
  StampOrder order(10'000'000);
  int delivered = 0;
  for (int64_t t : std::initializer_list<int64_t>{100, 200, kMax, 300, 400, 0, 500,
                                                  std::numeric_limits<int64_t>::min(), 600}) {
    const auto s = order.next(t);
    delivered += s.deliver + s.release_held;
  }
  EXPECT_EQ(delivered, 6);
  EXPECT_EQ(order.outliers(), 2);  // kMax, INT64_MIN (0 is close: out of order)
  EXPECT_EQ(order.out_of_order(), 1);
  EXPECT_EQ(order.jumps(), 0);
}

TEST(StampOrder, ARealJumpIsDeliveredOneMessageLate) {
  // A pause longer than max_jump: the message after it is held until the next one confirms it.
  StampOrder order(10'000'000);
  EXPECT_TRUE(order.next(1'000).deliver);
  const auto held = order.next(60'000'000);
  EXPECT_TRUE(held.hold);
  EXPECT_FALSE(held.deliver);
  const auto next = order.next(60'100'000);
  EXPECT_TRUE(next.release_held);
  EXPECT_TRUE(next.deliver);
  EXPECT_EQ(order.jumps(), 1);
  EXPECT_EQ(order.outliers(), 0);
  // A clock reset backwards that stays there is a jump too, not a blocked channel.
  EXPECT_TRUE(order.next(5'000).hold);
  EXPECT_TRUE(order.next(6'000).release_held);
  EXPECT_TRUE(order.next(7'000).deliver);
  EXPECT_EQ(order.jumps(), 2);
  // The last message of a stream, if it jumped, is never confirmed.
  EXPECT_TRUE(order.next(kMax).hold);
  EXPECT_TRUE(order.finish());
  EXPECT_EQ(order.outliers(), 1);
}

}  // namespace
}  // namespace traverse
