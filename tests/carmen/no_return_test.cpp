// The no-return code is read from the data: the largest value many beams share exactly, at the
// top of the range, standing out from the values round it.
#include "no_return.hpp"

#include <gtest/gtest.h>

#include <random>

namespace traverse::carmen {
namespace {

// Readings of walls 0.5 to `max_m` away, printed to centimetres.
void add_returns(RangeHistogram& h, int n, double max_m, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.5, max_m);
  for (int i = 0; i < n; ++i) h.add(static_cast<float>(std::round(u(rng) * 100.0) / 100.0));
}

TEST(NoReturnCode, FoundBelowTheRangeLimit) {
  std::mt19937 rng(1);
  RangeHistogram h;
  add_returns(h, 100'000, 30.0, rng);
  for (int i = 0; i < 2'000; ++i) h.add(32.76f);
  const auto code = find_no_return_code(h, 0.001);
  ASSERT_TRUE(code);
  EXPECT_DOUBLE_EQ(code->code_m, 32.76);
  EXPECT_EQ(code->beams, 2'000);
  EXPECT_NEAR(code->fraction, 2'000.0 / 102'000.0, 1e-12);
}

TEST(NoReturnCode, RealReturnsJustBelowItDoNotHideIt) {
  // aces: 50.00 for no return, and a few real returns at 49.8 to 49.91.
  std::mt19937 rng(2);
  RangeHistogram h;
  add_returns(h, 100'000, 45.0, rng);
  for (float r : {49.91f, 49.86f, 49.82f, 49.81f, 49.81f}) h.add(r);
  for (int i = 0; i < 900; ++i) h.add(50.0f);
  const auto code = find_no_return_code(h, 0.001);
  ASSERT_TRUE(code);
  EXPECT_DOUBLE_EQ(code->code_m, 50.0);
}

TEST(NoReturnCode, NoneWhenNoValueIsCommonEnough) {
  std::mt19937 rng(3);
  RangeHistogram h;
  add_returns(h, 100'000, 30.0, rng);
  for (int i = 0; i < 50; ++i) h.add(32.76f);  // 0.05 %: below the share
  EXPECT_FALSE(find_no_return_code(h, 0.001));
  EXPECT_FALSE(find_no_return_code(RangeHistogram{}, 0.001));
}

TEST(NoReturnCode, NoneWhenManyReturnsLieAboveIt) {
  std::mt19937 rng(4);
  RangeHistogram h;
  add_returns(h, 100'000, 60.0, rng);  // 45 % of the beams beyond 32.76 m
  for (int i = 0; i < 2'000; ++i) h.add(32.76f);
  EXPECT_FALSE(find_no_return_code(h, 0.001));
}

TEST(NoReturnCode, AFarWallSeenForLongIsNoCode) {
  // A robot standing still before a wall 20 m away: thousands of beams within a few centimetres.
  std::mt19937 rng(5);
  std::normal_distribution<double> wall(20.0, 0.015);
  RangeHistogram h;
  add_returns(h, 50'000, 15.0, rng);
  for (int i = 0; i < 20'000; ++i) h.add(static_cast<float>(std::round(wall(rng) * 100.0) / 100.0));
  EXPECT_FALSE(find_no_return_code(h, 0.001));
}

TEST(RangeHistogram, CountsZeroAsNoReadingAndFarAsOverflow) {
  RangeHistogram h;
  h.add(0.0f);
  h.add(-1.0f);
  h.add(1000.0f);
  h.add(1.234f);
  EXPECT_EQ(h.total(), 2);
  EXPECT_EQ(h.overflow(), 1);
  EXPECT_EQ(h.count_mm(1234), 1);
}

}  // namespace
}  // namespace traverse::carmen
