#include "seconds_text.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

namespace traverse {
namespace {

TEST(SecondsText, ReadsDecimalSecondsExactly) {
  EXPECT_EQ(seconds_text_to_utime("976052905.167303"), 976'052'905'167'303);
  EXPECT_EQ(seconds_text_to_utime("1211.520329"), 1'211'520'329);
  EXPECT_EQ(seconds_text_to_utime("0.000246"), 246);
  EXPECT_EQ(seconds_text_to_utime("12.5"), 12'500'000);
  EXPECT_EQ(seconds_text_to_utime("7"), 7'000'000);
  EXPECT_EQ(seconds_text_to_utime("1."), 1'000'000);
  EXPECT_EQ(seconds_text_to_utime(".5"), 500'000);
  EXPECT_EQ(seconds_text_to_utime("-1.25"), -1'250'000);
  EXPECT_EQ(seconds_text_to_utime("+3"), 3'000'000);
  EXPECT_EQ(seconds_text_to_utime("0"), 0);
  EXPECT_EQ(seconds_text_to_utime("-0.0"), 0);
  EXPECT_EQ(seconds_text_to_utime("000012.000001"), 12'000'001);
}

TEST(SecondsText, ReadsExponents) {
  EXPECT_EQ(seconds_text_to_utime("1.13486e+09"), 1'134'860'000'000'000);
  EXPECT_EQ(seconds_text_to_utime("1.5E3"), 1'500'000'000);
  EXPECT_EQ(seconds_text_to_utime("2.5e-3"), 2'500);
  EXPECT_EQ(seconds_text_to_utime("1.08499e-42"), 0);  // garbage a real log holds
  EXPECT_EQ(seconds_text_to_utime("5e-7"), 1);         // a half rounds away from zero
  EXPECT_EQ(seconds_text_to_utime("-5e-7"), -1);
  EXPECT_EQ(seconds_text_to_utime("4.9e-7"), 0);
}

TEST(SecondsText, RoundsToTheNearestMicrosecond) {
  EXPECT_EQ(seconds_text_to_utime("1.0000004"), 1'000'000);
  EXPECT_EQ(seconds_text_to_utime("1.0000005"), 1'000'001);
  EXPECT_EQ(seconds_text_to_utime("1.00000049999999"), 1'000'000);
  EXPECT_EQ(seconds_text_to_utime("-1.0000015"), -1'000'002);
  // More digits than an int64 holds: the extra ones only round.
  EXPECT_EQ(seconds_text_to_utime("976052905.16730349999999999"), 976'052'905'167'303);
}

TEST(SecondsText, RefusesWhatIsNotSeconds) {
  for (const char* bad : {"", "-", ".", "e5", "1e", "1e+", "nan", "inf", "-inf", "0x10", "1.0.0",
                          "1,5", "12a", " 1", "1 ", "1e300", "-2e11", "100000000001"}) {
    EXPECT_FALSE(seconds_text_to_utime(bad).has_value()) << bad;
  }
  EXPECT_TRUE(seconds_text_to_utime("99999999999.999999").has_value());  // just under 1e11 s
}

// Agrees with the double route (llround(strtod(s) * 1e6)) wherever a double is exact enough.
TEST(SecondsText, AgreesWithFloatingPointOnLogStamps) {
  std::mt19937_64 rng(7);
  for (int i = 0; i < 20000; ++i) {
    const int64_t us = static_cast<int64_t>(rng() % 2'000'000'000'000'000ull);  // up to 2e9 s
    char text[40];
    std::snprintf(text, sizeof text, "%lld.%06lld", static_cast<long long>(us / 1'000'000),
                  static_cast<long long>(us % 1'000'000));
    ASSERT_EQ(seconds_text_to_utime(text), us) << text;
    ASSERT_EQ(std::llround(std::strtod(text, nullptr) * 1e6), us) << text;
  }
}

}  // namespace
}  // namespace traverse
