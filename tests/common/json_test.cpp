// The programs' JSON helpers (json.hpp): figures as printed, and lines that stay valid ASCII JSON
// whatever bytes a name brings.
#include "json.hpp"

#include <gtest/gtest.h>

#include <limits>

namespace traverse {
namespace {

TEST(Json, FiguresAreRoundedAsPrintedAndNullWhenUnknown) {
  EXPECT_EQ(json_line(json_fixed(0.1234567, 3)), "0.123");
  EXPECT_EQ(json_line(json_fixed(2.0 / 3.0, 6)), "0.666667");
  EXPECT_EQ(json_line(json_significant(123456.789, 4)), "123500.0");
  EXPECT_EQ(json_line(json_significant(5e-05, 9)), "5e-05");
  EXPECT_TRUE(json_fixed(std::numeric_limits<double>::quiet_NaN(), 3).is_null());
  EXPECT_TRUE(json_fixed(std::numeric_limits<double>::infinity(), 3).is_null());
  EXPECT_TRUE(json_significant(std::nullopt, 9).is_null());
}

TEST(Json, KeysKeepTheirOrder) {
  Json j;
  j["zeta"] = 1;
  j["alpha"] = "x";
  j["mid"] = {1.5, true, nullptr};
  EXPECT_EQ(json_line(j), R"({"zeta":1,"alpha":"x","mid":[1.5,true,null]})");
}

TEST(Json, LinesAreAsciiWhateverTheBytes) {
  Json j;
  j["q\"k"] = std::string("a\\b\n\x01");
  j["name"] = std::string("K\xc3\xbcmmerle");  // UTF-8
  j["bad"] = std::string("x\xff");             // not UTF-8
  const std::string line = json_line(j);
  EXPECT_EQ(line, R"({"q\"k":"a\\b\n\u0001","name":"K\u00fcmmerle","bad":"x\ufffd"})");
  EXPECT_EQ(Json::parse(line)["name"], "K\xc3\xbcmmerle");
}

}  // namespace
}  // namespace traverse
