#include "json_writer.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace traverse::validate {
namespace {

TEST(JsonWriter, NestsAndSeparates) {
  JsonWriter j;
  j.begin_object();
  j.field("a", 1).field("b", "x");
  j.key("c").begin_array().value(1.5).value(true).begin_object().end_object().end_array();
  j.key("d").begin_object().field("e", nullptr).end_object();
  j.end_object();
  EXPECT_EQ(j.str(), R"({"a":1,"b":"x","c":[1.5,true,{}],"d":{"e":null}})");
}

TEST(JsonWriter, EscapesStringsAndKeys) {
  JsonWriter j;
  j.begin_object().field("q\"k", std::string("a\\b\n\x01\xff")).end_object();
  EXPECT_EQ(j.str(), R"({"q\"k":"a\\b\n\u0001\u00ff"})");
}

TEST(JsonWriter, NonFiniteAndAbsentNumbersAreNull) {
  JsonWriter j;
  j.begin_array();
  j.value(std::numeric_limits<double>::quiet_NaN());
  j.value(std::numeric_limits<double>::infinity());
  j.value(std::optional<double>());
  j.value(std::optional<double>(0.25));
  j.end_array();
  EXPECT_EQ(j.str(), "[null,null,null,0.25]");
}

}  // namespace
}  // namespace traverse::validate
